//! `needle fe status`: each selected pose's result (up to date, or why it is to be
//! solved) beside the queue state of its latest SLURM array task (`squeue`) and, for a
//! task that left the queue without a result, the cause its output states; for a pose
//! run locally without a result, its failed attempts by class and depth.

use crate::campaign::Plan;
use crate::launcher::slurm::{self, QueueState, SLURM_DIR};
use anyhow::Result;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

/// The state of one pose.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseState {
    /// Pose name.
    pub pose: String,
    /// The result is up to date.
    pub done: bool,
    /// Why it is not (`no entry in manifest.toml`, `solved from another spec`...).
    pub result: String,
    /// The latest array task of the pose, `<job>_<task>`.
    pub task: Option<String>,
    /// `done`, `pending`, `running`, `failed`, `cancelled`, `ended` (no result, cause
    /// unknown) or `not submitted`.
    pub state: String,
    /// The cause, for a task that failed or left the queue without a result.
    pub cause: String,
}

/// What `needle fe status` shows.
#[derive(Debug, Clone)]
pub struct StatusReport {
    /// One per selected pose, in campaign order.
    pub poses: Vec<PoseState>,
    /// Why the queue could not be read, if it could not (the manifest part stands).
    pub queue_error: Option<String>,
}

impl StatusReport {
    /// Number of poses in each state, e.g. `done 3, running 1, failed 1`.
    pub fn counts(&self) -> BTreeMap<String, usize> {
        let mut m = BTreeMap::new();
        for p in &self.poses {
            *m.entry(p.state.clone()).or_insert(0) += 1;
        }
        m
    }

    /// The table and the count line.
    pub fn table(&self) -> String {
        let mut s = String::new();
        let w = self.poses.iter().map(|p| p.pose.len()).max().unwrap_or(4).max(4);
        let _ = writeln!(s, "{:<w$}  {:<13}  {:<12}  {:<36}  cause", "pose", "state", "slurm task", "result");
        for p in &self.poses {
            let _ = writeln!(
                s,
                "{:<w$}  {:<13}  {:<12}  {:<36}  {}",
                p.pose,
                p.state,
                p.task.as_deref().unwrap_or("-"),
                if p.done { "up to date" } else { p.result.as_str() },
                p.cause
            );
        }
        let counts: Vec<String> = self.counts().into_iter().map(|(k, v)| format!("{k} {v}")).collect();
        let _ = writeln!(s, "{} pose(s): {}", self.poses.len(), counts.join(", "));
        if let Some(e) = &self.queue_error {
            let _ = writeln!(s, "queue not read: {e}");
        }
        s
    }
}

/// The status of the poses of `plan` ([`campaign::plan`](crate::campaign::plan)).
///
/// # Errors
/// The submissions record cannot be read. A queue that cannot be read is not an error:
/// the report says so in [`StatusReport::queue_error`].
pub fn status(plan: &Plan) -> Result<StatusReport> {
    let subs = slurm::read_submissions(&plan.out_dir)?;
    let latest = subs.latest_tasks();
    let (queue, queue_error) = if subs.submission.is_empty() {
        (BTreeMap::new(), None)
    } else {
        match slurm::queue_states(&subs) {
            Ok(q) => (q, None),
            Err(e) => (BTreeMap::new(), Some(format!("{e:#}"))),
        }
    };
    let mut poses = Vec::new();
    for (i, pose) in plan.selected.iter().enumerate() {
        let done = !plan.to_run.contains(&i);
        let result = if done {
            String::new()
        } else {
            match plan.manifest.current_entry(&plan.campaign, pose, &plan.mesh_name) {
                Err(why) => why,
                Ok(_) if plan.resumes_forced_rerun(pose) => "up to date; an interrupted --force rerun resumes".to_string(),
                Ok(_) => "CSV missing, changed or of other steps".to_string(),
            }
        };
        let task = latest.get(&pose.name).map(|(job, t)| format!("{job}_{t}"));
        let (state, cause) = match (&task, done) {
            (_, true) => ("done".to_string(), String::new()),
            (None, false) => ("not submitted".to_string(), local_failures(&plan.out_dir, &pose.name, plan.campaign.loading.time_unit())),
            (Some(t), false) => match queue.get(t) {
                Some(q) => (q.state.to_lowercase(), reason(q)),
                None if queue_error.is_some() => ("unknown".to_string(), String::new()),
                None => ended_task(&plan.out_dir, t, &pose.name),
            },
        };
        poses.push(PoseState { pose: pose.name.clone(), done, result, task, state, cause });
    }
    Ok(StatusReport { poses, queue_error })
}

/// The failed attempts a local run left in `<out>/.work/<pose>/`, by class
/// ([`febio::failures`](crate::febio::failures)); empty when there are none.
/// Without logs, the attempts of its `.partial.toml` record (the logs' folder is gone
/// when the campaign ran elsewhere or the work folder was cleaned).
fn local_failures(out_dir: &Path, pose: &str, unit: &str) -> String {
    use crate::febio::failures;
    let f = failures::read_failures(&out_dir.join(".work").join(pose));
    if !f.is_empty() {
        return failures::summary(&f, unit);
    }
    let Some(r) = crate::partial::read_record(out_dir, pose) else {
        return String::new();
    };
    format!("{} (record {})", failures::summary(&failures::failures_from_record(&r.failure), unit), r.date)
}

/// The failed attempts of the selected poses by attempt and class (issue 42, item 2:
/// where the ladder fails): of solved runs from their manifest entry's `retry` (the
/// attempts before the one that solved), of unsolved ones from their failed attempts'
/// logs or partial record; then on which attempt the solved runs solved. Empty when
/// nothing failed and nothing is solved.
pub fn attempts_by_class(plan: &Plan) -> String {
    use crate::febio::failures::{self, AttemptFailure};
    let mut failed: Vec<AttemptFailure> = Vec::new();
    let mut solved_on: BTreeMap<u32, usize> = BTreeMap::new();
    for (i, pose) in plan.selected.iter().enumerate() {
        let done = !plan.to_run.contains(&i);
        if done {
            let retry = plan.manifest.pose.get(&pose.name).and_then(|e| e.retry.clone()).unwrap_or_default();
            let before = failures::failures_from_record(&retry);
            *solved_on.entry(before.len() as u32 + 1).or_default() += 1;
            failed.extend(before);
        } else {
            let logs = failures::read_failures(&plan.out_dir.join(".work").join(&pose.name));
            if logs.is_empty() {
                if let Some(r) = crate::partial::read_record(&plan.out_dir, &pose.name) {
                    failed.extend(failures::failures_from_record(&r.failure));
                }
            } else {
                failed.extend(logs);
            }
        }
    }
    let mut s = String::new();
    if failed.is_empty() && solved_on.is_empty() {
        return s;
    }
    let mut by: BTreeMap<(u32, &str), Vec<f64>> = BTreeMap::new();
    for f in &failed {
        by.entry((f.attempt, f.class)).or_default().push(f.depth_mm);
    }
    let unit = plan.campaign.loading.time_unit();
    let what = if unit == "s" { "time" } else { "depth" };
    let _ = writeln!(s, "failed attempts by class ({} in all; {what} where each stopped, min / median / max {unit}):", failed.len());
    for ((attempt, class), d) in &mut by {
        d.sort_by(f64::total_cmp);
        let median = d.get(d.len() / 2).copied().unwrap_or(f64::NAN);
        let (lo, hi) = (d.first().copied().unwrap_or(f64::NAN), d.last().copied().unwrap_or(f64::NAN));
        let _ = writeln!(s, "  attempt {attempt}: {class:<17} x{:<3} {lo:.2} / {median:.2} / {hi:.2} {unit}", d.len());
    }
    let on: Vec<String> = solved_on.iter().map(|(a, n)| format!("attempt {a}: {n}")).collect();
    let _ = writeln!(s, "solved runs by the attempt that solved them: {}", on.join(", "));
    s
}

/// The training design's coverage (issue 42): of the first `train_count` poses as drawn
/// and of the design's slots after the replacements (`campaign.train_replaced`), how
/// many have an up-to-date result in `plan`'s folder; `None` without training poses.
pub fn training_coverage(plan: &Plan) -> Option<String> {
    let c = &plan.campaign;
    let n = c.campaign.train_count as usize;
    if n == 0 {
        return None;
    }
    let poses = c.train_poses();
    let solved = |name: &str| {
        poses.iter().find(|p| p.name == name).is_some_and(|p| {
            plan.manifest.current_entry(c, p, &plan.mesh_name).is_ok() && plan.out_dir.join(format!("{name}.csv")).is_file()
        })
    };
    let drawn: Vec<String> = (0..n).map(|i| c.train_name(i)).collect();
    let first = drawn.iter().filter(|p| solved(p)).count();
    let design = c.train_design();
    let slots = design.iter().filter(|p| solved(p)).count();
    let mut s = format!(
        "training design: {first} of the first {n} poses as drawn solved; {slots} of its {n} slots after {} replacement(s) (campaign.train_replaced)",
        c.campaign.train_replaced.len()
    );
    for r in &c.campaign.train_replaced {
        let by = c.replacement_of(&r.pose).unwrap_or_default();
        let _ = write!(s, "\n  {} -> {by} ({}): {}", r.pose, if solved(&by) { "solved" } else { "not solved yet" }, r.why);
    }
    let open: Vec<&String> = design.iter().filter(|p| !solved(p)).collect();
    if !open.is_empty() {
        let _ = write!(s, "\n  slots not solved: {}", open.iter().map(|p| p.as_str()).collect::<Vec<_>>().join(", "));
    }
    Some(s)
}

fn reason(q: &QueueState) -> String {
    if q.reason.is_empty() || q.reason == "None" {
        String::new()
    } else {
        format!("waiting: {}", q.reason)
    }
}

/// A task that left the queue without an up-to-date result: the cause from its output
/// file `<out>/.slurm/<job>_<task>.out`.
fn ended_task(out_dir: &Path, task: &str, pose: &str) -> (String, String) {
    let path = out_dir.join(SLURM_DIR).join(format!("{task}.out"));
    let Ok(text) = std::fs::read_to_string(&path) else {
        return ("ended".into(), format!("no output file {} (the task never started?)", path.display()));
    };
    if let Some(l) = text.lines().rev().find(|l| l.contains("CANCELLED")) {
        // slurmstepd's line: `slurmstepd-<node>: error: *** JOB 9 ON vm CANCELLED AT ... ***`
        let what = l.find("***").and_then(|i| l.get(i..)).unwrap_or(l);
        return ("cancelled".into(), what.trim().to_string());
    }
    if let Some(l) = text.lines().find(|l| l.starts_with(&format!("interrupted {pose}:"))) {
        return ("interrupted".into(), l.trim().to_string());
    }
    if let Some(l) = text.lines().find(|l| l.starts_with(&format!("FAILED {pose}:"))) {
        return ("failed".into(), l.trim().to_string());
    }
    for key in ["DUE TO TIME LIMIT", "oom-kill", "Error:", "error:"] {
        if let Some(l) = text.lines().rev().find(|l| l.contains(key)) {
            return ("failed".into(), l.trim().to_string());
        }
    }
    ("ended".into(), format!("no result and no stated cause: see {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::campaign::tests::{opts, set_dir, Fake};
    use crate::campaign::tests::{plan, run_with};
    use crate::campaign::RunOptions;
    use crate::spec;

    /// Issue 42, item 3: `needle fe status` counts the design's slots (a replacement that
    /// solved fills the slot of the pose it replaces) and the failed attempts by class.
    #[test]
    fn the_status_counts_the_slots_and_the_attempts_by_class() {
        let d = set_dir();
        let (c, _) = spec::load(d.path()).expect("spec");
        let r = c.campaign.train_replaced.first().expect("the default set replaces a training pose").clone();
        let by = c.replacement_of(&r.pose).expect("its replacement");
        let mut fake = Fake { fail_reached: Some(r.pose.clone()), ..Fake::default() };
        run_with(&opts(d.path(), &r.pose, 4), &mut fake).expect("run");
        run_with(&opts(d.path(), &by, 4), &mut Fake::default()).expect("run");
        let plan = plan(&RunOptions { only: Some("train-*".into()), ..opts(d.path(), "", 4) }).expect("plan");
        let cov = training_coverage(&plan).unwrap_or_default();
        let n = c.campaign.train_count;
        assert!(cov.starts_with(&format!("training design: 0 of the first {n} poses as drawn solved; 1 of its {n} slots")), "{cov}");
        assert!(cov.contains(&format!("{} -> {by} (solved)", r.pose)), "{cov}");
        let classes = attempts_by_class(&plan);
        assert!(classes.contains("solved runs by the attempt that solved them: attempt 1: 1"), "{classes}");
    }

    /// A pose whose interrupted `--force` rerun will resume says so, not that its CSV is off.
    #[test]
    fn a_pose_whose_interrupted_forced_rerun_resumes_says_so() {
        let d = set_dir();
        let o = opts(d.path(), "x+04", 4);
        run_with(&o, &mut Fake::default()).expect("run");
        let p = plan(&o).expect("plan");
        let pose = p.selected.first().expect("x+04");
        let run = crate::resume::Identity {
            spec_hash: p.campaign.run_hash(pose, &p.mesh_name),
            engine: "fake".into(),
            engine_version: "1".into(),
            mesh: p.mesh_name.clone(),
            steps: p.steps,
        };
        let wd = p.out_dir.join(".work").join(&pose.name);
        std::fs::create_dir_all(&wd).expect("work folder");
        crate::resume::write(&wd, &run, 5, &crate::resume::Start::default()).expect("record");
        let s = status(&plan(&o).expect("plan")).expect("status");
        let states: Vec<(bool, &str)> = s.poses.iter().map(|p| (p.done, p.result.as_str())).collect();
        assert_eq!(states, [(false, "up to date; an interrupted --force rerun resumes")]);
    }
}
