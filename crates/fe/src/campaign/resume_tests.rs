//! Tests of the campaign's resume (`crate::resume`): a run killed in the middle of a pose
//! goes on at its attempt (also a `--force` rerun of an up-to-date pose, resumed without
//! `--force`); another run's record, `--force` and a pose whose attempts all
//! failed start afresh (with `--skip-failed` the last is not run again). (A module of `campaign`, in its own file: `resume` holds the
//! record, `campaign` uses it, these tests use both.)

use crate::backend::{Backend, Job, SolveFailure, Solved};
use crate::campaign::tests::run_with;
use crate::campaign::tests::{opts, set_dir};
use crate::campaign::RunOptions;
use crate::manifest::{read_manifest, MANIFEST};
use crate::mesh::summary::MeshSummary;
use crate::resume::{path, read};
use anyhow::Result;
use std::path::Path;
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

    // with --skip-failed a pose whose attempts all failed is not run again: reported
    // failed with the recorded failures, its record kept
    let skip = RunOptions { skip_failed: true, ..o.clone() };
    let (ran, again, _) = run(&skip, None, None);
    assert!(ran.is_empty(), "no attempt runs: {ran:?}");
    assert_eq!(
        again,
        format!(
            "not run again (--skip-failed): all 4 attempts of this spec failed in an earlier run: {}",
            failures(ATTEMPTS, &b).join("; ")
        )
    );
    assert!(read(&wd).expect("readable").is_some(), "its record and logs stay");

    // without it, the pose starts afresh
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

#[test]
fn an_interrupted_forced_rerun_of_an_up_to_date_pose_resumes_without_force() {
    let d = set_dir();
    let o = opts(d.path(), "x+04", 2);
    let (ran, ..) = run(&o, None, Some(0));
    assert_eq!(ran, [0], "solved by attempt 1");
    let (ran, ..) = run(&o, None, None);
    assert!(ran.is_empty(), "up to date: skipped ({ran:?})");
    // a --force rerun killed in its attempt 2: the earlier result and its entry stay
    let (ran, ..) = run(&RunOptions { force: true, ..o.clone() }, Some(1), None);
    assert_eq!(ran, [0, 1]);
    let m = read_manifest(&d.path().join("fe").join(MANIFEST)).expect("manifest");
    assert_eq!(m.pose["x+04"].retry, None, "the first run's entry");
    let plan = crate::campaign::tests::plan(&o).expect("plan");
    assert_eq!(plan.to_run, [0], "solved again to resume");
    assert!(plan.selected.iter().all(|p| plan.resumes_forced_rerun(p)));
    // a rerun without --force goes on with the forced run at its attempt 2
    let (ran, message, b) = run(&o, None, Some(2));
    assert_eq!((ran, message), (vec![1, 2], String::new()), "attempts 2 and 3, solved by 3");
    let m = read_manifest(&d.path().join("fe").join(MANIFEST)).expect("manifest");
    assert_eq!(m.pose["x+04"].retry.as_deref(), Some(failures(2, &b).join("; ").as_str()), "the forced run's entry");
    let (ran, ..) = run(&o, None, None);
    assert!(ran.is_empty(), "up to date again ({ran:?})");
}

/// The FEBio backend with its solver given (`prepare` would look for the real one).
struct Given(crate::febio::FebioBackend);

impl crate::backend::Backend for Given {
    fn prepare(&mut self) -> Result<String> {
        Ok("4.11.0".into())
    }
    fn engine(&self) -> &'static str {
        self.0.engine()
    }
    fn attempts(&self) -> u32 {
        self.0.attempts()
    }
    fn first_increment_in(&self, work_dir: &Path, attempt: u32, full_block: bool) -> f64 {
        self.0.first_increment_in(work_dir, attempt, full_block)
    }
    fn describe_attempt(&self, work_dir: &Path, attempt: u32, full_block: bool, depth_mm: f64, steps: u32) -> String {
        self.0.describe_attempt(work_dir, attempt, full_block, depth_mm, steps)
    }
    fn solve(&self, job: &crate::backend::Job<'_>) -> crate::febio::running::tests::Solve {
        self.0.solve(job)
    }
    fn steps_done(&self, work_dir: &Path) -> u32 {
        self.0.steps_done(work_dir)
    }
}

/// The campaign and FEBio together: a campaign killed in the first FEBio process of
/// `centre` (its work folder as the fake left it: `progress.toml`, `running.toml`, the
/// dump) resumes the pose with one restart, and writes the uninterrupted run's CSV with
/// "resumed after an interruption at 3 mm" in the manifest.
#[test]
fn a_killed_campaign_resumes_its_febio_pose_from_the_dump() {
    use crate::febio::running::tests::{backend_with, calls, dump_bytes, killed};
    let d = set_dir();
    let k = killed(d.path());
    std::fs::write(&k.dump, dump_bytes(3.0, true)).expect("fixture");
    let mut backend = Given(backend_with(&k.exe));
    let o = crate::campaign::RunOptions { jobs: 1, ..opts(d.path(), "centre", 4) };
    let fe = d.path().join("fe");
    let r = run_with(&o, &mut backend).expect("the run that was not killed");
    assert_eq!(r.done(), 1, "{}", r.table());
    let whole = std::fs::read(fe.join("centre.csv")).expect("csv");
    assert_eq!(calls(&k), ["-i", "-r"], "the first process gave up at 3.2 mm and was continued");
    let rec = crate::resume::read(&k.snap).expect("readable").expect("the campaign's record in the killed folder");
    assert_eq!((rec.attempt, rec.failures.len()), (0, 0));

    // the killed campaign's state: no result yet, the work folder as the kill left it
    for f in ["centre.csv", MANIFEST] {
        std::fs::remove_file(fe.join(f)).expect("remove");
    }
    let work = fe.join(".work/centre");
    std::fs::create_dir_all(&work).expect("mkdir");
    for e in std::fs::read_dir(&k.snap).expect("snapshot").flatten() {
        std::fs::copy(e.path(), work.join(e.file_name())).expect("copy");
    }
    let r = run_with(&o, &mut backend).expect("the rerun");
    assert_eq!(r.done(), 1, "{}", r.table());
    assert_eq!(calls(&k), ["-r"], "resumed from the dump, not from depth 0");
    assert_eq!(std::fs::read(fe.join("centre.csv")).expect("csv"), whole, "the uninterrupted run's result");
    let m = read_manifest(&fe.join(MANIFEST)).expect("manifest");
    let e = &m.pose["centre"];
    assert!(e.solver_settings.ends_with("; resumed after an interruption at 3 mm"), "{}", e.solver_settings);
    assert_eq!(e.retry, None, "attempt 1 solved");
}
