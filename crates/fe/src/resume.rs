//! The campaign's record of a pose that is being solved, so that a run killed in the
//! middle of a pose (a session's end SIGKILLs every process, no handler runs) goes on
//! where it was instead of from attempt 1: `<out>/.work/<pose>/progress.toml`
//! ([`RECORD_FILE`]).
//!
//! The campaign writes it atomically ([`results::write_atomic`]) at the start of each
//! attempt and after each failed attempt ([`write()`]), and removes it when the pose is
//! solved. It holds what identifies the run ([`Identity`]: spec hash, engine and its
//! version, mesh level, steps), the attempt running (or, after a failure, the next one),
//! the failure messages of the finished attempts and the furthest attempt's must points.
//!
//! On a rerun, [`decide`] keeps the work folder and resumes at the recorded attempt only
//! when the record is readable, matches the current run exactly and has attempts left
//! and `--force` is not given; otherwise the folder is cleared as before, with the reason
//! ([`Decision::Fresh`]). What an engine does with an interrupted attempt is its own
//! affair: FEBio continues it from its last dump (`febio/running.rs`), CalculiX reruns it
//! from its start.

use crate::manifest::rfc3339_utc;
use crate::results;
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
    results::write_atomic(&p, text.as_bytes())
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

/// Whether the pose whose work folder is `work_dir` resumes (module docs). Guarantees: a
/// [`Decision::Resume`] only for a readable record of exactly `run` with
/// `attempt < attempts` (the engine's count now) and `force` false, its attempt index,
/// failures and must points as recorded; [`Decision::Fresh`] with a reason whenever a
/// record exists but is not resumed, `Fresh(None)` when there is none.
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
    } else if record.attempt >= record.attempts {
        Some(format!("all {} attempts of that run finished (failed)", record.attempts))
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
        assert!(fresh(&run(), 5, false).contains("all 5 attempts of that run finished"));
        std::fs::write(path(d.path()), "attempt = \"x\"").expect("corrupt");
        assert!(fresh(&run(), 5, false).contains("not a progress record"));
        remove(d.path());
        assert_eq!(decide(d.path(), &run(), 5, false), Decision::Fresh(None));
    }
}

/// The campaign's side: a run killed in the middle of a pose goes on at its attempt.
#[cfg(test)]
mod campaign_tests {
    use super::*;
    use crate::backend::{Backend, Job, SolveFailure, Solved};
    use crate::campaign::tests::{opts, set_dir};
    use crate::campaign::{run_with, RunOptions};
    use crate::deck::MeshSummary;
    use crate::manifest::{read_manifest, MANIFEST};
    use std::sync::Mutex;

    /// A solver of `attempts` attempts whose attempt k fails after k + 1 must points
    /// ("fake stop k"), solves at `solve_at`, and at `kill_at` dies as a killed campaign
    /// does: nothing after the attempt's start runs (a panic, which the campaign's worker
    /// reports; the record written at the attempt's start stays).
    struct Killable {
        kill_at: Option<u32>,
        solve_at: Option<u32>,
        ran: Mutex<Vec<u32>>,
    }

    const ATTEMPTS: u32 = 4;

    fn killable(kill_at: Option<u32>, solve_at: Option<u32>) -> Killable {
        Killable { kill_at, solve_at, ran: Mutex::new(Vec::new()) }
    }

    impl Killable {
        fn ran(&self) -> Vec<u32> {
            self.ran.lock().map(|r| r.clone()).unwrap_or_default()
        }
    }

    impl Backend for Killable {
        fn prepare(&mut self) -> Result<String> {
            Ok("fake-1".into())
        }
        fn engine(&self) -> &'static str {
            "fake"
        }
        fn attempts(&self) -> u32 {
            ATTEMPTS
        }
        fn solve(&self, job: &Job<'_>) -> std::result::Result<Solved, SolveFailure> {
            if let Ok(mut r) = self.ran.lock() {
                r.push(job.attempt);
            }
            if self.kill_at == Some(job.attempt) {
                panic!("killed in attempt {}", job.attempt + 1);
            }
            if self.solve_at != Some(job.attempt) {
                let reached = (0..=job.attempt).map(|k| [0.0, f64::from(k), 0.0, 0.0, 0.0, 0.0]).collect();
                return Err(SolveFailure { message: format!("fake stop {}", job.attempt), log_tail: String::new(), reached });
            }
            let summary = MeshSummary {
                tissue_nodes: 1,
                tissue_elements: 1,
                needle_nodes: 1,
                needle_elements: 1,
                model: "fake".into(),
                tissue_mesh: "fake".into(),
            };
            Ok(Solved {
                wrenches: vec![[0.0, 1.0, 0.0, 0.0, 0.0, 0.0]; job.steps as usize],
                summary,
                increments: job.steps,
                iterations: job.steps,
                first_increment: job.first_increment,
                retry: None,
                element: "fake".into(),
                settings: "fake".into(),
                peak_rss_mib: 0.0,
            })
        }
        fn steps_done(&self, _work_dir: &Path) -> u32 {
            0
        }
    }

    /// The failure messages the campaign makes of attempts `0..n` of [`Killable`] (its
    /// own words, built the way `solve_with_retry` builds them).
    fn failures(n: u32, backend: &Killable) -> Vec<String> {
        (0..n)
            .map(|k| match k {
                0 => "fake stop 0".to_string(),
                _ => format!("retry {k} (first increment {}): fake stop {k}", backend.first_increment(k)),
            })
            .collect()
    }

    /// Run `o` with a [`Killable`]; the attempts it ran and the report's failure message.
    fn run(o: &RunOptions, kill_at: Option<u32>, solve_at: Option<u32>) -> (Vec<u32>, String, Killable) {
        let mut b = killable(kill_at, solve_at);
        let r = run_with(o, &mut b).expect("run");
        let message = match r.poses.first().map(|p| &p.status) {
            Some(crate::report::Status::Failed { message, .. }) => message.clone(),
            _ => String::new(),
        };
        (b.ran(), message, b)
    }

    #[test]
    fn a_killed_run_resumes_at_its_attempt_with_the_earlier_failures() {
        let d = set_dir();
        let o = opts(d.path(), "x+04", 2);
        let wd = d.path().join("fe/.work/x+04");
        let (ran, message, b) = run(&o, Some(2), None);
        assert_eq!(ran, [0, 1, 2], "killed in attempt 3");
        assert!(message.contains("panic while solving: killed in attempt 3"), "{message}");
        let rec = read(&wd).expect("readable").expect("the record stays");
        assert_eq!((rec.attempt, rec.attempts), (2, ATTEMPTS));
        assert_eq!(rec.failures, failures(2, &b));
        assert_eq!(rec.furthest.len(), 2, "attempt 2's must points");

        // the rerun goes on at attempt 3, with the two failures before it
        let (ran, message, b) = run(&o, None, None);
        assert_eq!(ran, [2, 3], "attempts 3 and 4 only");
        assert_eq!(message, failures(ATTEMPTS, &b).join("; ") + " (the 4 must point(s) reached are kept in x+04.partial.csv)");
        let rec = read(&wd).expect("readable").expect("kept with the failed pose");
        assert_eq!((rec.attempt, rec.failures.len()), (ATTEMPTS, ATTEMPTS as usize), "every attempt finished");

        // a pose whose attempts all failed starts afresh
        let (ran, ..) = run(&o, None, None);
        assert_eq!(ran, [0, 1, 2, 3]);
    }

    #[test]
    fn a_resumed_pose_that_solves_records_the_earlier_failures_and_drops_its_record() {
        let d = set_dir();
        let o = opts(d.path(), "x+04", 2);
        let wd = d.path().join("fe/.work/x+04");
        run(&o, Some(1), None);
        let (ran, message, b) = run(&o, None, Some(1));
        assert_eq!((ran, message), (vec![1], String::new()), "attempt 2 resumed and solved");
        let m = read_manifest(&d.path().join("fe").join(MANIFEST)).expect("manifest");
        assert_eq!(m.pose["x+04"].retry.as_deref(), Some(failures(1, &b).join("; ").as_str()));
        assert!(!wd.exists(), "the work folder (and its record) goes once the pose solves");
    }

    #[test]
    fn another_runs_record_or_force_starts_afresh() {
        let d = set_dir();
        let o = opts(d.path(), "x+04", 2);
        let wd = d.path().join("fe/.work/x+04");
        run(&o, Some(2), None);
        // the record of another spec (its hash differs)
        let p = path(&wd);
        let text = std::fs::read_to_string(&p).expect("record");
        let rec = read(&wd).expect("readable").expect("record");
        std::fs::write(&p, text.replace(&rec.run.spec_hash, "0123")).expect("write");
        let (ran, ..) = run(&o, Some(1), None);
        assert_eq!(ran, [0, 1], "another spec's record: from attempt 1 (killed again in attempt 2)");
        let (ran, ..) = run(&RunOptions { force: true, ..o.clone() }, None, None);
        assert_eq!(ran, [0, 1, 2, 3], "--force: from attempt 1");
        // another step count is another run
        run(&o, Some(1), None);
        let (ran, ..) = run(&opts(d.path(), "x+04", 3), None, None);
        assert_eq!(ran, [0, 1, 2, 3]);
    }
}
