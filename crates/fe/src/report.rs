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
        s.push_str(&format!(
            "{} done, {} up to date, {} failed; mesh {}, {} steps, {:.1} s\n",
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
        }
        s
    }
}
