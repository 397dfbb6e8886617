//! The outcome of `needle fe run`: one [`PoseReport`] per selected pose and the summary
//! table printed at the end.

use std::path::PathBuf;
use std::time::Duration;

/// What happened to one selected pose.
#[derive(Debug, Clone, PartialEq)]
pub enum Status {
    /// Solved now; CSV and manifest entry written.
    Done,
    /// Result already up to date; nothing run.
    UpToDate,
    /// The run failed; no CSV written. `message` says how (exit status, steps done),
    /// `log_tail` holds the end of the solver's output (ccx or FEBio; may be empty).
    Failed {
        /// One line: what failed.
        message: String,
        /// The last lines of ccx's output.
        log_tail: String,
    },
    /// Stopped by an interruption (SIGINT, SIGTERM, SIGHUP) while solving: not failed,
    /// a rerun resumes the attempt it was in. `message` says where it stopped.
    Interrupted {
        /// One line: the attempts so far and where the interrupted one stopped.
        message: String,
    },
    /// Selected and not up to date, but never started: the run was interrupted first.
    NotRun,
}

/// The line that says pose `pose` was interrupted (progress and summary; `needle fe
/// status` finds it by its `interrupted <pose>:` start).
pub(crate) fn interrupted_line(pose: &str, message: &str) -> String {
    format!("interrupted {pose}: {message}; a rerun resumes it")
}

/// One line of the final report.
#[derive(Debug, Clone)]
pub struct PoseReport {
    /// Pose name.
    pub pose: String,
    /// Outcome.
    pub status: Status,
    /// Wall time of the solve, s (from the manifest for up-to-date poses).
    pub wall_s: Option<f64>,
    /// Converged increments of the solve.
    pub increments: Option<u32>,
    /// Fy at the final depth, N (reaction on the needle).
    pub fy_final_n: Option<f64>,
    /// The kept work folder of a failed run.
    pub work_dir: Option<PathBuf>,
}

/// The result of [`run`](super::campaign::run).
#[derive(Debug, Clone)]
pub struct Report {
    /// One entry per selected pose, in campaign order.
    pub poses: Vec<PoseReport>,
    /// Mesh level used.
    pub mesh: String,
    /// Load steps per run.
    pub steps: u32,
    /// Final depth, mm.
    pub depth_mm: f64,
    /// The output folder.
    pub out_dir: PathBuf,
    /// Wall time of the whole campaign.
    pub wall: Duration,
}

impl Report {
    /// Number of poses solved now.
    pub fn done(&self) -> usize {
        self.poses.iter().filter(|p| p.status == Status::Done).count()
    }
    /// Number of poses skipped as up to date.
    pub fn up_to_date(&self) -> usize {
        self.poses.iter().filter(|p| p.status == Status::UpToDate).count()
    }
    /// Number of failed poses.
    pub fn failed(&self) -> usize {
        self.poses.iter().filter(|p| matches!(p.status, Status::Failed { .. })).count()
    }
    /// Number of poses stopped by an interruption while solving.
    pub fn interrupted(&self) -> usize {
        self.poses.iter().filter(|p| matches!(p.status, Status::Interrupted { .. })).count()
    }
    /// Number of selected poses that were not up to date and never started.
    pub fn not_run(&self) -> usize {
        self.poses.iter().filter(|p| p.status == Status::NotRun).count()
    }

    /// The summary table (pose, status, wall time, increments, Fy at the final depth),
    /// then one paragraph per failure with its log tail.
    pub fn table(&self) -> String {
        let mut s =
            format!("{:<10} {:<10} {:>9} {:>10} {:>14}\n", "pose", "status", "wall_s", "increments", format!("fy_n@{}mm", self.depth_mm));
        let opt = |v: Option<String>| v.unwrap_or_else(|| "-".into());
        for p in &self.poses {
            let status = match p.status {
                Status::Done => "done",
                Status::UpToDate => "up to date",
                Status::Failed { .. } => "FAILED",
                Status::Interrupted { .. } => "interrupted",
                Status::NotRun => "not run",
            };
            s.push_str(&format!(
                "{:<10} {:<10} {:>9} {:>10} {:>14}\n",
                p.pose,
                status,
                opt(p.wall_s.map(|w| format!("{w:.1}"))),
                opt(p.increments.map(|i| i.to_string())),
                opt(p.fy_final_n.map(|f| format!("{f:.6e}"))),
            ));
        }
        let stopped = match (self.interrupted(), self.not_run()) {
            (0, 0) => String::new(),
            (i, n) => format!(", {i} interrupted and {n} not run (a rerun resumes them)"),
        };
        s.push_str(&format!(
            "{} done, {} up to date, {} failed{stopped}; mesh {}, {} steps, {:.1} s\n",
            self.done(),
            self.up_to_date(),
            self.failed(),
            self.mesh,
            self.steps,
            self.wall.as_secs_f64()
        ));
        for p in &self.poses {
            if let Status::Failed { message, log_tail } = &p.status {
                s.push_str(&format!("\nFAILED {}: {message}\n", p.pose));
                if let Some(w) = &p.work_dir {
                    s.push_str(&format!("  work folder kept: {}\n", w.display()));
                }
                if !log_tail.is_empty() {
                    s.push_str("  end of the solver's output:\n");
                    for l in log_tail.lines() {
                        s.push_str(&format!("  | {l}\n"));
                    }
                }
            }
            if let Status::Interrupted { message } = &p.status {
                s.push_str(&format!("\n{}\n", interrupted_line(&p.pose, message)));
            }
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pose(name: &str, status: Status) -> PoseReport {
        PoseReport { pose: name.into(), status, wall_s: None, increments: None, fy_final_n: None, work_dir: None }
    }

    /// An interrupted campaign says which poses it stopped and which it never started: not
    /// "FAILED" (their attempts are not used up) and not "up to date" (they are stale).
    #[test]
    fn an_interrupted_run_reports_its_stopped_and_unstarted_poses_apart() {
        let r = Report {
            poses: vec![
                pose("centre", Status::UpToDate),
                pose("x+04", Status::Done),
                pose("z+04", Status::Interrupted { message: "febio4 interrupted (killed) after 3 of 20 steps".into() }),
                pose("z+08", Status::NotRun),
            ],
            mesh: "needle8".into(),
            steps: 20,
            depth_mm: 6.0,
            out_dir: PathBuf::from("fe"),
            wall: Duration::from_secs(1),
        };
        assert_eq!((r.done(), r.up_to_date(), r.failed(), r.interrupted(), r.not_run()), (1, 1, 0, 1, 1));
        let t = r.table();
        let row = |name: &str| t.lines().find(|l| l.starts_with(&format!("{name} "))).unwrap_or_default().to_string();
        assert!(row("z+04").contains("interrupted") && row("z+08").contains("not run"), "{t}");
        assert!(row("centre").contains("up to date") && !row("z+08").contains("up to date"), "{t}");
        assert!(t.contains("1 done, 1 up to date, 0 failed, 1 interrupted and 1 not run (a rerun resumes them)"), "{t}");
        assert!(
            t.contains("interrupted z+04: febio4 interrupted (killed) after 3 of 20 steps; a rerun resumes it") && !t.contains("FAILED"),
            "{t}"
        );
    }
}
