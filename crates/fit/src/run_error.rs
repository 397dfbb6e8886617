//! [`RunError`]: why the fitter or `needle validate` refused a set's FE runs, a variant per
//! kind of refusal so that a caller or a test tells them apart without reading the text.

use std::path::PathBuf;

/// Why a set's FE runs cannot be fitted or validated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RunError {
    /// Fitted runs without a result file.
    #[error(
        "{} of the {fitted} fitted FE runs are missing from {}: {}\n(run `needle fe run --set {}` to finish the campaign; the fit needs the centre run, every sweep run and, for [fit] form = \"coupled\", every training run, less those listed in campaign.fit_without)",
        poses.len(), set_dir.join("fe").display(), poses.join(", "), set_dir.display()
    )]
    Missing {
        /// The set.
        set_dir: PathBuf,
        /// Runs the fit uses.
        fitted: usize,
        /// The missing ones, by pose name.
        poses: Vec<String>,
    },
    /// Fitted runs whose result is not current with the spec (solved from another one, or
    /// no manifest entry).
    #[error(
        "{} of the {fitted} fitted FE runs in {} are stale:\n  {}\n(run `needle fe run --set {}`: it solves exactly the poses whose result is not current)",
        runs.len(), set_dir.join("fe").display(),
        runs.iter().map(|(p, why)| format!("{p}: {why}")).collect::<Vec<_>>().join("\n  "), set_dir.display()
    )]
    Stale {
        /// The set.
        set_dir: PathBuf,
        /// Runs the fit uses.
        fitted: usize,
        /// (pose name, why it is not current).
        runs: Vec<(String, String)>,
    },
    /// The run's manifest entry records no `csv_sha256`: nothing vouches for the file.
    #[error(
        "{}: fe/manifest.toml records no csv_sha256 for {pose}, so nothing vouches for the file's content: rerun the pose with `needle fe run --force --only {pose}`",
        path.display()
    )]
    NoHash {
        /// The run's file.
        path: PathBuf,
        /// Its pose.
        pose: String,
    },
    /// The file's bytes are not those the FE run wrote (their SHA-256 differs from the
    /// manifest's).
    #[error(
        "{}: content changed since the FE run wrote it (sha256 {} now, {} in fe/manifest.toml): restore it (git checkout) or rerun the pose with `needle fe run --force --only {pose}`",
        path.display(), now.get(..16).unwrap_or(now), recorded.get(..16).unwrap_or(recorded)
    )]
    ContentChanged {
        /// The run's file.
        path: PathBuf,
        /// Its pose.
        pose: String,
        /// The file's SHA-256 now (hex).
        now: String,
        /// The SHA-256 the manifest records (hex).
        recorded: String,
    },
    /// A run with another number of depth rows than the spec's loading (steps + 1).
    #[error("{}: {found} depth rows, expected loading.steps + 1 = {expected} (an unfinished or failed run?)", path.display())]
    DepthRows {
        /// The run's file.
        path: PathBuf,
        /// Rows in the file.
        found: usize,
        /// loading.steps + 1.
        expected: usize,
    },
    /// A row at another depth than the spec's loading puts there (to 1e-9 mm).
    #[error("{}:{line}: depth_mm = {found_mm}, expected {expected_mm}", path.display())]
    Depth {
        /// The run's file.
        path: PathBuf,
        /// The row's line.
        line: usize,
        /// Its depth, mm.
        found_mm: f64,
        /// The spec's depth there, mm.
        expected_mm: f64,
    },
}
