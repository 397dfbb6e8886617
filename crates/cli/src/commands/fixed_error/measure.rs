//! The fixed-point evaluator's error against the f64 evaluation of the same model,
//! measured: the library's [`needle_haptics::fixed::wrench`] against the fitter's
//! [`needle_fit::eval::float64`] on the f64 coefficients of the set's `model.toml`, at the same
//! Q16.16 poses (exact in f64), beside the bound the code generator derived
//! ([`needle_haptics::fixed::tables::ERROR_BOUND_MICRO`]).
//!
//! Used by `needle fixed-error` and the `fixed_error` test. Figures are in N and N·mm,
//! and relative to the model's peak |Fy| over the grid (moments: to peak |Fy| times the
//! needle's lever arm `needle.reference_from_tip_mm`, as in the validation reports).

use anyhow::Result;
use needle_contract::COMPONENT_COUNT;
use needle_fit::contract::{unit, COMPONENTS};
use needle_fit::{eval::float64 as eval_f64, model::Model, model_file, MODEL_FILE};
use needle_haptics::fixed::{self, tables::ERROR_BOUND_MICRO};
use needle_set::set_folder::SetFolder;
use std::fmt::Write as _;

/// Goal of issue 5: error <= 0.1 % of peak |Fy| (moments: of peak |Fy| x lever arm).
pub const GOAL_PCT: f64 = 0.1;

/// Q16.16 of the domain's bounds: x, z, theta_x, theta_z, depth.
const MIN_Q16: [i64; 5] = [-12 << 16, -12 << 16, -15 << 16, -15 << 16, 0];
const MAX_Q16: [i64; 5] = [12 << 16, 12 << 16, 15 << 16, 15 << 16, 6 << 16];

/// Running maxima of the error per component.
#[derive(Debug, Clone, Default)]
pub struct ErrorStats {
    /// Poses evaluated.
    pub poses: usize,
    /// Largest |fixed - f64| per component, N or N·mm.
    pub max_error: [f64; COMPONENT_COUNT],
    /// A pose where it was reached (Q16.16).
    pub worst_pose: [[i32; 5]; COMPONENT_COUNT],
    /// Largest |Fy| of the f64 model over the poses, N.
    pub peak_fy_n: f64,
}

impl ErrorStats {
    /// Evaluate both at `pose` and record the errors.
    pub fn add(&mut self, model: &Model, pose: [i32; 5]) {
        let (want, _) = eval_f64::eval(model, pose.map(|v| f64::from(v) / 65536.0));
        let got = fixed::wrench(&fixed::Pose::new(pose[0], pose[1], pose[2], pose[3], pose[4])).wrench.to_array();
        for c in 0..COMPONENT_COUNT {
            let e = (f64::from(got[c]) * 1e-6 - want[c]).abs();
            if e > self.max_error[c] {
                self.max_error[c] = e;
                self.worst_pose[c] = pose;
            }
        }
        self.peak_fy_n = self.peak_fy_n.max(want[1].abs());
        self.poses += 1;
    }

    /// Every pose of an `n`-point-per-axis grid over the domain (edges included).
    pub fn add_grid(&mut self, model: &Model, n: usize) {
        let axis: Vec<Vec<i32>> =
            (0..5).map(|i| (0..n).map(|m| (MIN_Q16[i] + (MAX_Q16[i] - MIN_Q16[i]) * m as i64 / (n as i64 - 1)) as i32).collect()).collect();
        for &x in &axis[0] {
            for &z in &axis[1] {
                for &tx in &axis[2] {
                    for &tz in &axis[3] {
                        for &d in &axis[4] {
                            self.add(model, [x, z, tx, tz, d]);
                        }
                    }
                }
            }
        }
    }

    /// Largest error of component `c` in micro-units (µN, µN·mm).
    #[must_use]
    pub fn max_error_micro(&self, c: usize) -> f64 {
        self.max_error[c] * 1e6
    }
}

/// Bound of component `c` from the generated tables, N or N·mm.
#[must_use]
pub fn bound(c: usize) -> f64 {
    f64::from(ERROR_BOUND_MICRO[c]) * 1e-6
}

/// Reads the f64 model of the set `set` (its model.toml) and gives it with the lever arm
/// (mm) of the set's spec, as read when `set` was opened.
///
/// # Errors
/// model.toml missing or malformed.
pub fn load(set: &SetFolder) -> Result<(Model, f64)> {
    let model = model_file::read(&set.file(MODEL_FILE))?;
    Ok((model, set.campaign().needle.reference_from_tip_mm))
}

/// The scale of component `c` for relative figures: peak |Fy| (forces) or peak |Fy| x
/// lever arm (moments).
#[must_use]
pub fn scale(stats: &ErrorStats, c: usize, lever_arm_mm: f64) -> f64 {
    needle_contract::error_scales(stats.peak_fy_n, lever_arm_mm).get(c).copied().unwrap_or(f64::NAN)
}

/// The report as a table: measured max error and derived bound per component, absolute
/// and in % of the scale, and whether the bound meets the goal.
#[must_use]
pub fn table(stats: &ErrorStats, lever_arm_mm: f64) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "fixed point vs f64, {} poses; peak |Fy| {:.6} N; moments relative to peak |Fy| x {lever_arm_mm} mm",
        stats.poses, stats.peak_fy_n
    );
    let _ = writeln!(s, "{:<8} {:>14} {:>10} {:>14} {:>10}  unit", "comp", "max error", "% peak", "bound", "% peak");
    for c in 0..COMPONENT_COUNT {
        let sc = scale(stats, c, lever_arm_mm);
        let _ = writeln!(
            s,
            "{:<8} {:>14.3e} {:>9.5}% {:>14.3e} {:>9.5}%  {}",
            COMPONENTS[c],
            stats.max_error[c],
            100.0 * stats.max_error[c] / sc,
            bound(c),
            100.0 * bound(c) / sc,
            unit(c)
        );
    }
    let worst = (0..COMPONENT_COUNT).map(|c| 100.0 * bound(c) / scale(stats, c, lever_arm_mm)).fold(0.0, f64::max);
    let _ = writeln!(
        s,
        "goal: every bound <= {GOAL_PCT} % of peak |Fy| (x lever arm): {} (worst {worst:.5} %)",
        if worst <= GOAL_PCT { "met" } else { "MISSED" }
    );
    s
}
