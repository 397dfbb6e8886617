//! The mirror check of `needle fe verify`: each `mirror` pose's FE result against its
//! mirrored counterpart, with the sign flips of coeffs/README.md (goal 1% of peak |Fy|).
//! No solve: it reads `fe/<pose>.csv`.

use crate::results;
use crate::spec::{Campaign, PoseSpec, Role};
use anyhow::{bail, Result};
use needle_contract::{error_scales, COMPONENT_COUNT, ODD};
use serde::Serialize;
use std::path::Path;

/// Largest difference of a mirror run from its counterpart that the check accepts, % of
/// peak |Fy| (moments: of peak |Fy| times the hub's lever arm).
pub const MIRROR_GOAL_PERCENT: f64 = 1.0;

/// Mirror-run result of one pose.
#[derive(Debug, Clone, Serialize)]
pub struct MirrorReport {
    /// The mirror pose.
    pub pose: String,
    /// Its counterpart on the positive side.
    pub counterpart: String,
    /// Largest difference over depths and components after the sign flips, N or N*mm.
    pub max_difference: f64,
    /// Component of that difference.
    pub component: String,
    /// That difference as % of the counterpart's peak |Fy| (forces) or of peak |Fy| times
    /// `needle.reference_from_tip_mm` (moments: the moment the peak axial force would make
    /// on the hub's lever arm).
    pub percent_of_peak_fy: f64,
}

/// Each mirror pose against its counterpart: x -> -x flips the components odd in x (Fx,
/// My, Mz), z -> -z those odd in z (Fz, Mx, My), per the contract's `ODD`.
pub(super) fn mirror_checks(c: &Campaign, fe: &Path) -> Result<Vec<MirrorReport>> {
    let poses = c.poses();
    let mut out = Vec::new();
    for m in poses.iter().filter(|p| p.role == Role::Mirror) {
        let (flip_x, flip_z) = (m.x_mm < 0.0 || m.theta_z_deg < 0.0, m.z_mm < 0.0 || m.theta_x_deg < 0.0);
        let want = PoseSpec {
            name: String::new(),
            role: m.role,
            x_mm: m.x_mm.abs(),
            z_mm: m.z_mm.abs(),
            theta_x_deg: m.theta_x_deg.abs(),
            theta_z_deg: m.theta_z_deg.abs(),
        };
        let Some(cp) = poses.iter().find(|p| {
            p.role != Role::Mirror
                && p.x_mm == want.x_mm
                && p.z_mm == want.z_mm
                && p.theta_x_deg == want.theta_x_deg
                && p.theta_z_deg == want.theta_z_deg
        }) else {
            bail!("mirror pose {}: no counterpart pose with the mirrored values in the spec", m.name);
        };
        let a = results::read_csv(&fe.join(format!("{}.csv", m.name)))?;
        let b = results::read_csv(&fe.join(format!("{}.csv", cp.name)))?;
        if a.len() != b.len() {
            bail!("mirror pose {}: {} rows, counterpart {} has {}", m.name, a.len(), cp.name, b.len());
        }
        // The x = 0 plane flips the components odd in x (ODD[0], the same as theta_z's),
        // the z = 0 plane those odd in z (ODD[1], the same as theta_x's).
        let [odd_x, odd_z, ..] = ODD;
        // flipped by exactly one of the two planes: sign -1 (by both: +1)
        let sign: [f64; COMPONENT_COUNT] = std::array::from_fn(|i| if (flip_x && odd_x[i]) != (flip_z && odd_z[i]) { -1.0 } else { 1.0 });
        let peak = results::peak_fy_n(&b);
        // forces against peak |Fy|; moments against peak |Fy| times the hub's lever arm
        let scales = error_scales(peak, c.needle.reference_from_tip_mm);
        let (mut worst, mut worst_pct, mut comp) = (0.0f64, 0.0f64, 0usize);
        for (ra, rb) in a.iter().zip(&b) {
            for i in 0..COMPONENT_COUNT {
                let d = (ra.wrench[i] - sign[i] * rb.wrench[i]).abs();
                let pct = if scales[i] > 0.0 { 100.0 * d / scales[i] } else { f64::INFINITY };
                if pct > worst_pct {
                    worst_pct = pct;
                    worst = d;
                    comp = i;
                }
            }
        }
        out.push(MirrorReport {
            pose: m.name.clone(),
            counterpart: cp.name.clone(),
            max_difference: worst,
            component: needle_contract::COMPONENTS[comp].to_string(),
            percent_of_peak_fy: worst_pct,
        });
    }
    Ok(out)
}

impl std::fmt::Display for MirrorReport {
    /// The report's line in `needle fe verify`'s table.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "mirror {:>6} vs {:>6}: max difference {:.3e} ({}) = {:.3}% of peak |Fy| (goal <= {MIRROR_GOAL_PERCENT}%)",
            self.pose, self.counterpart, self.max_difference, self.component, self.percent_of_peak_fy
        )
    }
}
