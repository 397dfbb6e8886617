//! The campaign's record of a pose that is being solved, so that a run killed in the
//! middle of a pose (a session's end SIGKILLs every process, no handler runs) goes on
//! where it was instead of from attempt 1: `<out>/.work/<pose>/progress.toml`
//! ([`RECORD_FILE`]).
//!
//! The campaign writes it atomically ([`needle_stdx::fs::write_atomic`]) at the start of each
//! attempt and after each failed attempt ([`write()`]), and removes it when the pose is
//! solved. It holds what identifies the run ([`Identity`]: spec hash, engine and its
//! version, mesh level, steps), the attempt running (or, after a failure, the next one),
//! the failure messages of the finished attempts and the furthest attempt's must points.
//!
//! On a rerun, [`decide`] keeps the work folder and resumes at the recorded attempt only
//! when the record is readable, matches the current run exactly and has attempts left
//! and `--force` is not given; a record of exactly this run whose attempts all failed is
//! [`Decision::Finished`] (the campaign clears it, or with `--skip-failed` keeps it and
//! runs nothing); otherwise the folder is cleared as before, with the reason
//! ([`Decision::Fresh`]). A `--force` rerun of an up-to-date pose that was interrupted
//! leaves a record of exactly this run ([`unfinished`]): a rerun without `--force`
//! resumes it rather than skip the pose as up to date. What an engine does with an interrupted attempt is its own
//! affair: FEBio continues it from its last dump (`febio/running.rs`), CalculiX reruns it
//! from its start.

use crate::manifest::rfc3339_utc;
use anyhow::{Context, Result};
use needle_contract::COMPONENT_COUNT;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::SystemTime;

/// The record's file name in a pose's work folder.
pub const RECORD_FILE: &str = "progress.toml";

/// What identifies a run of a pose: a record of another run is never resumed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Identity {
    /// [`Campaign::run_hash`](crate::spec::Campaign::run_hash) of the spec as run, the pose
    /// and the mesh level (it includes the engine's settings).
    pub spec_hash: String,
    /// The engine's name (`febio`, `ccx`).
    pub engine: String,
    /// The engine's version as `prepare` found it.
    pub engine_version: String,
    /// Mesh level name.
    pub mesh: String,
    /// Load steps of the run.
    pub steps: u32,
}

/// `progress.toml`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Record {
    /// The run this record belongs to.
    pub run: Identity,
    /// The engine's number of attempts ([`Backend::attempts`](crate::backend::Backend::attempts)).
    pub attempts: u32,
    /// The attempt (0-based) running, or, after a failed attempt, the next one; equal to
    /// `attempts` once every attempt failed.
    pub attempt: u32,
    /// The finished attempts' failure messages, as the campaign reports them.
    pub failures: Vec<String>,
    /// The wrench at each must point of the furthest finished attempt (from step 1 on).
    pub furthest: Vec<[f64; COMPONENT_COUNT]>,
    /// When the record was written, UTC, RFC 3339.
    pub date: String,
}

/// Where a pose's attempts start.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Start {
    /// The first attempt to run (0-based).
    pub attempt: u32,
    /// The failures of the attempts before it.
    pub failures: Vec<String>,
    /// The furthest of those attempts' must points.
    pub furthest: Vec<[f64; COMPONENT_COUNT]>,
}

/// What a rerun does with a pose's work folder.
#[derive(Debug, Clone, PartialEq)]
pub enum Decision {
    /// Keep the folder and start at the recorded attempt.
    Resume(Start),
    /// Every attempt of exactly this run failed before (the failure messages as
    /// recorded): the campaign starts it afresh, or with `--skip-failed` runs nothing.
    Finished(Vec<String>),
    /// Clear the folder and start at attempt 1; `Some(why)` when a record was there but is
    /// not resumed (one line for stderr).
    Fresh(Option<String>),
}

/// `<work_dir>/progress.toml`.
pub fn path(work_dir: &Path) -> PathBuf {
    work_dir.join(RECORD_FILE)
}

/// Write the record of `run` at `start` atomically.
///
/// # Errors
/// The file cannot be written (with its path).
pub fn write(work_dir: &Path, run: &Identity, attempts: u32, start: &Start) -> Result<()> {
    let record = Record {
        run: run.clone(),
        attempts,
        attempt: start.attempt,
        failures: start.failures.clone(),
        furthest: start.furthest.clone(),
        date: rfc3339_utc(SystemTime::now()),
    };
    let p = path(work_dir);
    let text = format!(
        "# the campaign's record of this pose's attempts (fe/src/resume.rs): a rerun resumes here\n{}",
        toml::to_string(&record).with_context(|| format!("{}: cannot serialise the record", p.display()))?
    );
    needle_stdx::fs::write_atomic(&p, text.as_bytes())
}

/// Remove the record (the pose is solved); a missing record is fine.
pub fn remove(work_dir: &Path) {
    let _ = std::fs::remove_file(path(work_dir));
}

/// Read the record in `work_dir`; `Ok(None)` when there is none.
///
/// # Errors
/// The file exists but cannot be read or is not a record (with its path).
pub fn read(work_dir: &Path) -> Result<Option<Record>> {
    let p = path(work_dir);
    match std::fs::read_to_string(&p) {
        Ok(t) => toml::from_str(&t).map(Some).with_context(|| format!("{}: not a progress record", p.display())),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(e).with_context(|| format!("{}: cannot read", p.display())),
    }
}

/// Whether `work_dir` holds the record of an unfinished run (attempts left) of this
/// spec hash, mesh level and step count. A pose whose result is up to date has such a
/// record only when a `--force` rerun of it was interrupted: `campaign::plan` then
/// solves it again, and [`decide`] resumes that run (or, if the engine or its version
/// changed since, starts afresh and says why). Reads the record only; an unreadable
/// record or none is no unfinished run.
pub fn unfinished(work_dir: &Path, spec_hash: &str, mesh: &str, steps: u32) -> bool {
    matches!(read(work_dir), Ok(Some(r)) if r.run.spec_hash == spec_hash && r.run.mesh == mesh && r.run.steps == steps && r.attempt < r.attempts)
}

/// Whether the pose whose work folder is `work_dir` resumes (module docs). Guarantees: a
/// [`Decision::Resume`] only for a readable record of exactly `run` with
/// `attempt < attempts` (the engine's count now) and `force` false, its attempt index,
/// failures and must points as recorded; [`Decision::Finished`] only for a readable
/// record of exactly `run` and the same count whose attempts all finished, with one
/// failure message each, and `force` false; [`Decision::Fresh`] with a reason whenever a
/// record exists but is neither, `Fresh(None)` when there is none.
pub fn decide(work_dir: &Path, run: &Identity, attempts: u32, force: bool) -> Decision {
    let record = match read(work_dir) {
        Ok(Some(r)) => r,
        Ok(None) => return Decision::Fresh(None),
        Err(e) => return Decision::Fresh(Some(format!("{e:#}"))),
    };
    let p = path(work_dir);
    let why = if force {
        Some("--force".to_string())
    } else if record.run != *run {
        Some(format!("it is the record of another run ({})", differences(&record.run, run)))
    } else if record.attempts != attempts {
        Some(format!("it counts {} attempts, the engine now {attempts}", record.attempts))
    } else if record.attempt >= record.attempts && record.failures.len() == record.attempts as usize {
        return Decision::Finished(record.failures);
    } else if record.attempt >= record.attempts {
        Some(format!("all {} attempts finished with {} failure message(s)", record.attempts, record.failures.len()))
    } else if record.failures.len() != record.attempt as usize {
        Some(format!("attempt {} with {} failure message(s)", record.attempt + 1, record.failures.len()))
    } else {
        None
    };
    match why {
        Some(w) => Decision::Fresh(Some(format!("{}: not resumed: {w}", p.display()))),
        None => Decision::Resume(Start { attempt: record.attempt, failures: record.failures, furthest: record.furthest }),
    }
}

/// `spec_hash abc != def, steps 4 != 5`: the fields of `a` and `b` that differ.
fn differences(a: &Identity, b: &Identity) -> String {
    let mut d = Vec::new();
    let mut cmp = |name: &str, x: &str, y: &str| {
        if x != y {
            d.push(format!("{name} {x} != {y}"));
        }
    };
    cmp("spec_hash", &a.spec_hash, &b.spec_hash);
    cmp("engine", &a.engine, &b.engine);
    cmp("engine_version", &a.engine_version, &b.engine_version);
    cmp("mesh", &a.mesh, &b.mesh);
    cmp("steps", &a.steps.to_string(), &b.steps.to_string());
    d.join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run() -> Identity {
        Identity { spec_hash: "h1".into(), engine: "fake".into(), engine_version: "1".into(), mesh: "smoke".into(), steps: 4 }
    }

    fn start(attempt: u32) -> Start {
        Start {
            attempt,
            failures: (0..attempt).map(|k| format!("stop {k}")).collect(),
            furthest: vec![[1.0, -2.5e-3, 0.0, 0.0, 4.0, 1e-9]],
        }
    }

    #[test]
    fn a_matching_record_with_attempts_left_resumes_as_written() {
        let d = tempfile::tempdir().expect("tempdir");
        assert_eq!(decide(d.path(), &run(), 5, false), Decision::Fresh(None), "no record");
        write(d.path(), &run(), 5, &start(2)).expect("write");
        assert_eq!(decide(d.path(), &run(), 5, false), Decision::Resume(start(2)));
        let fresh = |r: &Identity, attempts: u32, force: bool| match decide(d.path(), r, attempts, force) {
            Decision::Fresh(Some(why)) => why,
            other => panic!("expected a fresh start with a reason: {other:?}"),
        };
        assert!(fresh(&run(), 5, true).ends_with("not resumed: --force"));
        let other = Identity { spec_hash: "h2".into(), steps: 5, ..run() };
        let why = fresh(&other, 5, false);
        assert!(why.contains("another run (spec_hash h1 != h2, steps 4 != 5)") && why.contains(RECORD_FILE), "{why}");
        assert!(fresh(&Identity { engine_version: "2".into(), ..run() }, 5, false).contains("engine_version 1 != 2"));
        assert!(fresh(&run(), 2, false).contains("counts 5 attempts, the engine now 2"));
        write(d.path(), &run(), 5, &start(5)).expect("write");
        assert_eq!(decide(d.path(), &run(), 5, false), Decision::Finished(start(5).failures), "every attempt failed");
        assert!(fresh(&run(), 5, true).ends_with("not resumed: --force"));
        assert!(fresh(&other, 5, false).contains("another run"), "a changed spec runs afresh");
        write(d.path(), &run(), 5, &Start { failures: vec!["one".into()], ..start(5) }).expect("write");
        assert!(fresh(&run(), 5, false).contains("all 5 attempts finished with 1 failure message(s)"));
        std::fs::write(path(d.path()), "attempt = \"x\"").expect("corrupt");
        assert!(fresh(&run(), 5, false).contains("not a progress record"));
        remove(d.path());
        assert_eq!(decide(d.path(), &run(), 5, false), Decision::Fresh(None));
    }
}
