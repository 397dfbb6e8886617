//! The partial record of a pose that failed every attempt (issue 42, item 4: a failed
//! pose is kept as a record of the depth reached and why it stopped): the must points its
//! furthest attempt reached, in `<out>/<pose>.partial.csv` (the format of `<pose>.csv`,
//! rows from depth 0 to the depth reached) and `<out>/<pose>.partial.toml` (how it was
//! made, how far it got, the attempts' failures). Written by the campaign when the last
//! attempt fails, removed when the pose solves. Nothing takes it for a result: the fitter
//! and the checks read `<pose>.csv` and its manifest entry only.

use crate::results::{self, Row};
use crate::spec::{Campaign, PoseSpec};
use anyhow::{Context, Result};
use needle_contract::COMPONENT_COUNT;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// `<pose>.partial.toml`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PartialRecord {
    /// The run hash the pose's full result would have ([`Campaign::run_hash`]).
    pub spec_hash: String,
    /// Engine and its version.
    pub engine: String,
    /// Version of the engine.
    pub engine_version: String,
    /// Mesh level.
    pub mesh: String,
    /// Load steps asked for.
    pub steps: u32,
    /// Depth asked for, mm.
    pub depth_mm: f64,
    /// Must points reached (the CSV has one more row, depth 0).
    pub reached_steps: u32,
    /// Depth reached, mm.
    pub reached_depth_mm: f64,
    /// SHA-256 of the partial CSV as written.
    pub csv_sha256: String,
    /// Every attempt's failure, as the campaign reports it.
    pub failure: String,
    /// When it was written, UTC, RFC 3339.
    pub date: String,
}

/// `<out>/<pose>.partial.csv` and `.partial.toml`.
pub fn paths(out_dir: &Path, pose: &str) -> (PathBuf, PathBuf) {
    (out_dir.join(format!("{pose}.partial.csv")), out_dir.join(format!("{pose}.partial.toml")))
}

/// The pose's `.partial.toml` record in `out_dir`, when there is one that parses.
#[must_use]
pub fn read_record(out_dir: &Path, pose: &str) -> Option<PartialRecord> {
    let (_, record) = paths(out_dir, pose);
    toml::from_str(&std::fs::read_to_string(record).ok()?).ok()
}

/// As [`read_record`], only when the record is of the run with `spec_hash` (a record of
/// another spec is an earlier problem's, not this run's).
#[must_use]
pub fn read_current_record(out_dir: &Path, pose: &str, spec_hash: &str) -> Option<PartialRecord> {
    read_record(out_dir, pose).filter(|r| r.spec_hash == spec_hash)
}

/// What the campaign knows of the failed run.
pub struct Failed<'a> {
    /// The spec as run (steps applied).
    pub campaign: &'a Campaign,
    /// The pose.
    pub pose: &'a PoseSpec,
    /// Mesh level name.
    pub mesh: &'a str,
    /// Engine name and version.
    pub engine: (&'a str, &'a str),
    /// The attempts' failures.
    pub failure: &'a str,
}

/// Write the record of `reached` (must points from step 1 on); nothing when it is empty.
///
/// # Errors
/// A file cannot be written.
pub fn write(out_dir: &Path, f: &Failed<'_>, reached: &[[f64; COMPONENT_COUNT]]) -> Result<()> {
    if reached.is_empty() {
        return Ok(());
    }
    let mut rows = vec![Row { depth_mm: 0.0, wrench: [0.0; COMPONENT_COUNT] }];
    rows.extend((1u32..).zip(reached).map(|(k, w)| Row { depth_mm: f.campaign.loading.depth_at(k), wrench: *w }));
    // a ramp-and-hold run's record keeps its times (`needle_fe::visco`: the hold's depths repeat)
    let loading = &f.campaign.loading;
    let text = match loading.ramp_hold {
        Some(_) => results::to_timed_csv(&(0..rows.len() as u32).map(|k| loading.time_at(k)).collect::<Vec<_>>(), &rows),
        None => results::to_csv(&rows),
    };
    let record = PartialRecord {
        spec_hash: f.campaign.run_hash(f.pose, f.mesh),
        engine: f.engine.0.into(),
        engine_version: f.engine.1.into(),
        mesh: f.mesh.into(),
        steps: f.campaign.loading.steps,
        depth_mm: f.campaign.loading.depth_mm,
        reached_steps: reached.len() as u32,
        reached_depth_mm: rows.last().map_or(0.0, |r| r.depth_mm),
        csv_sha256: results::content_sha256(text.as_bytes()),
        failure: f.failure.into(),
        date: crate::manifest::rfc3339_utc(std::time::SystemTime::now()),
    };
    let toml = format!(
        "# written by `needle fe run`: the must points of the furthest failed attempt (of the attempts so far, while a campaign runs); not a result\n{}",
        toml::to_string(&record).context("cannot serialise the partial record")?
    );
    let (csv, rec) = paths(out_dir, &f.pose.name);
    needle_stdx::fs::write_all_atomic(&[(&csv, text.as_bytes()), (&rec, toml.as_bytes())])
}

/// Remove a pose's partial record (it solved); a missing one is fine.
pub fn remove(out_dir: &Path, pose: &str) {
    let (csv, rec) = paths(out_dir, pose);
    let _ = std::fs::remove_file(csv);
    let _ = std::fs::remove_file(rec);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_partial_record_holds_the_reached_must_points_and_goes_when_removed() {
        let d = tempfile::tempdir().expect("tempdir");
        let set = needle_stdx::workspace_root().join("coeffs/default");
        let (mut c, _) = crate::spec::load(&set).expect("spec");
        c.loading.steps = 4;
        let pose = c.poses().into_iter().find(|p| p.name == "centre").expect("centre");
        let f = Failed { campaign: &c, pose: &pose, mesh: "needle8", engine: ("febio", "4.11.0"), failure: "max reformations" };
        write(d.path(), &f, &[]).expect("nothing to write");
        assert!(!paths(d.path(), "centre").0.exists(), "no record without a must point");
        write(d.path(), &f, &[[0.0, 0.01, 0.0, 0.0, 0.0, 0.0], [0.0, 0.03, 0.0, 0.0, 0.0, 0.0]]).expect("write");
        let (csv, rec) = paths(d.path(), "centre");
        let rows = results::read_csv(&csv).expect("csv");
        assert_eq!(rows.iter().map(|r| (r.depth_mm, r.fy_n())).collect::<Vec<_>>(), [(0.0, 0.0), (1.5, 0.01), (3.0, 0.03)]);
        let text = std::fs::read_to_string(&rec).expect("record");
        let r: PartialRecord = toml::from_str(text.lines().skip(1).collect::<Vec<_>>().join("\n").as_str()).expect("parse");
        assert_eq!((r.reached_steps, r.reached_depth_mm, r.steps, r.depth_mm), (2, 3.0, 4, 6.0));
        assert_eq!(r.spec_hash, c.run_hash(&pose, "needle8"));
        assert_eq!(r.csv_sha256, results::content_sha256(std::fs::read(&csv).expect("bytes").as_slice()));
        remove(d.path(), "centre");
        assert!(!csv.exists() && !rec.exists());
    }
}
