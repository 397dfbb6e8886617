//! `[[pose]]`: the named poses, what each is for, the mirror planes it keeps, its
//! checks, and the selection of poses by name.

use super::block::Block;
use super::error::{SpecError, SpecResult};
use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};

/// The domain of the model (docs/architecture.md section 3); poses outside it are refused.
pub const X_MAX_MM: f64 = 12.0;
/// Largest |z| of a pose, mm.
pub const Z_MAX_MM: f64 = 12.0;
/// Largest |theta_x|, |theta_z| of a pose, degrees.
pub const THETA_MAX_DEG: f64 = 15.0;

/// What a pose is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, PartialOrd, Ord)]
#[serde(rename_all = "kebab-case")]
pub enum Role {
    /// The centred vertical needle: the baseline of every sweep.
    Centre,
    /// Sweep along x (others zero), fitted.
    SweepX,
    /// Sweep along z, fitted.
    SweepZ,
    /// Sweep in theta_x, fitted.
    SweepThetaX,
    /// Sweep in theta_z, fitted.
    SweepThetaZ,
    /// Mirror-side run that checks a symmetry, not fitted.
    Mirror,
    /// The paper's Table 2 validation points, never fitted.
    Table2,
    /// Latin hypercube validation poses, never fitted.
    Lhs,
    /// Combined poses of the Sobol training design (generated from
    /// `campaign.train_seed`), fitted by the coupled model form only: the paper's form
    /// stays a fit of the sweeps.
    Train,
}

impl Role {
    /// Whether the fitter may use runs of this role.
    pub fn is_fitted(self) -> bool {
        matches!(self, Role::Centre | Role::SweepX | Role::SweepZ | Role::SweepThetaX | Role::SweepThetaZ)
    }
    /// Whether `campaign.fit_without` may name a run of this role: a sweep or a training
    /// run whose FE run cannot be solved. The centre run is always fitted; validation runs
    /// are never fitted.
    pub fn may_be_left_out(self) -> bool {
        matches!(self, Role::SweepX | Role::SweepZ | Role::SweepThetaX | Role::SweepThetaZ | Role::Train)
    }
    /// Whether the run is a validation run (never fitted).
    pub fn is_validation(self) -> bool {
        matches!(self, Role::Table2 | Role::Lhs)
    }
}

/// One named pose: needle tip on the top surface at (x, 0, z), tilted by theta_x about x
/// and theta_z about z, then fed `loading.depth_mm` along its own axis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoseSpec {
    /// File stem of the result, `fe/<name>.csv`.
    pub name: String,
    /// What the run is for.
    pub role: Role,
    /// Tip x on the top surface, mm.
    #[serde(default)]
    pub x_mm: f64,
    /// Tip z on the top surface, mm.
    #[serde(default)]
    pub z_mm: f64,
    /// Tilt about the x axis, degrees.
    #[serde(default)]
    pub theta_x_deg: f64,
    /// Tilt about the z axis, degrees.
    #[serde(default)]
    pub theta_z_deg: f64,
}

/// Mirror planes of the block and the needle that a pose keeps: a run can be solved on
/// the half (or quarter) of the block on the positive side of each plane.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Symmetry {
    /// The pose is symmetric under x -> -x (plane x = 0).
    pub plane_x: bool,
    /// The pose is symmetric under z -> -z (plane z = 0).
    pub plane_z: bool,
}

impl PoseSpec {
    /// The mirror planes this pose keeps. The block is symmetric about x = 0 and z = 0 and
    /// the double-bevel wedge about both of its own mid-planes, so a pose keeps plane
    /// x = 0 when x = 0 and theta_z = 0, and plane z = 0 when z = 0 and theta_x = 0.
    pub fn symmetry(&self) -> Symmetry {
        Symmetry { plane_x: self.x_mm == 0.0 && self.theta_z_deg == 0.0, plane_z: self.z_mm == 0.0 && self.theta_x_deg == 0.0 }
    }

    /// Unit vector along the needle axis from the tip towards the hub (at theta = 0: +y).
    /// The needle is rotated first by theta_x about x, then by theta_z about z.
    pub fn axis(&self) -> [f64; 3] {
        let (sx, cx) = self.theta_x_deg.to_radians().sin_cos();
        let (sz, cz) = self.theta_z_deg.to_radians().sin_cos();
        // R = Rz * Rx applied to (0, 1, 0): Rx(0,1,0) = (0, cx, sx); Rz(a,b,c) = (cz a - sz b, sz a + cz b, c)
        [-sz * cx, cz * cx, sx]
    }

    /// Lateral travel (x, z) of the tip over an insertion of `depth_mm` along the axis, mm.
    pub fn lateral_travel(&self, depth_mm: f64) -> (f64, f64) {
        let a = self.axis();
        (-a[0] * depth_mm, -a[2] * depth_mm)
    }

    /// Check the pose on its own (its place in the block: `check_pose_in_block`);
    /// messages start with `p`, the spec's path or `path:line`.
    ///
    /// # Errors
    /// A name that is not a file stem, a value outside the domain, a sweep pose that
    /// varies another input than its own.
    pub fn validate(&self, p: &str) -> SpecResult<()> {
        check_pose(self, p)?;
        check_pose_role(self, p)
    }
}

/// A sweep pose varies its own axis only (the centre none): the fitter reads a sweep
/// run as the deviation along that axis alone.
fn check_pose_role(pose: &PoseSpec, p: &str) -> SpecResult<()> {
    let own = match pose.role {
        Role::Centre => None,
        Role::SweepX => Some("x_mm"),
        Role::SweepZ => Some("z_mm"),
        Role::SweepThetaX => Some("theta_x_deg"),
        Role::SweepThetaZ => Some("theta_z_deg"),
        _ => return Ok(()),
    };
    for (f, v) in [("x_mm", pose.x_mm), ("z_mm", pose.z_mm), ("theta_x_deg", pose.theta_x_deg), ("theta_z_deg", pose.theta_z_deg)] {
        if Some(f) != own && v != 0.0 {
            let what = own.map_or("the centre pose has all four at 0".to_string(), |o| format!("a {:?} pose varies {o} only", pose.role));
            return Err(SpecError::inconsistent(p, format!("pose.{f}"), format!("pose {:?}: {f} = {v}: must be 0 ({what})", pose.name)));
        }
    }
    Ok(())
}

/// The needle stays inside the block: at entry and at full depth (after the lateral
/// travel of the tilt), the needle's axis is at least its radius from each side face.
pub(crate) fn check_pose_in_block(pose: &PoseSpec, block: &Block, radius_mm: f64, depth_mm: f64, p: &str) -> SpecResult<()> {
    let (tx, tz) = pose.lateral_travel(depth_mm);
    for (f, entry, travel, half) in [("x_mm", pose.x_mm, tx, block.size_x_mm / 2.0), ("z_mm", pose.z_mm, tz, block.size_z_mm / 2.0)] {
        let reach = entry.abs().max((entry + travel).abs()) + radius_mm;
        if reach > half {
            return Err(SpecError::OutsideBlock {
                at: p.to_string(),
                pose: pose.name.clone(),
                message: format!(
                    "pose {:?}: {f} = {entry} with a lateral travel of {travel:.3} mm at full depth ({depth_mm} mm): the needle (radius {radius_mm} mm) reaches {reach:.3} mm from the centre, beyond the block's side at {half} mm",
                    pose.name
                ),
            });
        }
    }
    Ok(())
}

/// The name is a file stem and the pose inside the domain.
fn check_pose(pose: &PoseSpec, p: &str) -> SpecResult<()> {
    if pose.name.is_empty() || !pose.name.chars().all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '+' | '_')) {
        return Err(SpecError::range(p, "pose.name", format!("pose name {:?}: use letters, digits, '-', '+', '_' only", pose.name)));
    }
    for (f, v, max, unit) in [
        ("x_mm", pose.x_mm, X_MAX_MM, "mm"),
        ("z_mm", pose.z_mm, Z_MAX_MM, "mm"),
        ("theta_x_deg", pose.theta_x_deg, THETA_MAX_DEG, "deg"),
        ("theta_z_deg", pose.theta_z_deg, THETA_MAX_DEG, "deg"),
    ] {
        if !(v.is_finite() && v.abs() <= max) {
            return Err(SpecError::range(
                p,
                format!("pose.{f}"),
                format!("pose {:?}: {f} = {v}: outside the domain |{f}| <= {max} {unit}", pose.name),
            ));
        }
    }
    Ok(())
}

/// Select poses whose name matches a glob `pattern` (`*`, `?`, `[..]`), or any of several
/// globs separated by commas (`lhs-09,lhs-1*`). Poses keep the spec's order.
///
/// # Errors
/// A pattern is empty or not a valid glob.
pub fn select<'a>(poses: &'a [PoseSpec], pattern: Option<&str>) -> Result<Vec<&'a PoseSpec>> {
    let Some(list) = pattern else { return Ok(poses.iter().collect()) };
    let globs = list
        .split(',')
        .map(|pat| {
            if pat.trim().is_empty() {
                bail!("--only {list:?}: empty pattern between commas");
            }
            glob::Pattern::new(pat.trim()).with_context(|| format!("--only {list:?}: {pat:?} is not a valid glob"))
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(poses.iter().filter(|p| globs.iter().any(|g| g.matches(&p.name))).collect())
}

#[cfg(test)]
mod tests {
    use super::{select, PoseSpec, Role};
    use crate::spec::{parse, SpecError};
    use std::path::Path;

    fn names(poses: &[&PoseSpec]) -> Vec<String> {
        poses.iter().map(|p| p.name.clone()).collect()
    }

    #[test]
    fn select_takes_comma_separated_globs_in_spec_order() {
        let poses: Vec<PoseSpec> = ["centre", "lhs-03", "lhs-09", "lhs-10", "lhs-13"]
            .iter()
            .map(|n| PoseSpec { name: (*n).to_owned(), role: Role::Lhs, x_mm: 0.0, z_mm: 0.0, theta_x_deg: 0.0, theta_z_deg: 0.0 })
            .collect();
        let all = select(&poses, None).map(|v| names(&v)).ok();
        assert_eq!(all.map(|v| v.len()), Some(5));
        let two = select(&poses, Some("lhs-1*,lhs-09")).map(|v| names(&v)).ok();
        assert_eq!(two, Some(vec!["lhs-09".into(), "lhs-10".into(), "lhs-13".into()]));
        assert!(select(&poses, Some("lhs-09,,x")).is_err(), "an empty pattern is refused");
        assert!(select(&poses, Some("lhs-[")).is_err(), "a broken glob is refused");
    }

    /// Issue 18: a pose outside the block and a sweep pose off its axis were accepted.
    #[test]
    fn poses_outside_the_block_or_off_their_sweep_axis_are_refused() {
        let set = needle_stdx::workspace_root().join("coeffs/default");
        let text = std::fs::read_to_string(set.join("campaign.toml")).expect("campaign.toml");
        // block 10 mm wide: x+06 (the first listed pose beyond 4.5 mm) is outside
        let narrow = text.replace("size_x_mm = 50.0", "size_x_mm = 10.0");
        assert_ne!(narrow, text, "the test's edit did not apply");
        let r = parse(&narrow, Path::new("campaign.toml"));
        assert!(matches!(&r, Err(SpecError::OutsideBlock { at, pose, .. }) if at == "campaign.toml" && pose == "x+06"), "{r:?}");
        // a sweep-x pose with z = 3
        let off_axis = text.replacen("role = \"sweep-x\"\nx_mm = 2.0", "role = \"sweep-x\"\nx_mm = 2.0\nz_mm = 3.0", 1);
        assert_ne!(off_axis, text, "the test's edit did not apply");
        let r = parse(&off_axis, Path::new("campaign.toml"));
        assert!(matches!(&r, Err(SpecError::Inconsistent { field, .. }) if field == "pose.z_mm"), "{r:?}");
        assert!(parse(&text, Path::new("campaign.toml")).is_ok(), "the shipped spec passes");
        // a malformed value: file and line
        let line = text.lines().position(|l| l.starts_with("bulk_to_shear =")).expect("bulk_to_shear line") + 1;
        let bad = text.replace("bulk_to_shear = 100.0", "bulk_to_shear = abc");
        let e = parse(&bad, Path::new("campaign.toml")).err();
        assert!(matches!(&e, Some(SpecError::Syntax { line: l, .. }) if *l == line), "{e:?}");
        let msg = e.map(|e| e.to_string()).unwrap_or_default();
        assert!(msg.starts_with(&format!("campaign.toml:{line}: ")), "the message starts with file:line: {msg}");
    }
}
