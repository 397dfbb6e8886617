//! The smoothness check of `needle fe verify`: in every FE result present, the must point
//! furthest from the mean of its two neighbours. No solve: it reads `fe/<pose>.csv`.
//!
//! Why: a solver can accept a state that is not in equilibrium (FEBio with `rtol` 0
//! accepted one where the line search had cut the last step to 0.033: the default set's tx+04's
//! Fy at 2.1 mm 6.1 % of peak |Fy| below its neighbours' mean, t2-a's at 4.2 mm 6.1 %
//! above). The force-depth curves are smooth where the runs are sound: on the 0.3 mm
//! steps of the campaign the curvature alone puts a point 0.4-0.8 % of peak |Fy| from its
//! neighbours' mean, and the largest converged contact event seen (tx+02 at 3.6 mm, the
//! same value with and without the residual checked) 2.3 %.

use crate::results::{self, Row};
use crate::spec::Campaign;
use anyhow::Result;
use needle_contract::{COMPONENTS, COMPONENT_COUNT};
use serde::Serialize;
use std::path::Path;

/// Largest distance of a must point from its neighbours' mean that the check accepts, %
/// of the run's peak |Fy| (moments: of peak |Fy| times the hub's lever arm): between
/// the sound runs' 2.3 % and the faults' 6 %.
pub const SMOOTH_GOAL_PERCENT: f64 = 3.0;

/// The must point of one run furthest from its neighbours' mean.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SmoothReport {
    /// The pose.
    pub pose: String,
    /// Depth of that must point, mm.
    pub depth_mm: f64,
    /// Its component.
    pub component: String,
    /// The value minus its neighbours' mean, N or N*mm.
    pub deviation: f64,
    /// That as % of the run's peak |Fy| (moments: of peak |Fy| times the lever arm).
    pub percent_of_peak_fy: f64,
}

/// The must point of `rows` (a run's rows, depth 0 first) furthest from the mean of its
/// neighbours, over every component and every point from the second loaded one on (the
/// first loaded point's lower neighbour is the unloaded state, where contact starts, so
/// it is not judged itself). `None` for fewer than four rows or a run without force.
pub fn largest_jump(pose: &str, rows: &[Row], lever_arm_mm: f64) -> Option<SmoothReport> {
    let peak = results::peak_fy_n(rows);
    if peak <= 0.0 || lever_arm_mm.is_nan() || lever_arm_mm <= 0.0 {
        return None;
    }
    let scales = needle_contract::error_scales(peak, lever_arm_mm);
    let mut best: Option<SmoothReport> = None;
    for w in rows.windows(3).skip(1) {
        let [before, at, after] = w else { continue };
        for c in 0..COMPONENT_COUNT {
            let deviation = at.wrench[c] - 0.5 * (before.wrench[c] + after.wrench[c]);
            let percent = 100.0 * deviation.abs() / scales[c];
            if best.as_ref().is_none_or(|b| percent > b.percent_of_peak_fy) {
                best = Some(SmoothReport {
                    pose: pose.to_string(),
                    depth_mm: at.depth_mm,
                    component: COMPONENTS[c].to_string(),
                    deviation,
                    percent_of_peak_fy: percent,
                });
            }
        }
    }
    best
}

impl std::fmt::Display for SmoothReport {
    /// The report's line in `needle fe verify`'s table.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "smooth {:>8}: largest must-point jump {:+.3e} ({}) at {} mm = {:.3}% of peak |Fy| (goal <= {SMOOTH_GOAL_PERCENT}%)",
            self.pose, self.deviation, self.component, self.depth_mm, self.percent_of_peak_fy
        )
    }
}

/// [`largest_jump`] of every pose of `c` whose result is in `fe`, in the spec's pose
/// order (poses without a result are left out).
///
/// # Errors
/// A result file that cannot be read.
pub(super) fn smooth_checks(c: &Campaign, fe: &Path) -> Result<Vec<SmoothReport>> {
    let mut out = Vec::new();
    for p in c.poses() {
        let path = fe.join(format!("{}.csv", p.name));
        if !path.is_file() {
            continue;
        }
        let rows = results::read_csv(&path)?;
        out.extend(largest_jump(&p.name, &rows, c.needle.reference_from_tip_mm));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rows of a smooth force law `Fy = 0.002 d^2` (peak 0.072 N at 6 mm), moments zero.
    fn smooth_rows() -> Vec<Row> {
        (0..=20)
            .map(|k| {
                let d = 0.3 * f64::from(k);
                let mut wrench = [0.0; COMPONENT_COUNT];
                wrench[1] = 0.002 * d * d;
                Row { depth_mm: d, wrench }
            })
            .collect()
    }

    #[test]
    fn a_smooth_curve_passes_and_one_bad_point_is_found() {
        let rows = smooth_rows();
        let r = largest_jump("p", &rows, 60.0).expect("a report");
        // the parabola's own second difference: 0.002 * 0.3^2 = 1.8e-4 N, 0.25 % of 0.072 N
        assert!((r.percent_of_peak_fy - 0.25).abs() < 1e-9 && r.percent_of_peak_fy < SMOOTH_GOAL_PERCENT, "{r:?}");
        let mut bad = rows;
        bad[7].wrench[5] = -0.3; // Mz at 2.1 mm: 0.3 N*mm off, 6.9 % of 0.072 N x 60 mm
        let r = largest_jump("p", &bad, 60.0).expect("a report");
        assert_eq!((r.depth_mm, r.component.as_str()), (bad[7].depth_mm, "mz_nmm"));
        assert!((r.percent_of_peak_fy - 100.0 * 0.3 / (0.072 * 60.0)).abs() < 1e-9, "{r:?}");
        assert!(r.percent_of_peak_fy > SMOOTH_GOAL_PERCENT);
    }

    #[test]
    fn short_and_forceless_runs_are_not_judged() {
        let rows = smooth_rows();
        assert_eq!(largest_jump("p", &rows[..3], 60.0), None, "depth 0 and two loaded points: no point has two loaded-side neighbours");
        assert!(largest_jump("p", &rows[..4], 60.0).is_some());
        let flat: Vec<Row> = rows.iter().map(|r| Row { depth_mm: r.depth_mm, wrench: [0.0; COMPONENT_COUNT] }).collect();
        assert_eq!(largest_jump("p", &flat, 60.0), None);
    }
}
