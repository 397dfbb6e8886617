//! `needle fe run --launcher slurm` on a real SLURM cluster (`.ci/slurm-cluster start`:
//! slurmctld and slurmd on this machine, Debian's slurm-wlm 22.05): a smoke campaign
//! through `sbatch` whose CSVs equal a local run's, an array task cancelled mid-run and
//! resubmitted alone, and the clear errors that leave the set unchanged. Without a
//! running cluster these tests fail, they are not skipped.

mod common;
use common::{campaign_copy, needle_env, show};

use needle_set::manifest::{read_manifest, MANIFEST};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

const POSES: &str = "centre,x+04,z+04";

/// Fail unless sbatch is installed, the controller answers and a node takes jobs. A node
/// still completing the previous test's cancelled job (state `comp`, seen for over 40 s
/// while two FEBio jobs loaded the machine) is waited for, up to [`NODE_READY_LIMIT`].
fn require_cluster() {
    let start = Instant::now();
    loop {
        let out = Command::new("sinfo")
            .args(["-h", "-o", "%t"])
            .output()
            .unwrap_or_else(|e| panic!("sinfo: {e}: these tests need a running SLURM cluster: start one with .ci/slurm-cluster start"));
        let states = String::from_utf8_lossy(&out.stdout);
        let state = |want: &[&str]| states.lines().any(|s| want.contains(&s.trim()));
        if out.status.success() && state(&["idle", "mix", "alloc"]) {
            return;
        }
        assert!(
            out.status.success() && state(&["comp"]) && start.elapsed() < NODE_READY_LIMIT,
            "no usable SLURM node after {:.0} s (sinfo: {states:?}, {}): start the cluster with .ci/slurm-cluster start",
            start.elapsed().as_secs_f64(),
            String::from_utf8_lossy(&out.stderr)
        );
        std::thread::sleep(Duration::from_secs(1));
    }
}

/// How long [`require_cluster`] waits for a completing node.
const NODE_READY_LIMIT: Duration = Duration::from_secs(300);

fn spec_args<'a>(set: &'a str, steps: &'a str) -> Vec<&'a str> {
    vec!["--set", set, "--solver", "ccx", "--mesh", "smoke", "--steps", steps, "--only", POSES]
}

/// Submit (`fe run --launcher slurm`); the job id.
fn submit(set: &str, steps: &str) -> (String, Output) {
    let mut a = vec!["fe", "run"];
    a.extend(spec_args(set, steps));
    a.extend(["--launcher", "slurm"]);
    let out = needle_env(&a, &[]);
    assert!(out.status.success(), "{}", show(&out));
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    let id = text
        .lines()
        .find_map(|l| l.strip_prefix("submitted job array ").and_then(|r| r.split_whitespace().next()))
        .map(str::to_string)
        .unwrap_or_default();
    (id, out)
}

/// The tasks of `job` still in the queue.
fn queued(job: &str) -> Vec<String> {
    let out = Command::new("squeue").args(["-h", "--array", "-j", job, "-o", "%i %T"]).output().expect("squeue");
    String::from_utf8_lossy(&out.stdout).lines().map(str::to_string).filter(|l| !l.trim().is_empty()).collect()
}

/// Wait until none of `job`'s tasks is in the queue (at most `limit`).
fn wait_for(job: &str, limit: Duration) {
    let start = Instant::now();
    while !queued(job).is_empty() {
        assert!(start.elapsed() < limit, "job {job} still queued after {limit:?}: {:?}", queued(job));
        std::thread::sleep(Duration::from_millis(500));
    }
}

fn status(set: &str, steps: &str) -> String {
    let mut a = vec!["fe", "status"];
    a.extend(spec_args(set, steps));
    let out = needle_env(&a, &[]);
    assert!(out.status.success(), "{}", show(&out));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The state column of `pose` in `needle fe status`.
fn state_of(table: &str, pose: &str) -> String {
    table.lines().find(|l| l.split_whitespace().next() == Some(pose)).and_then(|l| l.split_whitespace().nth(1)).unwrap_or("").to_string()
}

/// Every file under `dir` with its bytes, sorted by path.
fn tree(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut v = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).expect("read_dir") {
            let p = e.expect("entry").path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let bytes = std::fs::read(&p).expect("read");
                v.push((p, bytes));
            }
        }
    }
    v.sort();
    v
}

#[test]
fn a_campaign_through_sbatch_equals_a_local_run() {
    require_cluster();
    let (_tmp, set) = campaign_copy();
    let s = set.to_str().expect("utf-8 path");
    let (job, out) = submit(s, "2");
    assert!(!job.is_empty(), "no job id: {}", show(&out));
    assert!(String::from_utf8_lossy(&out.stdout).contains("with 3 task(s): centre, x+04, z+04"), "{}", show(&out));
    wait_for(&job, Duration::from_secs(300));
    let table = status(s, "2");
    for p in ["centre", "x+04", "z+04"] {
        assert_eq!(state_of(&table, p), "done", "{p}:\n{table}");
    }

    // the same poses on this machine, into another folder
    let local = set.join("local");
    let mut a = vec!["fe", "run"];
    a.extend(spec_args(s, "2"));
    let local_s = local.to_str().expect("utf-8");
    a.extend(["--out", local_s, "--jobs", "2"]);
    let out = needle_env(&a, &[]);
    assert!(out.status.success(), "{}", show(&out));

    let slurm_m = read_manifest(&set.join("fe").join(MANIFEST)).expect("slurm manifest");
    let local_m = read_manifest(&local.join(MANIFEST)).expect("local manifest");
    for (i, p) in ["centre", "x+04", "z+04"].iter().enumerate() {
        let from_slurm = std::fs::read(set.join("fe").join(format!("{p}.csv"))).expect("slurm csv");
        let from_local = std::fs::read(local.join(format!("{p}.csv"))).expect("local csv");
        assert_eq!(from_slurm, from_local, "{p}: the CSV of the array task differs from the local run's");
        let (e, l) = (&slurm_m.pose[*p], &local_m.pose[*p]);
        assert_eq!((e.launcher.as_deref(), l.launcher.as_deref()), (Some("slurm"), Some("local")), "{p}");
        assert_eq!(e.batch_job.as_deref(), Some(format!("{job}_{i}").as_str()), "{p}");
        assert_eq!((&e.spec_hash, &e.csv_sha256), (&l.spec_hash, &l.csv_sha256), "{p}");
        assert!(e.peak_rss_mib.is_some_and(|m| m > 1.0), "{p}: peak memory measured: {e:?}");
    }
    // the whole campaign is up to date: nothing to submit
    let (again, out) = submit(s, "2");
    assert!(again.is_empty(), "{}", show(&out));
    assert!(
        String::from_utf8_lossy(&out.stdout).contains("3 up to date") && String::from_utf8_lossy(&out.stdout).contains("nothing to submit"),
        "{}",
        show(&out)
    );
}

#[test]
fn a_cancelled_task_is_resubmitted_alone_and_nothing_finished_is_redone() {
    require_cluster();
    let (_tmp, set) = campaign_copy();
    let s = set.to_str().expect("utf-8 path");
    // 8 steps: x+04 (a half model) takes about 10 s on the smoke mesh, long enough to
    // be cancelled after its first step
    let (job, out) = submit(s, "8");
    assert!(!job.is_empty(), "{}", show(&out));
    let work = set.join("fe/.work/x+04");
    let start = Instant::now();
    loop {
        if needle_fe::ccx::steps_done(&work, "pose") >= 1 {
            break;
        }
        assert!(start.elapsed() < Duration::from_secs(240), "x+04 never finished a step: {:?}", queued(&job));
        std::thread::sleep(Duration::from_millis(100));
    }
    let cancel = Command::new("scancel").arg(format!("{job}_1")).output().expect("scancel");
    assert!(cancel.status.success(), "scancel: {}", String::from_utf8_lossy(&cancel.stderr));
    wait_for(&job, Duration::from_secs(300));
    let table = status(s, "8");
    assert_eq!(state_of(&table, "x+04"), "cancelled", "{table}");
    assert!(table.contains("CANCELLED"), "the cause is stated:\n{table}");
    for p in ["centre", "z+04"] {
        assert_eq!(state_of(&table, p), "done", "{p}:\n{table}");
    }
    let fe = set.join("fe");
    assert!(!fe.join("x+04.csv").exists(), "a cancelled pose writes no CSV");
    let finished: Vec<(String, Vec<u8>)> =
        ["centre", "z+04"].iter().map(|p| (p.to_string(), std::fs::read(fe.join(format!("{p}.csv"))).expect("csv"))).collect();
    let entries_before = read_manifest(&fe.join(MANIFEST)).expect("manifest");

    // the rerun submits x+04 alone and ends complete
    let (rerun, out) = submit(s, "8");
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(!rerun.is_empty() && text.contains("2 up to date") && text.contains("with 1 task(s): x+04"), "{}", show(&out));
    wait_for(&rerun, Duration::from_secs(300));
    let table = status(s, "8");
    for p in ["centre", "x+04", "z+04"] {
        assert_eq!(state_of(&table, p), "done", "{p}:\n{table}");
    }
    for (p, bytes) in &finished {
        assert_eq!(&std::fs::read(fe.join(format!("{p}.csv"))).expect("csv"), bytes, "{p} was redone");
    }
    let after = read_manifest(&fe.join(MANIFEST)).expect("manifest");
    for p in ["centre", "z+04"] {
        assert_eq!(after.pose[p], entries_before.pose[p], "{p}: manifest entry changed");
    }
    assert_eq!(after.pose["x+04"].batch_job.as_deref(), Some(format!("{rerun}_0").as_str()));
}

#[test]
fn no_sbatch_a_down_controller_or_a_refused_job_is_one_error_and_changes_nothing() {
    require_cluster();
    let (tmp, set) = campaign_copy();
    let s = set.to_str().expect("utf-8 path");
    let before = tree(&set);
    let mut a = vec!["fe", "run"];
    a.extend(spec_args(s, "2"));
    a.extend(["--launcher", "slurm"]);

    // no sbatch on PATH
    let out = needle_env(&a, &[("PATH", "/nonexistent")]);
    assert_eq!(out.status.code(), Some(2), "{}", show(&out));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("sbatch not found on PATH") && err.contains("no file of the set changed"), "{err}");
    assert_eq!(tree(&set), before);

    // a controller that does not answer: the cluster's config with a port nobody serves
    let conf = std::fs::read_to_string("/etc/slurm/slurm.conf").expect("the cluster's slurm.conf");
    let down: String = conf.lines().map(|l| format!("{l}\n")).collect::<String>() + "SlurmctldPort=6999\n";
    let down_conf = tmp.path().join("down.conf");
    std::fs::write(&down_conf, down).expect("write");
    let out = needle_env(&a, &[("SLURM_CONF", down_conf.to_str().expect("utf-8"))]);
    assert_eq!(out.status.code(), Some(2), "{}", show(&out));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("Unable to contact slurm controller") && err.contains("Nothing was submitted"), "{err}");
    assert_eq!(err.lines().filter(|l| l.starts_with("error:")).count(), 1, "one error: {err}");
    assert_eq!(tree(&set), before);

    // a job SLURM refuses
    let mut refused = a.clone();
    refused.extend(["--partition", "no-such-partition"]);
    let out = needle_env(&refused, &[]);
    assert_eq!(out.status.code(), Some(2), "{}", show(&out));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("sbatch refused the job array") && err.contains("invalid partition"), "{err}");
    assert_eq!(tree(&set), before, "the set's files are unchanged");
}
