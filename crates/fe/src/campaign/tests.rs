//! Tests of the campaign driver with a fake solver (bookkeeping only, no physics); the
//! fake and the helpers are shared with `resume_tests` and the launcher's tests.

use super::*;
use crate::backend::{Job, SolveFailure, Solved};
use crate::mesh::summary::MeshSummary;
use crate::partial;
use crate::results::Row;
use crate::resume;
use crate::spec;
use crate::spec::Role;
use needle_contract::COMPONENT_COUNT;
use std::sync::atomic::{AtomicUsize, Ordering};

/// A solver that returns a made-up wrench (bookkeeping tests only, no physics), can
/// fail or panic on one pose, and counts its solves.
#[derive(Default)]
pub(crate) struct Fake {
    pub(crate) fail: Option<String>,
    /// Fails this pose's first attempt only (whole-step first increment).
    pub(crate) fail_first: Option<String>,
    pub(crate) panic_on: Option<String>,
    /// Fails this pose on every attempt after the first must point (attempt 2: two).
    pub(crate) fail_reached: Option<String>,
    pub(crate) solves: AtomicUsize,
    pub(crate) prepared: usize,
}

impl Backend for Fake {
    fn prepare(&mut self) -> Result<String> {
        self.prepared += 1;
        Ok("fake-1".into())
    }
    fn engine(&self) -> &'static str {
        "fake"
    }
    fn solve(&self, job: &Job<'_>) -> std::result::Result<Solved, SolveFailure> {
        self.solves.fetch_add(1, Ordering::SeqCst);
        assert!(job.work_dir.is_dir(), "work dir exists");
        if job.first_increment == 1.0 {
            let others =
                std::fs::read_dir(job.work_dir).map(|d| d.flatten().filter(|e| e.file_name() != resume::RECORD_FILE).count()).unwrap_or(9);
            assert_eq!(others, 0, "work dir is empty but for the progress record");
        }
        // a panic leaves the folder as a killed run does: only the progress record, so
        // that the rerun's resumed first attempt finds it empty too
        if self.panic_on.as_deref() == Some(job.pose.name.as_str()) {
            panic!("fake panic");
        }
        std::fs::write(job.work_dir.join("pose.log"), "fake log\n").map_err(anyhow::Error::from)?;
        if self.fail.as_deref() == Some(job.pose.name.as_str()) {
            return Err(SolveFailure { message: "fake exit code 201".into(), log_tail: "*ERROR fake".into(), reached: Vec::new() });
        }
        if self.fail_reached.as_deref() == Some(job.pose.name.as_str()) {
            let reached = (1..=job.attempt.min(1) + 1).map(|k| [0.0, f64::from(k), 0.0, 0.0, 0.0, 0.0]).collect();
            return Err(SolveFailure { message: format!("fake stop {}", job.attempt), log_tail: String::new(), reached });
        }
        if self.fail_first.as_deref() == Some(job.pose.name.as_str()) && job.first_increment == 1.0 {
            return Err(SolveFailure { message: "fake stall".into(), log_tail: String::new(), reached: Vec::new() });
        }
        let wrenches = (1..=job.steps)
            .map(|k| {
                let d = job.campaign.loading.depth_at(k);
                [job.pose.x_mm * d, d * d, job.pose.z_mm, 0.0, 0.0, 0.0]
            })
            .collect();
        let summary = MeshSummary {
            tissue_nodes: 1,
            tissue_elements: 2,
            needle_nodes: 3,
            needle_elements: 4,
            model: "fake".into(),
            tissue_mesh: "fake".into(),
        };
        Ok(Solved {
            wrenches,
            summary,
            increments: job.steps,
            iterations: 2 * job.steps,
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

/// [`super::run_with`] on the set of `o.set_dir`, opened afresh: the tests change the spec
/// and the manifest between runs, as a user between two commands.
pub(crate) fn run_with(o: &RunOptions, backend: &mut dyn Backend) -> Result<Report> {
    super::run_with(&SetFolder::open(&o.set_dir)?, o, backend)
}

/// [`super::plan`] on the set of `o.set_dir`, opened afresh.
pub(crate) fn plan(o: &RunOptions) -> Result<Plan> {
    super::plan(&SetFolder::open(&o.set_dir)?, o)
}

pub(crate) fn set_dir() -> tempfile::TempDir {
    let d = tempfile::tempdir().expect("tempdir");
    let src = needle_stdx::workspace_root().join("coeffs/default/campaign.toml");
    std::fs::copy(&src, d.path().join("campaign.toml")).expect("copy the default spec");
    d
}

pub(crate) fn opts(dir: &Path, only: &str, steps: u32) -> RunOptions {
    RunOptions { only: Some(only.into()), steps: Some(steps), mesh: Some("smoke".into()), jobs: 2, ..RunOptions::new(dir) }
}

/// Issue 42, item 3: the replacement of a training pose that failed every attempt
/// records which pose it replaces and why (the spec's words and the partial record).
#[test]
fn a_replacement_records_what_it_replaces_and_the_status_counts_the_slots() {
    let d = set_dir();
    let (c, _) = spec::load(d.path()).expect("spec");
    let r = c.campaign.train_replaced.first().expect("the default set replaces a training pose").clone();
    let by = c.replacement_of(&r.pose).expect("its replacement");
    let mut fake = Fake { fail_reached: Some(r.pose.clone()), ..Fake::default() };
    let failed = run_with(&opts(d.path(), &r.pose, 4), &mut fake).expect("run");
    assert_eq!(failed.failed(), 1, "{}", failed.table());
    let solved = run_with(&opts(d.path(), &by, 4), &mut Fake::default()).expect("run");
    assert_eq!(solved.done(), 1, "{}", solved.table());
    let m = read_manifest(&d.path().join("fe").join(MANIFEST)).expect("manifest");
    let e = &m.pose[&by];
    assert_eq!(e.replaces.as_deref(), Some(r.pose.as_str()));
    let because = e.replaced_because.clone().unwrap_or_default();
    assert!(because.starts_with(&r.why) && because.contains("its record: reached 3 mm of 6") && because.contains("fake stop"), "{because}");
    // the status's counts of the same runs: launcher::status's tests
}

#[test]
fn writes_results_and_skips_up_to_date_poses() {
    let d = set_dir();
    let mut fake = Fake::default();
    let o = opts(d.path(), "x+0[24]", 2);
    let r = run_with(&o, &mut fake).expect("run");
    assert_eq!((r.done(), r.up_to_date(), r.failed()), (2, 0, 0), "{}", r.table());
    let fe = d.path().join("fe");
    for name in ["x+02", "x+04"] {
        let rows = crate::results::read_csv(&fe.join(format!("{name}.csv"))).expect("csv");
        assert_eq!(rows.len(), 3);
        assert_eq!(rows[0], Row { depth_mm: 0.0, wrench: [0.0; COMPONENT_COUNT] });
        assert_eq!(rows.iter().map(|r| r.depth_mm).collect::<Vec<_>>(), [0.0, 3.0, 6.0]);
        assert_eq!(rows[2].wrench[1], 36.0);
        assert!(!fe.join(".work").join(name).exists(), "work dir removed on success");
    }
    let text = std::fs::read_to_string(fe.join(MANIFEST)).expect("manifest");
    let m = read_manifest(&fe.join(MANIFEST)).expect("parse");
    assert_eq!(m.pose.keys().cloned().collect::<Vec<_>>(), ["x+02", "x+04"]);
    assert!(text.find("[pose.\"x+02\"]") < text.find("[pose.\"x+04\"]"), "sorted:\n{text}");
    let (mut c, _) = spec::load(d.path()).expect("spec");
    c.loading.steps = 2;
    let p4 = c.poses().into_iter().find(|p| p.name == "x+04").expect("x+04");
    let e = &m.pose["x+04"];
    assert_eq!(e.spec_hash, c.run_hash(&p4, "smoke"));
    assert_eq!((e.engine_version.as_str(), e.mesh.as_str(), e.steps, e.increments, e.iterations), ("fake-1", "smoke", 2, 2, 4));
    assert_eq!((e.x_mm, e.role), (4.0, Role::SweepX));
    assert_eq!(e.date.len(), "2025-01-01T00:00:00Z".len());
    assert_eq!(fake.solves.load(Ordering::SeqCst), 2);

    // rerun: nothing to do, the solver is not even prepared, files untouched
    let mut again = Fake::default();
    let r = run_with(&o, &mut again).expect("rerun");
    assert_eq!((r.done(), r.up_to_date()), (0, 2));
    assert_eq!((again.prepared, again.solves.load(Ordering::SeqCst)), (0, 0));
    assert_eq!(std::fs::read_to_string(fe.join(MANIFEST)).expect("manifest"), text);
    assert!(r.table().contains("up to date"));
    assert_eq!(r.poses[0].fy_final_n, Some(36.0));

    // another step count is another spec: rerun
    let r = run_with(&opts(d.path(), "x+02", 3), &mut again).expect("steps 3");
    assert_eq!(r.done(), 1);
    assert_eq!(crate::results::read_csv(&fe.join("x+02.csv")).expect("csv").len(), 4);
    // --force reruns an up-to-date pose
    let r = run_with(&RunOptions { force: true, ..opts(d.path(), "x+04", 2) }, &mut again).expect("force");
    assert_eq!(r.done(), 1);
    // a CSV deleted by hand is rerun even though the manifest has its entry
    std::fs::remove_file(fe.join("x+04.csv")).expect("rm");
    let r = run_with(&o, &mut again).expect("missing csv");
    assert_eq!((r.done(), r.up_to_date()), (2, 0), "x+02 has 4 rows (3 steps), x+04 has no CSV");
}

/// The bytes of every CSV and the manifest in `fe`.
fn snapshot(fe: &Path) -> Vec<(String, Vec<u8>)> {
    let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(fe)
        .expect("fe folder")
        .flatten()
        .filter(|e| e.path().is_file())
        .map(|e| (e.file_name().to_string_lossy().into_owned(), std::fs::read(e.path()).expect("read")))
        .collect();
    files.sort();
    files
}

/// Issue 18: a solver killed mid-run, an unwritable result file and a corrupted
/// manifest each leave every earlier result intact, and the next run completes the set.
#[test]
fn faults_leave_earlier_results_intact_and_the_next_run_completes_the_set() {
    let d = set_dir();
    let fe = d.path().join("fe");
    run_with(&opts(d.path(), "x+0[24]", 2), &mut Fake::default()).expect("first results");
    let before = snapshot(&fe);
    let all = "x+0[2468]";

    // 1. the solver is killed while solving x+06 (and x+08 in the same run finishes)
    let mut killed = Fake { fail: Some("x+06".into()), ..Fake::default() };
    let r = run_with(&opts(d.path(), all, 2), &mut killed).expect("run");
    assert_eq!((r.done(), r.up_to_date(), r.failed()), (1, 2, 1), "{}", r.table());
    let after: Vec<_> = snapshot(&fe).into_iter().filter(|(n, _)| n != "x+08.csv" && n != MANIFEST).collect();
    assert_eq!(after, before.iter().filter(|(n, _)| n != MANIFEST).cloned().collect::<Vec<_>>(), "earlier CSVs intact");
    let m = read_manifest(&fe.join(MANIFEST)).expect("manifest");
    assert_eq!(m.pose.keys().cloned().collect::<Vec<_>>(), ["x+02", "x+04", "x+08"], "no entry for the killed x+06");

    // 2. x+06's result file cannot be written (a folder is in its place)
    std::fs::create_dir(fe.join("x+06.csv")).expect("block the CSV path");
    let r = run_with(&opts(d.path(), all, 2), &mut Fake::default()).expect("run");
    assert_eq!((r.done(), r.up_to_date(), r.failed()), (0, 3, 1), "{}", r.table());
    assert!(r.table().contains("x+06.csv"), "the failure names the file:\n{}", r.table());
    let intact = snapshot(&fe);
    std::fs::remove_dir(fe.join("x+06.csv")).expect("unblock");

    // 3. the manifest is corrupted: refused before anything is solved or written
    let manifest = fe.join(MANIFEST);
    let good = std::fs::read(&manifest).expect("manifest");
    std::fs::write(&manifest, b"[pose.x+02\nspec_hash = ").expect("corrupt");
    let mut untouched = Fake::default();
    let e = run_with(&opts(d.path(), all, 2), &mut untouched).expect_err("corrupt manifest");
    assert!(format!("{e:#}").contains(MANIFEST), "{e:#}");
    assert_eq!(untouched.solves.load(Ordering::SeqCst), 0);
    std::fs::write(&manifest, &good).expect("restore the manifest (from git, say)");
    assert_eq!(snapshot(&fe), intact, "every result as before the faults");

    // temporaries a killed campaign left beside its targets (a pid that is gone)
    let stale = [fe.join(".x+06.csv.4194303.tmp"), fe.join(format!(".{MANIFEST}.4194303.tmp"))];
    for t in &stale {
        std::fs::write(t, b"half").expect("stale temporary");
    }
    let mut intact = intact;
    intact.extend(stale.iter().map(|t| (t.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default(), b"half".to_vec())));
    intact.sort();
    assert_eq!(snapshot(&fe), intact);

    // the next run completes the set, solving only x+06, and removes the temporaries
    let mut last = Fake::default();
    let r = run_with(&opts(d.path(), all, 2), &mut last).expect("run");
    assert_eq!((r.done(), r.up_to_date(), r.failed()), (1, 3, 0), "{}", r.table());
    assert_eq!(last.solves.load(Ordering::SeqCst), 1);
    assert!(stale.iter().all(|t| !t.exists()), "stale temporaries removed");
    for (name, bytes) in &before {
        if name != MANIFEST {
            assert_eq!(&std::fs::read(fe.join(name)).expect("read"), bytes, "{name} unchanged through the faults");
        }
    }
}

#[test]
fn a_failed_pose_keeps_its_work_dir_and_the_others_finish() {
    let d = set_dir();
    let fe = d.path().join("fe");
    // a first, good result of x+04
    run_with(&opts(d.path(), "x+04", 2), &mut Fake::default()).expect("first");
    assert!(fe.join("x+04.csv").exists());

    let mut fake = Fake { fail: Some("x+04".into()), panic_on: Some("x+06".into()), ..Fake::default() };
    let r = run_with(&RunOptions { force: true, ..opts(d.path(), "x+0[246]", 2) }, &mut fake).expect("run");
    assert_eq!((r.done(), r.failed()), (1, 2), "{}", r.table());
    let t = r.table();
    assert!(t.contains("FAILED x+04: fake exit code 201") && t.contains("| *ERROR fake"), "{t}");
    assert!(t.contains("FAILED x+06: panic while solving: fake panic"), "{t}");
    assert!(fe.join(".work/x+04/pose.log").exists(), "work dir kept on failure");
    assert!(!fe.join("x+06.csv").exists());
    // the failed --force rerun cost nothing: x+04's first CSV and its entry are intact
    // (issue 18: the entry used to be deleted, and `needle fit` then refused the set)
    let m = read_manifest(&fe.join(MANIFEST)).expect("manifest");
    assert_eq!(m.pose.keys().cloned().collect::<Vec<_>>(), ["x+02", "x+04"]);
    assert_eq!(crate::results::read_csv(&fe.join("x+04.csv")).expect("csv").len(), 3, "the first result's CSV");
    // so the next run only solves x+06
    let mut ok = Fake::default();
    let r = run_with(&opts(d.path(), "x+0[246]", 2), &mut ok).expect("resume");
    assert_eq!((r.done(), r.up_to_date(), r.failed()), (1, 2, 0), "{}", r.table());
    assert!(fe.join("x+06.csv").exists());
}

#[test]
fn a_failed_run_is_retried_once_with_a_smaller_first_increment_and_the_manifest_says_so() {
    let d = set_dir();
    let mut fake = Fake { fail_first: Some("x+04".into()), ..Fake::default() };
    let r = run_with(&opts(d.path(), "x+0[24]", 2), &mut fake).expect("run");
    assert_eq!((r.done(), r.failed()), (2, 0), "{}", r.table());
    assert_eq!(fake.solves.load(Ordering::SeqCst), 3, "x+02 once, x+04 twice");
    let m = read_manifest(&d.path().join("fe").join(MANIFEST)).expect("manifest");
    let (x2, x4) = (&m.pose["x+02"], &m.pose["x+04"]);
    assert_eq!((x2.first_increment, x2.retry.as_deref()), (None, None));
    assert_eq!((x4.first_increment, x4.retry.as_deref()), (Some(crate::backend::RETRY_FIRST_INCREMENT), Some("fake stall")));
    let text = std::fs::read_to_string(d.path().join("fe").join(MANIFEST)).expect("manifest text");
    assert_eq!(text.matches("first_increment = 0.25").count(), 1, "{text}");
    assert_eq!(text.matches("retry = \"fake stall\"").count(), 1, "{text}");
}

/// Issue 42: a run its first attempt solved stays current when only settings of the
/// retry ladder's later attempts change (`retry_dtol`); a run a retry solved is solved
/// again; an entry from before the first attempt's hash gets it on the next run.
#[test]
fn a_change_of_the_later_attempts_settings_reruns_only_the_runs_they_solved() {
    let d = set_dir();
    let mut fake = Fake { fail_first: Some("x+04".into()), ..Fake::default() };
    let r = run_with(&opts(d.path(), "x+0[24]", 2), &mut fake).expect("run");
    assert_eq!((r.done(), r.failed()), (2, 0), "{}", r.table());
    let path = d.path().join("fe").join(MANIFEST);
    let m = read_manifest(&path).expect("manifest");
    let first = m.pose["x+02"].first_attempt_hash.clone();
    assert!(first.is_some() && m.pose["x+04"].first_attempt_hash.is_none(), "{m:?}");
    // an entry written before the hash existed gets it from the next run
    let mut old = m.clone();
    if let Some(e) = old.pose.get_mut("x+02") {
        e.first_attempt_hash = None;
    }
    std::fs::write(&path, manifest_text(&old).expect("text")).expect("write");
    let r = run_with(&opts(d.path(), "x+04", 2), &mut Fake::default()).expect("run");
    assert_eq!(r.up_to_date(), 1, "{}", r.table());
    assert_eq!(read_manifest(&path).expect("manifest").pose["x+02"].first_attempt_hash, first);
    // the retry's displacement tolerance changes: x+04 (solved by the retry) is stale
    let spec_path = d.path().join("campaign.toml");
    let text = std::fs::read_to_string(&spec_path).expect("spec");
    assert!(text.contains("[solver.febio]\n") && !text.contains("\nretry_dtol"), "the default set's [solver.febio]");
    std::fs::write(&spec_path, text.replacen("[solver.febio]\n", "[solver.febio]\nretry_dtol = 0.0005\n", 1)).expect("write");
    let mut fake = Fake::default();
    let r = run_with(&opts(d.path(), "x+0[24]", 2), &mut fake).expect("run");
    assert_eq!((r.done(), r.up_to_date()), (1, 1), "{}", r.table());
    assert_eq!(fake.solves.load(Ordering::SeqCst), 1, "x+04 only");
    let m = read_manifest(&path).expect("manifest");
    assert_eq!(m.pose["x+02"].first_attempt_hash, first, "x+02 kept");
    assert!(m.pose["x+04"].first_attempt_hash.is_some(), "x+04 solved again, by its first attempt now");
}

/// `--deep`: the [deep] poses only, to the deep depth, into fe/deep/ with its own
/// manifest; the shallow results are not touched.
#[test]
fn deep_runs_go_to_their_own_folder_at_the_deep_depth() {
    let d = set_dir();
    let deep = |only: &str| RunOptions {
        deep: true,
        only: Some(only.into()),
        mesh: Some("smoke".into()),
        steps: Some(5),
        ..RunOptions::new(d.path())
    };
    let (c, _) = spec::load(d.path()).expect("spec");
    let depth_mm = c.deep.as_ref().map(|d| d.depth_mm).expect("a [deep] section");
    let r = run_with(&deep("centre"), &mut Fake::default()).expect("deep run");
    assert_eq!((r.done(), r.depth_mm), (1, depth_mm), "{}", r.table());
    let rows = crate::results::read_csv(&d.path().join("fe/deep/centre.csv")).expect("deep csv");
    let want: Vec<f64> = (0..=5).map(|k| depth_mm * f64::from(k) / 5.0).collect();
    assert_eq!(rows.iter().map(|r| r.depth_mm).collect::<Vec<_>>(), want);
    assert_eq!(rows[5].wrench[1], depth_mm * depth_mm, "the fake's depth squared at the deep depth");
    assert!(!d.path().join("fe/centre.csv").exists(), "nothing written beside the shallow runs");
    let m = read_manifest(&d.path().join("fe/deep").join(MANIFEST)).expect("deep manifest");
    assert_eq!((m.pose["centre"].depth_mm, m.pose["centre"].steps), (depth_mm, 5));
    let again = run_with(&deep("centre"), &mut Fake::default()).expect("rerun");
    assert_eq!(again.up_to_date(), 1, "resumes like the campaign");
    let e = run_with(&deep("x+02"), &mut Fake::default()).err().map(|e| e.to_string()).unwrap_or_default();
    assert!(e.contains("matches no pose (poses: centre, x+04, tz+08, z+04)"), "{e}");
}

/// The material family's runs (issue 64) go to `fe/family/` under their member names, at
/// the family's depth for a centre and the campaign's for a check, each with its member's
/// one-term tissue in its manifest entry's hash; the campaign's own results are untouched.
#[test]
fn family_runs_go_to_their_own_folder_with_the_members_tissue() {
    use crate::family::FamilyRun;
    let d = set_dir();
    let (c, _) = spec::load(d.path()).expect("spec");
    let f = c.family.clone().expect("a [family] section");
    let weight = *f.weight.first().expect("a member");
    let run = |r: FamilyRun| RunOptions { family_run: Some(r), mesh: Some("smoke".into()), steps: Some(4), ..RunOptions::new(d.path()) };
    let r = run_with(&run(FamilyRun::Centre { weight }), &mut Fake::default()).expect("family centre");
    assert_eq!((r.done(), r.depth_mm), (1, f.depth_mm), "{}", r.table());
    let name = spec::family::member_name("centre", weight);
    let rows = crate::results::read_csv(&d.path().join(format!("fe/family/{name}.csv"))).expect("family csv");
    assert_eq!(rows.last().map(|r| r.depth_mm), Some(f.depth_mm));
    assert!(!d.path().join("fe/centre.csv").exists(), "nothing written beside the campaign's runs");
    let m = read_manifest(&d.path().join("fe/family").join(MANIFEST)).expect("family manifest");
    let (member, poses, _) = crate::family::apply(&c, &f, FamilyRun::Centre { weight });
    let mut member = member;
    member.loading.steps = 4;
    let pose = poses.first().expect("the centre");
    assert_eq!(m.pose[&name].spec_hash, member.run_hash(pose, "smoke"), "the member's tissue is in the hash");
    let check = *f.check_weight.first().expect("a check member");
    let r = run_with(&run(FamilyRun::Check { weight: check }), &mut Fake::default()).expect("family checks");
    assert_eq!((r.done(), r.depth_mm), (f.check_poses.len(), c.loading.depth_mm), "{}", r.table());
    let again = run_with(&run(FamilyRun::Centre { weight }), &mut Fake::default()).expect("rerun");
    assert_eq!(again.up_to_date(), 1, "resumes like the campaign");
    let both = RunOptions { deep: true, ..run(FamilyRun::Centre { weight }) };
    assert!(run_with(&both, &mut Fake::default()).is_err(), "--family with --deep is refused");
}

/// A pose that fails every attempt keeps the furthest attempt's must points as its
/// partial record; solving it later removes the record.
#[test]
fn a_pose_failing_every_attempt_keeps_its_furthest_must_points() {
    let d = set_dir();
    let fe = d.path().join("fe");
    let mut fake = Fake { fail_reached: Some("x+04".into()), ..Fake::default() };
    let r = run_with(&opts(d.path(), "x+04", 4), &mut fake).expect("run");
    assert_eq!(r.failed(), 1, "{}", r.table());
    assert!(r.table().contains("the 2 must point(s) reached are kept in x+04.partial.csv"), "{}", r.table());
    let (csv, rec) = partial::paths(&fe, "x+04");
    let rows = crate::results::read_csv(&csv).expect("partial csv");
    assert_eq!(rows.iter().map(|r| (r.depth_mm, r.fy_n())).collect::<Vec<_>>(), [(0.0, 0.0), (1.5, 1.0), (3.0, 2.0)]);
    let text = std::fs::read_to_string(&rec).expect("record");
    assert!(text.contains("reached_depth_mm = 3.0") && text.contains("fake stop 0; retry 1"), "{text}");
    assert!(!fe.join("x+04.csv").exists(), "no result");
    let r = run_with(&opts(d.path(), "x+04", 4), &mut Fake::default()).expect("solved");
    assert_eq!(r.done(), 1);
    assert!(!csv.exists() && !rec.exists(), "the record goes once the pose solves");
}

#[test]
fn refuses_bad_options_and_a_corrupt_manifest_before_solving() {
    let d = set_dir();
    let mut fake = Fake::default();
    let e = run_with(&opts(d.path(), "nothing*", 2), &mut fake).expect_err("no pose").to_string();
    assert!(e.contains("matches no pose"), "{e}");
    let e = run_with(&RunOptions { mesh: Some("huge".into()), ..opts(d.path(), "x+02", 2) }, &mut fake).expect_err("mesh").to_string();
    assert!(e.contains("huge"), "{e}");
    let e = run_with(&opts(d.path(), "x+02", 0), &mut fake).expect_err("steps").to_string();
    assert!(e.contains("--steps 0"), "{e}");
    std::fs::create_dir_all(d.path().join("fe")).expect("mkdir");
    std::fs::write(d.path().join("fe").join(MANIFEST), "[pose.x]\nspec_hash = 1\n").expect("write");
    let e = run_with(&opts(d.path(), "x+02", 2), &mut fake).expect_err("manifest").to_string();
    assert!(e.contains("delete it"), "{e}");
    assert_eq!((fake.prepared, fake.solves.load(Ordering::SeqCst)), (0, 0));
}

/// The poses a plan would solve are "not run" until their solve reports, never "up to
/// date": an interruption before they start must not show them as current.
#[test]
fn the_poses_a_plan_would_solve_are_not_run_until_they_report() {
    let d = set_dir();
    let plan = plan(&opts(d.path(), "centre,x+04", 4)).expect("plan");
    assert_eq!(plan.to_run.len(), 2, "nothing solved yet: both stale");
    for r in &plan.reports {
        assert_eq!(r.status, crate::report::Status::NotRun, "{}", r.pose);
    }
}
