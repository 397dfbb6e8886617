//! `[family]`: the material family (issue 64): the centre pose solved deep for a family of
//! blended tissues (the paper's Ogden terms of `[tissue]` weighted by `weight`, a soft
//! one-term Ogden of exponent `soft_alpha` by `1 - weight`, at the initial shear modulus of
//! `[tissue]`), and a few off-centre poses at two members to check the ratio law that
//! carries the coupled model's pose dependence over to the family. The runs themselves are
//! `needle_fe::family`'s; here the section's type and its checks.

pub mod runs;

use super::error::{SpecError, SpecResult};
use super::loading::MAX_LOAD_STEPS;
use super::pose::check_pose_in_block;
use super::Campaign;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The largest |soft_alpha| the soft term may have: past it `lambda^alpha` over the checked
/// stretch range spans more than 1e12 and FEBio's Newton iterations stop being meaningful.
pub const MAX_ABS_ALPHA: f64 = 30.0;

/// `[family]`: which members are solved how deep, in how many load steps, on which mesh,
/// and which off-centre poses check the ratio law at which members.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FamilySettings {
    /// The members' weights of the paper's terms, each in `0 ..= 1` (exclusive of 1: the
    /// paper's own tissue is the reference run), solved in this order (each a distinct
    /// tissue, hence a distinct run hash).
    pub weight: Vec<f64>,
    /// The Ogden exponent of the soft term (2: neo-Hookean), weighted by `1 - weight`.
    pub soft_alpha: f64,
    /// Final depth of the centre runs along the needle axis, mm.
    pub depth_mm: f64,
    /// Number of equal load steps to `depth_mm`.
    pub steps: u32,
    /// Mesh level (`[mesh.<level>]`) of the centre runs; its fine layers reach past `depth_mm`.
    pub mesh: String,
    /// Off-centre poses of the campaign solved at `check_weight` to `loading.depth_mm` on
    /// the campaign's mesh level.
    #[serde(default)]
    pub check_poses: Vec<String>,
    /// The members (each one of `weight`) the off-centre poses are solved at.
    #[serde(default)]
    pub check_weight: Vec<f64>,
    /// The members (each one of `weight`) the family's surrogate is not fitted on: `needle
    /// fit` checks it against them (members it was not fitted on).
    #[serde(default)]
    pub held_out: Vec<f64>,
    /// `[family.fitted]`: the FEBio run of a calibrated layer's material (issue 64, item 5);
    /// absent: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fitted: Option<FittedMaterial>,
}

/// `[family.fitted]`: a calibrated layer's material solved by FEBio at the centre (the
/// member `family_weight` of the layer with every modulus times its `stiffness_scale`,
/// both read from the stack file when the run is made: [`runs::FamilyRun::fitted`]) on
/// `family.mesh`, to `depth_mm` in `steps` load steps: the check that a fitted tissue is a
/// material and not a curve (its force against the measured curve, by geometric
/// similarity, in `needle_calibrate::fe_loop`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FittedMaterial {
    /// The stack file, relative to the set's folder (`calibrated/<name>.toml`).
    pub stack: String,
    /// The layer (0: the surface's) whose material is solved.
    pub layer: usize,
    /// Final depth along the needle axis, mm (the FE needle's: the measured depth over the
    /// geometric similarity).
    pub depth_mm: f64,
    /// Number of equal load steps to `depth_mm`.
    pub steps: u32,
}

impl FittedMaterial {
    /// The run's name: `fitted_<stack file stem>_l<layer>` (`fitted_rig_skin_2mmps_t1_l0`).
    #[must_use]
    pub fn run_name(&self) -> String {
        let stem = std::path::Path::new(&self.stack).file_stem().map_or_else(String::new, |s| s.to_string_lossy().into_owned());
        format!("fitted_{stem}_l{}", self.layer)
    }
}

/// The run name of `pose` at the member `weight`: `centre_w0p05`, `x+04_w0p2`, `centre_w0`
/// (a file name: no dot).
pub fn member_name(pose: &str, weight: f64) -> String {
    format!("{pose}_w{}", format!("{weight}").replace('.', "p"))
}

/// Check `[family]` against the rest of the spec; messages start with `file:line:` and
/// name the field (`family.weight = ...`).
///
/// # Errors
/// No members, a weight outside `0 ..= 1` or equal to 1 (the reference), a soft exponent
/// that is not finite, zero or beyond [`MAX_ABS_ALPHA`], a member listed twice (names collide), a depth outside the block, 0 steps or too many, an
/// unknown mesh level or one whose fine layers stop above the depth, an unknown or
/// repeated check pose, a check pose whose needle leaves the block, or a check or
/// held-out member that is not one of `weight`.
pub fn validate_family(c: &Campaign, text: &str, path: &Path) -> SpecResult<()> {
    let Some(f) = &c.family else { return Ok(()) };
    let at = |key: &str| format!("{}:{}", path.display(), crate::spec::key_line(text, "family", key));
    if f.weight.is_empty() {
        return Err(SpecError::range(at("weight"), "family.weight", "family.weight is empty: name at least one member"));
    }
    for (k, &w) in f.weight.iter().enumerate() {
        if !(w.is_finite() && (0.0..1.0).contains(&w)) {
            let message = format!("family.weight = {w}: must be in 0 ..= 1, not 1 (weight 1 is the paper's tissue, the reference run)");
            return Err(SpecError::range(at("weight"), "family.weight", message));
        }
        let name = member_name("centre", w);
        if f.weight[..k].iter().any(|&b| member_name("centre", b) == name) {
            return Err(SpecError::duplicate(at("weight"), "family.weight", w.to_string(), format!("family.weight: {w} is listed twice")));
        }
    }
    let a = f.soft_alpha;
    if !(a.is_finite() && a != 0.0 && a.abs() <= MAX_ABS_ALPHA) {
        let message = format!("family.soft_alpha = {a}: must be finite, not 0 and within +-{MAX_ABS_ALPHA}");
        return Err(SpecError::range(at("soft_alpha"), "family.soft_alpha", message));
    }
    if !(f.depth_mm.is_finite() && f.depth_mm > 0.0 && f.depth_mm < c.block.depth_mm) {
        let message =
            format!("family.depth_mm = {}: must be > 0 and inside the block (block.depth_mm = {} mm)", f.depth_mm, c.block.depth_mm);
        return Err(SpecError::range(at("depth_mm"), "family.depth_mm", message));
    }
    if f.steps == 0 || f.steps > MAX_LOAD_STEPS {
        return Err(SpecError::range(at("steps"), "family.steps", format!("family.steps = {}: must be 1 ..= {MAX_LOAD_STEPS}", f.steps)));
    }
    let Some(level) = c.mesh.get(&f.mesh) else {
        let levels: Vec<&str> = c.mesh.keys().map(String::as_str).collect();
        let message = format!("family.mesh = {:?}: no [mesh.{}] level (levels: {})", f.mesh, f.mesh, levels.join(", "));
        return Err(SpecError::unknown(at("mesh"), "family.mesh", &f.mesh, message));
    };
    if level.fine_depth_mm < f.depth_mm {
        let message = format!(
            "family.mesh = {:?}: its fine layers end at fine_depth_mm = {} mm, above family.depth_mm = {} mm",
            f.mesh, level.fine_depth_mm, f.depth_mm
        );
        return Err(SpecError::inconsistent(at("mesh"), "family.mesh", message));
    }
    validate_checks(c, f, &at)?;
    validate_fitted(c, f, text, path)
}

/// `[family.fitted]`: a stack path inside the set, a depth inside the block and the
/// family mesh's fine layers, 1 ..= [`MAX_LOAD_STEPS`] steps.
fn validate_fitted(c: &Campaign, f: &FamilySettings, text: &str, path: &Path) -> SpecResult<()> {
    let Some(m) = &f.fitted else { return Ok(()) };
    let at = |key: &str| format!("{}:{}", path.display(), crate::spec::key_line(text, "family.fitted", key));
    let stack = std::path::Path::new(&m.stack);
    if m.stack.is_empty() || stack.is_absolute() || stack.components().any(|c| matches!(c, std::path::Component::ParentDir)) {
        let message = format!("family.fitted.stack = {:?}: must be a path inside the set's folder (calibrated/<name>.toml)", m.stack);
        return Err(SpecError::range(at("stack"), "family.fitted.stack", message));
    }
    let fine = c.mesh.get(&f.mesh).map_or(0.0, |l| l.fine_depth_mm);
    if !(m.depth_mm.is_finite() && m.depth_mm > 0.0 && m.depth_mm <= fine) {
        let message = format!(
            "family.fitted.depth_mm = {}: must be > 0 and within the family mesh's fine layers (fine_depth_mm = {fine} mm)",
            m.depth_mm
        );
        return Err(SpecError::range(at("depth_mm"), "family.fitted.depth_mm", message));
    }
    if m.steps == 0 || m.steps > MAX_LOAD_STEPS {
        let message = format!("family.fitted.steps = {}: must be 1 ..= {MAX_LOAD_STEPS}", m.steps);
        return Err(SpecError::range(at("steps"), "family.fitted.steps", message));
    }
    Ok(())
}

/// The off-centre check runs: known poses inside the block, listed once; members of the family.
fn validate_checks(c: &Campaign, f: &FamilySettings, at: &dyn Fn(&str) -> String) -> SpecResult<()> {
    let every = c.poses();
    for (k, name) in f.check_poses.iter().enumerate() {
        if f.check_poses[..k].contains(name) {
            return Err(SpecError::duplicate(
                at("check_poses"),
                "family.check_poses",
                name,
                format!("family.check_poses: {name:?} is listed twice"),
            ));
        }
        let Some(pose) = every.iter().find(|p| &p.name == name) else {
            let message = format!("family.check_poses: {name:?} is not a pose of this campaign");
            return Err(SpecError::unknown(at("check_poses"), "family.check_poses", name, message));
        };
        check_pose_in_block(pose, &c.block, c.needle.diameter_mm / 2.0, c.loading.depth_mm, &at("check_poses"))?;
    }
    for &w in &f.check_weight {
        if !f.weight.contains(&w) {
            let message = format!("family.check_weight = {w}: not a member (family.weight)");
            return Err(SpecError::inconsistent(at("check_weight"), "family.check_weight", message));
        }
    }
    for &w in &f.held_out {
        if !f.weight.contains(&w) {
            let message = format!("family.held_out = {w}: not a member (family.weight)");
            return Err(SpecError::inconsistent(at("held_out"), "family.held_out", message));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::parse;
    use crate::spec::shipped_key;

    fn refusal(text: &str) -> SpecError {
        match parse(text, Path::new("campaign.toml")) {
            Ok(_) => panic!("the spec was accepted"),
            Err(e) => e,
        }
    }

    #[test]
    fn member_names_are_file_names() {
        assert_eq!(member_name("centre", 0.05), "centre_w0p05");
        assert_eq!(member_name("x+04", 0.2), "x+04_w0p2");
        assert_eq!(member_name("centre", 0.0), "centre_w0");
    }

    #[test]
    fn bad_family_sections_are_refused_with_file_line_and_field() {
        let (text, weight_line, weight) = shipped_key("family", "weight");
        let (_, soft_line, soft) = shipped_key("family", "soft_alpha");
        let (_, _, depth) = shipped_key("family", "depth_mm");
        let (_, _, mesh) = shipped_key("family", "mesh");
        let (_, check_line, check) = shipped_key("family", "check_weight");
        let (_, poses_line, poses) = shipped_key("family", "check_poses");
        let (_, held_line, held) = shipped_key("family", "held_out");
        let (_, stack_line, stack) = shipped_key("family.fitted", "stack");
        let (_, fitted_depth_line, fitted_depth) = shipped_key("family.fitted", "depth_mm");
        let (_, fitted_steps_line, fitted_steps) = shipped_key("family.fitted", "steps");
        let cases = [
            (text.replace(&weight, "weight = []"), "family.weight", weight_line),
            (text.replace(&weight, "weight = [0.1, 1.0]"), "family.weight", weight_line),
            (text.replace(&weight, "weight = [0.1, -0.2]"), "family.weight", weight_line),
            (text.replace(&weight, "weight = [0.1, nan]"), "family.weight", weight_line),
            (text.replace(&weight, "weight = [0.1, 0.2, 0.1]"), "family.weight", weight_line),
            (text.replace(&soft, "soft_alpha = 0.0"), "family.soft_alpha", soft_line),
            (text.replace(&soft, "soft_alpha = 40.0"), "family.soft_alpha", soft_line),
            (text.replace(&depth, "depth_mm = 31.0"), "family.depth_mm", shipped_key("family", "depth_mm").1),
            (text.replace(&mesh, "mesh = \"needle8\""), "family.mesh", shipped_key("family", "mesh").1),
            (text.replace(&check, "check_weight = [0.75]"), "family.check_weight", check_line),
            (text.replace(&poses, "check_poses = [\"nowhere\"]"), "family.check_poses", poses_line),
            (text.replace(&held, "held_out = [0.4]"), "family.held_out", held_line),
            (text.replace(&poses, "check_poses = [\"x+04\", \"x+04\"]"), "family.check_poses", poses_line),
            (text.replace(&stack, "stack = \"../elsewhere.toml\""), "family.fitted.stack", stack_line),
            (text.replace(&fitted_depth, "depth_mm = 40.0"), "family.fitted.depth_mm", fitted_depth_line),
            (text.replace(&fitted_steps, "steps = 0"), "family.fitted.steps", fitted_steps_line),
        ];
        for (spec, field, line) in cases {
            assert_ne!(spec, text, "the test's edit did not apply ({field})");
            let e = refusal(&spec);
            assert_eq!(e.field(), field, "{e:?}");
            assert!(e.to_string().starts_with(&format!("campaign.toml:{line}: ")), "file:line first: {e}");
        }
    }
}
