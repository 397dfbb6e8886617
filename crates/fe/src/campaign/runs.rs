//! Runs solved and read through the campaign's own machinery ([`campaign::run`]), as the
//! verification's checks, the mesh study and the QLV comparison use them: each variant (a mesh level, a tissue scale) has its own output
//! folder with a manifest, so an interrupted check resumes where it stopped, failed poses
//! get the campaign's retry ladder and continuations, and a run already up to date is
//! read, not solved again.

use crate::campaign::{self, RunOptions};
pub use crate::pose_rows::{same_depths, PoseRows, Run};
use crate::report::Status;
use crate::results::{self, Row};
use crate::set_folder::SetFolder;
use anyhow::Result;

/// Solve what is not up to date among the poses `opts` selects of `set` (one job), print
/// the campaign's table, then read every selected pose's result.
///
/// # Errors
/// As [`campaign::run`]: the spec, an option, the manifest (not a failed solve: that is
/// the pose's `Err`).
pub fn solve_and_read(set: &SetFolder, opts: &RunOptions) -> Result<PoseRows> {
    let report = campaign::run(set, opts)?;
    needle_stdx::out!("{}", report.table());
    let mut rows = read_current(set, opts)?;
    for p in &report.poses {
        if let (Status::Failed { message, .. }, Some(Err(why))) = (&p.status, rows.get_mut(&p.pose)) {
            *why = format!("{message} ({why})");
        }
    }
    Ok(rows)
}

/// Read the selected poses' results of `set` without solving: `Ok(rows)` for a result that is up
/// to date for the spec (hash and content per the manifest), `Err(why)` otherwise (for a
/// pose with failed attempts, how far the furthest got, from its partial record).
///
/// # Errors
/// As [`campaign::plan`].
pub fn read_current(set: &SetFolder, opts: &RunOptions) -> Result<PoseRows> {
    let plan = campaign::plan(set, opts)?;
    let mut out = PoseRows::new();
    for (i, pose) in plan.selected.iter().enumerate() {
        let csv = plan.out_dir.join(format!("{}.csv", pose.name));
        let entry = plan.manifest.pose.get(&pose.name).filter(|_| !plan.to_run.contains(&i));
        let r = match entry {
            None => {
                Err(match crate::partial::read_current_record(&plan.out_dir, &pose.name, &plan.campaign.run_hash(pose, &plan.mesh_name)) {
                    Some(r) => format!(
                        "{}: not solved; its furthest failed attempt so far reached {} of {} mm (its record: {}.partial.toml)",
                        csv.display(),
                        r.reached_depth_mm,
                        r.depth_mm,
                        pose.name
                    ),
                    None => format!("{}: no current result (mesh {}, {} steps)", csv.display(), plan.mesh_name, plan.steps),
                })
            }
            Some(e) => read_rows(&csv, plan.campaign.loading.ramp_hold.is_some())
                .map(|rows| Run { rows, entry: e.clone() })
                .map_err(|e| format!("{e:#}")),
        };
        out.insert(pose.name.clone(), r);
    }
    Ok(out)
}

/// A result's rows: an elastic run's, or a ramp-and-hold run's without its time column
/// (`timed`; the times are the loading's must points).
fn read_rows(csv: &std::path::Path, timed: bool) -> Result<Vec<Row>> {
    if !timed {
        return results::read_csv(csv);
    }
    let text = std::fs::read_to_string(csv).map_err(|e| anyhow::anyhow!("{}: cannot read: {e}", csv.display()))?;
    Ok(results::parse_timed_csv(&text, csv)?.1)
}

#[cfg(test)]
mod tests {
    use super::read_current;
    use crate::campaign::tests::{opts, run_with, set_dir, Fake};
    use crate::set_folder::SetFolder;

    /// A pose without a result whose attempts all failed says how far the furthest got.
    #[test]
    fn a_pose_without_a_result_names_its_furthest_failed_attempt() {
        let d = set_dir();
        let mut fake = Fake { fail_reached: Some("x+04".into()), ..Fake::default() };
        let r = run_with(&opts(d.path(), "x+04", 4), &mut fake).expect("run");
        assert_eq!(r.failed(), 1, "{}", r.table());
        let why = read_current(&SetFolder::open(d.path()).expect("set"), &opts(d.path(), "x+04", 4))
            .expect("plan")
            .remove("x+04")
            .and_then(|r| r.err());
        assert!(
            why.as_deref().is_some_and(
                |w| w.ends_with("not solved; its furthest failed attempt so far reached 3 of 6 mm (its record: x+04.partial.toml)")
            ),
            "{why:?}"
        );
    }
}
