//! The mirror check of `needle fe verify`: each `mirror` pose's FE result against its
//! mirrored counterpart, with the sign flips of coeffs/README.md (goal 1% of peak |Fy|).
//! No solve: it reads `fe/<pose>.csv`.

use crate::results;
use crate::spec::{Campaign, PoseSpec, Role};
use anyhow::{bail, Result};
use needle_contract::COMPONENT_COUNT;
use serde::Serialize;
use std::path::Path;

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

/// Each mirror pose against its counterpart: x -> -x flips (Fx, My, Mz), z -> -z flips
/// (Fz, Mx, My).
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
        let mut sign = [1.0f64; COMPONENT_COUNT];
        if flip_x {
            for i in [0, 4, 5] {
                sign[i] = -sign[i];
            }
        }
        if flip_z {
            for i in [2, 3, 4] {
                sign[i] = -sign[i];
            }
        }
        let peak = b.iter().map(|r| r.wrench[1].abs()).fold(0.0, f64::max);
        // forces against peak |Fy|; moments against peak |Fy| times the hub's lever arm
        let lever = c.needle.reference_from_tip_mm;
        let (mut worst, mut worst_rel, mut comp) = (0.0f64, 0.0f64, 0usize);
        for (ra, rb) in a.iter().zip(&b) {
            for i in 0..COMPONENT_COUNT {
                let d = (ra.wrench[i] - sign[i] * rb.wrench[i]).abs();
                let rel = if i < 3 { d } else { d / lever };
                if rel > worst_rel {
                    worst_rel = rel;
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
            percent_of_peak_fy: if peak > 0.0 { 100.0 * worst_rel / peak } else { f64::INFINITY },
        });
    }
    Ok(out)
}
