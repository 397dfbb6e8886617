//! `needle fe run --launcher slurm`: the poses still to solve go to SLURM as one job
//! array, one task per pose. Each task runs `needle fe run-one --pose <name>` with the
//! same spec options, which solves the pose through the campaign's own code path and
//! writes `<out>/<pose>.csv` and its manifest entry atomically, the manifest under the
//! campaign's file lock ([`lock_manifest`](crate::campaign::lock_manifest)), so
//! the folder ends exactly as a local run would leave it (plus `launcher = "slurm"` and
//! `batch_job` in the entries).
//!
//! Files, in `<out>/.slurm/` (on the shared filesystem, like the set):
//! - `submissions.toml`: one `[[submission]]` per accepted `sbatch`: job id, date, the
//!   poses by task index, the sbatch options.
//! - `<job>.sh`: the batch script as submitted (it names its poses itself: a later
//!   submission cannot change what a queued task solves).
//! - `<job>_<task>.out`: the task's output (progress, the report, a failure's cause).
//!
//! A resubmission skips the poses that are up to date and the poses whose task of an
//! earlier submission is still pending or running (`squeue`), so rerunning the command
//! after a cancelled or partly failed array submits only what is missing or stale. A
//! failed task has already had the engine's retries inside it (the same
//! [`solve_with_retry`](crate::campaign) as a local job).
//!
//! Before anything is submitted nothing of the set changes: a missing `sbatch`, a
//! controller that does not answer, or a submission that SLURM refuses is one error, and
//! `<out>/.slurm/` is only kept once a job was accepted.

use crate::campaign::{self, Plan, RunOptions};
use crate::manifest::rfc3339_utc;
use crate::process::which;
use crate::set_folder::SetFolder;
use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::SystemTime;

/// The folder of the SLURM files in the output folder.
pub const SLURM_DIR: &str = ".slurm";
/// The record of the submissions in [`SLURM_DIR`].
pub const SUBMISSIONS: &str = "submissions.toml";

/// Resources and passthrough options of the job array (`sbatch` options).
#[derive(Debug, Clone, Default)]
pub struct SlurmOptions {
    /// `--partition`; none: the cluster's default partition.
    pub partition: Option<String>,
    /// `--time` in SLURM's format (`MM`, `HH:MM:SS`, `D-HH`); none: from the measured
    /// runs ([`Resources::defaults`]).
    pub time: Option<String>,
    /// `--mem` per task (`4G`, `500M`); none: from the measured runs.
    pub mem: Option<String>,
    /// `--cpus-per-task`, also the solver threads of each task; none: 1.
    pub cpus_per_task: Option<u32>,
    /// Further `sbatch` arguments, passed as given (e.g. `--account=abc`, `--qos=long`).
    pub extra: Vec<String>,
    /// The `needle` executable the tasks run (it must be reachable from the compute
    /// nodes); none: this executable.
    pub needle: Option<PathBuf>,
}

/// `submissions.toml`.
#[derive(Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Submissions {
    /// In the order they were made.
    #[serde(default)]
    pub submission: Vec<Submission>,
}

/// One accepted job array.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Submission {
    /// SLURM's job id of the array.
    pub job_id: String,
    /// When it was submitted, UTC, RFC 3339.
    pub date: String,
    /// The pose of each array task: task `i` solves `poses[i]`.
    pub poses: Vec<String>,
    /// The `sbatch` options it was submitted with.
    pub sbatch: Vec<String>,
}

impl Submissions {
    /// The latest task of each pose: pose -> (job id, task index).
    pub fn latest_tasks(&self) -> BTreeMap<String, (String, usize)> {
        let mut m = BTreeMap::new();
        for s in &self.submission {
            for (i, p) in s.poses.iter().enumerate() {
                m.insert(p.clone(), (s.job_id.clone(), i));
            }
        }
        m
    }
}

/// Read `<out>/.slurm/submissions.toml`; a missing file is no submission.
///
/// # Errors
/// The file exists but cannot be read or parsed.
pub fn read_submissions(out_dir: &Path) -> Result<Submissions> {
    let path = out_dir.join(SLURM_DIR).join(SUBMISSIONS);
    match std::fs::read_to_string(&path) {
        Ok(t) => toml::from_str(&t).with_context(|| format!("{}: not a valid submissions record", path.display())),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(Submissions::default()),
        Err(e) => Err(e).with_context(|| format!("{}: cannot read", path.display())),
    }
}

/// The resources of a job array, from the options or the set's measured runs.
#[derive(Debug, Clone, PartialEq)]
pub struct Resources {
    /// `--cpus-per-task`.
    pub cpus_per_task: u32,
    /// `--time`, or none (the partition's default).
    pub time: Option<String>,
    /// `--mem`, or none (the partition's default).
    pub mem: Option<String>,
    /// Where each came from, for the user.
    pub why: Vec<String>,
}

/// Safety factor on the longest measured run for the default `--time`: every attempt of
/// the engine's retry ladder may take as long as a measured success, plus half again.
const TIME_FACTOR: f64 = 1.5;
/// The default `--time` is at least this many minutes (queue start-up, deck, reading).
const MIN_TIME_MIN: f64 = 10.0;
/// Safety factor on the largest measured peak memory for the default `--mem`.
const MEM_FACTOR: f64 = 1.5;
/// Added to the measured peak memory for the task's own `needle` process, MiB.
const MEM_NEEDLE_MIB: f64 = 256.0;

impl Resources {
    /// Defaults from the set's manifest for this engine, mesh level and step count: time
    /// = attempts x the longest measured wall time x 1.5 (at least 10 min), memory =
    /// the largest measured solver peak x 1.5 + 256 MiB; without measured runs on that
    /// level, left to the partition's defaults. The options override them.
    pub fn defaults(plan: &Plan, attempts: u32, slurm: &SlurmOptions) -> Resources {
        let engine = plan.campaign.solver.engine.name();
        let runs: Vec<_> =
            plan.manifest.pose.values().filter(|e| e.engine == engine && e.mesh == plan.mesh_name && e.steps == plan.steps).collect();
        let mut why = Vec::new();
        let max_wall = runs.iter().map(|e| e.wall_s).filter(|w| w.is_finite()).fold(0.0_f64, f64::max);
        let time = match &slurm.time {
            Some(t) => Some(t.clone()),
            None if max_wall > 0.0 => {
                let min = (f64::from(attempts.max(1)) * max_wall * TIME_FACTOR / 60.0).ceil().max(MIN_TIME_MIN) as u64;
                why.push(format!(
                    "--time {min} min: {attempts} attempt(s) x the longest of {} measured {engine} runs on mesh {} ({max_wall:.0} s) x {TIME_FACTOR}",
                    runs.len(),
                    plan.mesh_name
                ));
                Some(min.to_string())
            }
            None => {
                why.push(format!(
                    "--time: the partition's default (no measured {engine} run on mesh {} with {} steps)",
                    plan.mesh_name, plan.steps
                ));
                None
            }
        };
        let max_rss = runs.iter().filter_map(|e| e.peak_rss_mib).fold(0.0_f64, f64::max);
        let mem = match &slurm.mem {
            Some(m) => Some(m.clone()),
            None if max_rss > 0.0 => {
                let mib = ((max_rss * MEM_FACTOR + MEM_NEEDLE_MIB) / 64.0).ceil() as u64 * 64;
                why.push(format!(
                    "--mem {mib}M: the largest measured solver peak ({max_rss:.0} MiB) x {MEM_FACTOR} + {MEM_NEEDLE_MIB} MiB"
                ));
                Some(format!("{mib}M"))
            }
            None => {
                why.push(format!("--mem: the partition's default (no measured peak memory of {engine} on mesh {})", plan.mesh_name));
                None
            }
        };
        Resources { cpus_per_task: slurm.cpus_per_task.unwrap_or(1).max(1), time, mem, why }
    }
}

/// What [`submit`] did.
#[derive(Debug, Clone)]
pub struct SubmitReport {
    /// The plan it submitted from.
    pub selected: usize,
    /// Poses up to date (not submitted).
    pub up_to_date: Vec<String>,
    /// Poses whose earlier task is still pending or running: (pose, `job_task`, state).
    pub in_queue: Vec<(String, String, String)>,
    /// The accepted submission, or none when there was nothing to submit.
    pub submission: Option<Submission>,
    /// The resources and where they came from.
    pub resources: Option<Resources>,
}

/// Submit the poses of `opts` (of the set `set`, opened once by the caller) that are neither up to date nor queued as one job array.
/// See the module docs.
///
/// # Errors
/// `sbatch` or `squeue` is missing, the controller does not answer, `sbatch` refuses the
/// job, or the spec is invalid: nothing was submitted and no file of the set changed.
pub fn submit(set: &SetFolder, opts: &RunOptions, slurm: &SlurmOptions) -> Result<SubmitReport> {
    let sbatch = which(Path::new("sbatch")).with_context(|| {
        format!("sbatch not found on PATH: --launcher slurm submits with SLURM's sbatch (install the SLURM client or load your cluster's slurm module). {UNCHANGED}")
    })?;
    let needle = match &slurm.needle {
        Some(p) => p.clone(),
        None => std::env::current_exe().context("cannot find this needle executable for the batch script")?,
    };
    let plan = campaign::plan(set, opts)?;
    let earlier = read_submissions(&plan.out_dir)?;
    let mut report =
        SubmitReport { selected: plan.selected.len(), up_to_date: Vec::new(), in_queue: Vec::new(), submission: None, resources: None };
    let poses = sort_poses(&plan, &earlier, &mut report)?;
    if poses.is_empty() {
        return Ok(report);
    }
    let attempts = crate::engines::backend_for(plan.campaign.solver.engine, 1).attempts();
    let res = Resources::defaults(&plan, attempts, slurm);
    let out_abs = absolute(&plan.out_dir)?;
    let slurm_dir = out_abs.join(SLURM_DIR);
    let args = sbatch_args(opts, slurm, &res, poses.len(), &slurm_dir)?;
    let script = batch_script(opts, &plan, &needle, &poses)?;

    // .slurm/ must exist before the tasks start (their output goes there); what this
    // call made is removed again when the submission fails
    let made_out = !out_abs.exists();
    let made_dir = !slurm_dir.exists();
    std::fs::create_dir_all(&slurm_dir).with_context(|| format!("{}: cannot create", slurm_dir.display()))?;
    let job_id = match run_sbatch(&sbatch, &args, &script) {
        Ok(id) => id,
        Err(e) => {
            if made_out {
                let _ = std::fs::remove_dir_all(&out_abs);
            } else if made_dir {
                let _ = std::fs::remove_dir_all(&slurm_dir);
            }
            return Err(e);
        }
    };
    let sub = Submission { job_id: job_id.clone(), date: rfc3339_utc(SystemTime::now()), poses, sbatch: args };
    needle_stdx::fs::write_atomic(&slurm_dir.join(format!("{job_id}.sh")), script.as_bytes())?;
    let mut all = earlier;
    all.submission.push(sub.clone());
    let text = toml::to_string(&all).context("cannot write the submissions record")?;
    needle_stdx::fs::write_atomic(&slurm_dir.join(SUBMISSIONS), text.as_bytes())?;
    report.submission = Some(sub);
    report.resources = Some(res);
    Ok(report)
}

/// The poses of `plan` to submit: those to run that have no active task of an earlier
/// submission; the others go into `report` (up to date, or in the queue with their task).
fn sort_poses(plan: &campaign::Plan, earlier: &Submissions, report: &mut SubmitReport) -> Result<Vec<String>> {
    let queued = queue_states(earlier)?;
    let latest = earlier.latest_tasks();
    let to_run = plan.to_run_names();
    for p in &plan.selected {
        if !to_run.contains(&p.name) {
            report.up_to_date.push(p.name.clone());
        }
    }
    let mut poses = Vec::new();
    for name in to_run {
        let active = latest
            .get(&name)
            .and_then(|(job, task)| queued.get(&format!("{job}_{task}")).map(|s| (format!("{job}_{task}"), s.clone())))
            .filter(|(_, s)| s.is_active());
        match active {
            Some((task, state)) => report.in_queue.push((name, task, state.state)),
            None => poses.push(name),
        }
    }
    Ok(poses)
}

/// sbatch's arguments for an array of `tasks` (>= 1) tasks writing their output to
/// `slurm_dir`.
fn sbatch_args(opts: &RunOptions, slurm: &SlurmOptions, res: &Resources, tasks: usize, slurm_dir: &Path) -> Result<Vec<String>> {
    let mut args = vec![
        "--parsable".to_string(),
        format!("--job-name=needle-fe-{}", set_name(&opts.set_dir)),
        format!("--array=0-{}", tasks.saturating_sub(1)),
        format!("--output={}/%A_%a.out", slurm_dir.display()),
        format!("--chdir={}", absolute(Path::new("."))?.display()),
        format!("--cpus-per-task={}", res.cpus_per_task),
    ];
    if let Some(t) = &res.time {
        args.push(format!("--time={t}"));
    }
    if let Some(m) = &res.mem {
        args.push(format!("--mem={m}"));
    }
    if let Some(p) = &slurm.partition {
        args.push(format!("--partition={p}"));
    }
    args.extend(slurm.extra.iter().cloned());
    Ok(args)
}

const UNCHANGED: &str = "Nothing was submitted; no file of the set changed.";

/// `sbatch <args>` with the script on stdin; the job id it prints (`--parsable`:
/// `<id>` or `<id>;<cluster>`).
fn run_sbatch(sbatch: &Path, args: &[String], script: &str) -> Result<String> {
    let mut child = Command::new(sbatch)
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .with_context(|| format!("{}: cannot start. {UNCHANGED}", sbatch.display()))?;
    if let Some(mut stdin) = child.stdin.take() {
        stdin.write_all(script.as_bytes()).with_context(|| format!("cannot hand the batch script to sbatch. {UNCHANGED}"))?;
    }
    let out = child.wait_with_output().context("cannot wait for sbatch")?;
    let stderr = String::from_utf8_lossy(&out.stderr).trim().replace('\n', " / ");
    if !out.status.success() {
        bail!("sbatch refused the job array ({}): {stderr}. {UNCHANGED}", out.status);
    }
    let stdout = String::from_utf8_lossy(&out.stdout);
    let id = stdout.trim().split(';').next().unwrap_or("").trim().to_string();
    if id.is_empty() || !id.chars().all(|c| c.is_ascii_digit()) {
        bail!("sbatch accepted the job but printed no job id ({:?}; {stderr}): check squeue; the set's files are unchanged", stdout.trim());
    }
    Ok(id)
}

/// The batch script: the poses by task index, then `needle fe run-one` for the task's
/// pose with the options of this run.
fn batch_script(opts: &RunOptions, plan: &Plan, needle: &Path, poses: &[String]) -> Result<String> {
    let q = |s: &str| format!("'{}'", s.replace('\'', r"'\''"));
    let path = |p: &Path| -> Result<String> { Ok(q(&absolute(p)?.to_string_lossy())) };
    let mut cmd = vec![
        q(&needle.to_string_lossy()),
        "fe".into(),
        "run-one".into(),
        "--set".into(),
        path(&opts.set_dir)?,
        "--out".into(),
        path(&plan.out_dir)?,
        "--pose".into(),
        "\"$pose\"".into(),
        "--solver".into(),
        plan.campaign.solver.engine.name().into(),
        "--mesh".into(),
        q(&plan.mesh_name),
        "--steps".into(),
        plan.steps.to_string(),
    ];
    if opts.deep {
        cmd.push("--deep".into());
    }
    if opts.force {
        cmd.push("--force".into());
    }
    if opts.keep_work {
        cmd.push("--keep-work".into());
    }
    if let Some(t) = opts.timeout {
        cmd.push(format!("--timeout-s {}", t.as_secs_f64()));
    }
    if let Some(s) = opts.stall {
        cmd.push(format!("--stall-s {}", s.as_secs_f64()));
    }
    let list: Vec<String> = poses.iter().map(|p| q(p)).collect();
    Ok(format!(
        "#!/bin/bash\n\
         # needle fe run --launcher slurm: set {set}, {n} pose(s), one per array task;\n\
         # task i solves poses[i] with `needle fe run-one` (the same code path as a local job).\n\
         set -euo pipefail\n\
         poses=({list})\n\
         pose=\"${{poses[$SLURM_ARRAY_TASK_ID]}}\"\n\
         echo \"needle fe run-one: pose $pose (array task $SLURM_ARRAY_JOB_ID\"_\"$SLURM_ARRAY_TASK_ID on $(hostname))\"\n\
         exec {cmd}\n",
        set = opts.set_dir.display(),
        n = poses.len(),
        list = list.join(" "),
        cmd = cmd.join(" "),
    ))
}

fn absolute(p: &Path) -> Result<PathBuf> {
    std::path::absolute(p).with_context(|| format!("{}: cannot make the path absolute", p.display()))
}

/// The set folder's name, for the job name.
fn set_name(set_dir: &Path) -> String {
    absolute(set_dir)
        .ok()
        .and_then(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .unwrap_or_else(|| "set".into())
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' })
        .collect()
}

/// One array task in the queue.
#[derive(Debug, Clone, PartialEq)]
pub struct QueueState {
    /// SLURM's state, e.g. `PENDING`, `RUNNING`, `COMPLETING`.
    pub state: String,
    /// SLURM's reason (`None`, `Resources`, `Priority`...).
    pub reason: String,
}

impl QueueState {
    /// Pending, running or about to run: a resubmission must not submit its pose again.
    pub fn is_active(&self) -> bool {
        !matches!(
            self.state.as_str(),
            "COMPLETED" | "FAILED" | "CANCELLED" | "TIMEOUT" | "OUT_OF_MEMORY" | "NODE_FAIL" | "PREEMPTED" | "BOOT_FAIL" | "DEADLINE"
        )
    }
}

/// The queue state of the tasks of `subs` that SLURM still lists: `<job>_<task>` ->
/// state (`squeue --me --array`; finished tasks leave the queue within the controller's
/// `MinJobAge`, 300 s by default).
///
/// # Errors
/// `squeue` is missing or fails (the controller does not answer).
pub fn queue_states(subs: &Submissions) -> Result<BTreeMap<String, QueueState>> {
    let mut m = BTreeMap::new();
    if subs.submission.is_empty() {
        // nothing of ours can be queued; still check that the controller answers
        squeue(&["--me", "-h", "-o", "%i"])?;
        return Ok(m);
    }
    let text = squeue(&["--me", "-h", "--array", "-o", "%F|%K|%T|%r"])?;
    let ours: Vec<&str> = subs.submission.iter().map(|s| s.job_id.as_str()).collect();
    for line in text.lines() {
        let f: Vec<&str> = line.split('|').map(str::trim).collect();
        if let [job, task, state, reason] = f[..] {
            if ours.contains(&job) && task.chars().all(|c| c.is_ascii_digit()) {
                m.insert(format!("{job}_{task}"), QueueState { state: state.to_string(), reason: reason.to_string() });
            }
        }
    }
    Ok(m)
}

fn squeue(args: &[&str]) -> Result<String> {
    let exe = which(Path::new("squeue")).with_context(|| format!("squeue not found on PATH (the SLURM client). {UNCHANGED}"))?;
    let out = Command::new(&exe).args(args).stdin(Stdio::null()).output().with_context(|| format!("{}: cannot start", exe.display()))?;
    if !out.status.success() {
        bail!(
            "squeue failed ({}): {}: the SLURM controller does not answer. {UNCHANGED}",
            out.status,
            String::from_utf8_lossy(&out.stderr).trim().replace('\n', " / ")
        );
    }
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}
