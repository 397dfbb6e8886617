//! `fe/manifest.toml`: how each `fe/<pose>.csv` was made (spec hash, solver, mesh,
//! increments, wall time), read to skip up-to-date poses and rewritten atomically by the
//! campaign after each pose; and how the process that solved a run was launched
//! ([`Launched`], its `launcher` and `batch_job`).

use crate::spec::{Campaign, PoseSpec, Role};
use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::SystemTime;

/// Name of the manifest file in the output folder.
pub const MANIFEST: &str = "manifest.toml";

/// `manifest.toml`: one entry per finished pose, keyed and sorted by pose name.
#[derive(Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// Entries by pose name.
    #[serde(default)]
    pub pose: BTreeMap<String, ManifestEntry>,
}

/// What is known about how one `fe/<pose>.csv` was made.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ManifestEntry {
    /// [`Campaign::run_hash`](crate::spec::Campaign::run_hash) of the spec (with the steps actually run), pose and mesh.
    pub spec_hash: String,
    /// For a run its first attempt solved (no `retry`):
    /// [`Campaign::first_attempt_hash`](crate::spec::Campaign::first_attempt_hash) of the
    /// same spec. The run stays current while that hash does, when only settings of the
    /// retry ladder's later attempts change. None for a run a later attempt solved, and
    /// in entries from before it was recorded (until [`Manifest::record_first_attempts`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub first_attempt_hash: Option<String>,
    /// The engine that solved it: "ccx" or "febio" (entries written before there were
    /// two engines have none: ccx).
    #[serde(default = "ccx")]
    pub engine: String,
    /// Version of that engine, e.g. "2.20" (ccx) or "4.11.0" (febio); read from the
    /// older key `ccx_version` too.
    #[serde(alias = "ccx_version")]
    pub engine_version: String,
    /// The tissue element and formulation (empty in entries from before it was recorded).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub element: String,
    /// The solver settings of the run, one line (empty in entries from before).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub solver_settings: String,
    /// Mesh level name.
    pub mesh: String,
    /// SHA-256 of the CSV as the campaign wrote it ([`results::content_sha256`](crate::results::content_sha256)):
    /// the fitter, validator, plots and explorer refuse a CSV whose content differs
    /// (`fit::data::FeRuns::read`). An entry without it is not trusted: `needle fe run`
    /// solves its pose again and the fitter refuses its CSV (a hash taken later would
    /// vouch for whatever file is there then).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub csv_sha256: Option<String>,
    /// The model solved, e.g. "half, mirror plane z = 0".
    pub model: String,
    /// The tissue mesh in words.
    pub tissue_mesh: String,
    /// Tissue nodes of the model.
    pub tissue_nodes: u64,
    /// Tissue elements of the model.
    pub tissue_elements: u64,
    /// Needle nodes of the model.
    pub needle_nodes: u64,
    /// Needle elements of the model.
    pub needle_elements: u64,
    /// Load steps.
    pub steps: u32,
    /// Final depth, mm.
    pub depth_mm: f64,
    /// Converged increments, all steps.
    pub increments: u32,
    /// Newton iterations, all steps and attempts.
    pub iterations: u32,
    /// Wall time of the solve (deck, ccx, reading back), s.
    pub wall_s: f64,
    /// Peak resident memory of the solver process of the successful attempt, MiB
    /// (Linux `VmHWM`); none in entries from before it was recorded. The SLURM
    /// launcher's default `--mem` comes from it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_rss_mib: Option<f64>,
    /// When the run finished, UTC, RFC 3339 (`2025-01-31T12:00:00Z`).
    pub date: String,
    /// Role of the pose.
    pub role: Role,
    /// Pose: tip x, mm.
    pub x_mm: f64,
    /// Pose: tip z, mm.
    pub z_mm: f64,
    /// Pose: tilt about x, degrees.
    pub theta_x_deg: f64,
    /// Pose: tilt about z, degrees.
    pub theta_z_deg: f64,
    /// First increment of each load step as a fraction of the step, when not 1 (the
    /// retry of a failed run, see the module docs).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub first_increment: Option<f64>,
    /// Why the first attempt failed, when this result comes from the retry.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub retry: Option<String>,
    /// How the run was started: "local" (`needle fe run`) or "slurm" (an array task of
    /// `needle fe run --launcher slurm`); none in entries from before it was recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub launcher: Option<String>,
    /// The batch system's job of the run, e.g. "1234_5" (SLURM array job 1234, task 5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub batch_job: Option<String>,
    /// The training pose this one replaces in the design (`campaign.train_replaced`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub replaces: Option<String>,
    /// Why that pose was replaced: the spec's `why`, then the failure of its furthest
    /// attempt from its `.partial.toml` when there is one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub replaced_because: Option<String>,
    /// A viscoelastic ramp-and-hold run (`needle_fe::visco`): its Prony series and time
    /// course, one line with units.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub viscoelastic: Option<String>,
}

impl Manifest {
    /// The entry of `pose` when it says the pose's result came from the spec `campaign`
    /// as it is now, on mesh level `mesh_name`: its spec hash is
    /// [`Campaign::run_hash`](crate::spec::Campaign::run_hash), or its first attempt
    /// solved it and its `first_attempt_hash` is
    /// [`Campaign::first_attempt_hash`](crate::spec::Campaign::first_attempt_hash) (the
    /// spec changed only where later attempts would have differed); otherwise why not.
    /// The one test of "current" shared by the campaign's skipping and by the fitter's
    /// and validator's refusal of stale runs.
    ///
    /// # Errors
    /// The reason, e.g. `no entry in manifest.toml` or `solved from another spec (...)`.
    pub fn current_entry(&self, campaign: &Campaign, pose: &PoseSpec, mesh_name: &str) -> std::result::Result<&ManifestEntry, String> {
        let want = campaign.run_hash(pose, mesh_name);
        let short = |h: &str| h.get(..12).unwrap_or(h).to_string();
        match self.pose.get(&pose.name) {
            None => Err(format!("no entry in {MANIFEST}")),
            Some(e) if e.spec_hash == want => Ok(e),
            Some(e) if e.first_attempt_hash.as_deref() == Some(campaign.first_attempt_hash(pose, mesh_name).as_str()) => Ok(e),
            Some(e) => Err(format!(
                "solved from another spec (spec_hash {} in {MANIFEST}, {} for the current campaign.toml)",
                short(&e.spec_hash),
                short(&want)
            )),
        }
    }

    /// Record the first attempt's hash in every entry of `poses` that is current by its
    /// spec hash on `mesh_name`, was solved by its first attempt (no `retry`) and has none
    /// yet (entries written before the hash existed). Returns how many entries changed.
    /// Only a current entry gets it: the hash is of the spec that solved the run.
    pub fn record_first_attempts(&mut self, campaign: &Campaign, poses: &[PoseSpec], mesh_name: &str) -> usize {
        let mut changed = 0;
        for pose in poses {
            if let Some(e) = self.pose.get_mut(&pose.name) {
                if e.retry.is_none() && e.first_attempt_hash.is_none() && e.spec_hash == campaign.run_hash(pose, mesh_name) {
                    e.first_attempt_hash = Some(campaign.first_attempt_hash(pose, mesh_name));
                    changed += 1;
                }
            }
        }
        changed
    }
}

impl ManifestEntry {
    /// Whether `bytes` are the CSV this entry was written for: its `csv_sha256` matches
    /// (an entry without the hash vouches for nothing: false).
    #[must_use]
    pub fn content_matches(&self, bytes: &[u8]) -> bool {
        self.csv_sha256.as_ref().is_some_and(|h| *h == crate::results::content_sha256(bytes))
    }
}

impl Manifest {
    /// Wall times in s of the recorded runs of `engine` on mesh level `mesh_name` with `steps` load
    /// steps, by model (e.g. "full block, no mirror plane"), for the ETA of a campaign.
    /// Any spec hash counts: a spec change rarely changes the cost much.
    pub fn wall_times_s(&self, engine: &str, mesh_name: &str, steps: u32) -> BTreeMap<String, Vec<f64>> {
        let mut by_model: BTreeMap<String, Vec<f64>> = BTreeMap::new();
        for e in self.pose.values() {
            if e.engine == engine && e.mesh == mesh_name && e.steps == steps && e.wall_s.is_finite() && e.wall_s > 0.0 {
                by_model.entry(e.model.clone()).or_default().push(e.wall_s);
            }
        }
        by_model
    }
}

fn ccx() -> String {
    "ccx".into()
}

/// Why a manifest was refused.
#[derive(Debug, thiserror::Error)]
pub enum ManifestError {
    /// The file exists but cannot be read.
    #[error("{}: cannot read", path.display())]
    Read {
        /// The manifest's path.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// Not TOML, or not a manifest's tables and keys.
    #[error("{}:{line}: not a valid manifest ({message}); it is written by `needle fe run` only: delete it to rerun every pose", path.display())]
    Invalid {
        /// The manifest's path.
        path: PathBuf,
        /// 1-based line of the error (0: unknown).
        line: usize,
        /// The TOML reader's words.
        message: String,
    },
}

/// Read a manifest; a missing file is an empty manifest.
///
/// # Errors
/// [`ManifestError`]: the file exists but cannot be read or is not a valid manifest.
pub fn read_manifest(path: &Path) -> std::result::Result<Manifest, ManifestError> {
    crate::read_count::count_manifest_read();
    let text = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Manifest::default()),
        Err(source) => return Err(ManifestError::Read { path: path.into(), source }),
    };
    toml::from_str(&text).map_err(|e| {
        let line = e.span().and_then(|s| text.get(..s.start)).map_or(0, |t| t.matches('\n').count() + 1);
        ManifestError::Invalid { path: path.into(), line, message: e.message().to_string() }
    })
}

/// The manifest's text: a comment, then the entries sorted by pose name.
///
/// # Errors
/// Serialization failed (a bug).
pub fn manifest_text(m: &Manifest) -> Result<String> {
    let body = toml::to_string(m).context("cannot serialize the manifest")?;
    let nl = if body.ends_with('\n') { "" } else { "\n" };
    Ok(format!("# Written by `needle fe run`, one table per pose whose fe/<pose>.csv is current. Do not edit.\n\n{body}{nl}"))
}

/// `t` as an RFC 3339 UTC timestamp with whole seconds, e.g. `2025-01-31T12:00:00Z`.
pub fn rfc3339_utc(t: SystemTime) -> String {
    let secs = t.duration_since(SystemTime::UNIX_EPOCH).map(|d| d.as_secs()).unwrap_or(0);
    let days = (secs / 86_400) as i64;
    let rem = secs % 86_400;
    // civil_from_days (H. Hinnant): days since the Unix epoch -> proleptic Gregorian date
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1_460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!("{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}Z", rem / 3_600, rem % 3_600 / 60, rem % 60)
}

/// How the process that solved a pose was started; recorded in its manifest entry
/// (`launcher`, `batch_job`).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum Launched {
    /// `needle fe run` on this machine.
    #[default]
    Local,
    /// A SLURM array task; `job` is `<array job id>_<task id>`.
    Slurm {
        /// `SLURM_ARRAY_JOB_ID_SLURM_ARRAY_TASK_ID`, e.g. `1234_5`.
        job: String,
    },
}

impl Launched {
    /// `"local"` or `"slurm"`: the manifest's `launcher`.
    pub fn name(&self) -> &'static str {
        match self {
            Launched::Local => "local",
            Launched::Slurm { .. } => "slurm",
        }
    }

    /// The manifest's `batch_job`: the SLURM array task, none for a local run.
    pub fn batch_job(&self) -> Option<String> {
        match self {
            Launched::Local => None,
            Launched::Slurm { job } => Some(job.clone()),
        }
    }

    /// The launcher of this process: a SLURM array task when `SLURM_ARRAY_JOB_ID` and
    /// `SLURM_ARRAY_TASK_ID` are set, else local.
    pub fn from_env() -> Self {
        match (std::env::var("SLURM_ARRAY_JOB_ID"), std::env::var("SLURM_ARRAY_TASK_ID")) {
            (Ok(j), Ok(t)) if !j.is_empty() && !t.is_empty() => Launched::Slurm { job: format!("{j}_{t}") },
            _ => Launched::Local,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn dates() {
        let at = |s: u64| rfc3339_utc(SystemTime::UNIX_EPOCH + Duration::from_secs(s));
        assert_eq!(at(0), "1970-01-01T00:00:00Z");
        // 2000-02-29 (leap day of a century leap year) and 2100-03-01 (not a leap year)
        assert_eq!(at(951_782_400 + 3_600 + 61), "2000-02-29T01:01:01Z");
        assert_eq!(at(4_107_542_400), "2100-03-01T00:00:00Z");
        assert_eq!(at(1_735_689_599), "2024-12-31T23:59:59Z");
    }

    /// A missing manifest is an empty one; a folder in its place cannot be read; a broken
    /// one is refused with the line of the fault.
    #[test]
    fn each_bad_manifest_is_its_own_error() {
        let d = tempfile::tempdir().expect("tempdir");
        let path = d.path().join(MANIFEST);
        assert!(read_manifest(&path).expect("missing: empty").pose.is_empty());
        std::fs::create_dir(&path).expect("a folder in its place");
        assert!(matches!(read_manifest(&path), Err(ManifestError::Read { .. })));
        std::fs::remove_dir(&path).expect("remove the folder");
        std::fs::write(&path, "# a comment\n\n[pose.x]\nengine = 3\n").expect("write");
        match read_manifest(&path) {
            Err(e @ ManifestError::Invalid { line: 4, .. }) => {
                assert!(e.to_string().contains("manifest.toml:4: not a valid manifest"), "{e}")
            }
            other => panic!("a wrong type on line 4 must be Invalid at line 4: {other:?}"),
        }
    }
}
