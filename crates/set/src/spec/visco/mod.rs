//! The `[viscoelastic]` section of the campaign spec checked against the rest of it (the
//! ramp-and-hold runs, `needle_fe::visco`).

use super::{check_pose_in_block, Campaign, MAX_LOAD_STEPS};
pub mod runs;
pub mod settings;

use anyhow::{bail, Result};
pub use runs::{apply, apply_frictionless_elastic, describe, Friction};
pub use settings::{decimal_tag, frictionless_name, run_name, Prony, RampHold, ViscoSettings, FRICTIONLESS_SUFFIX, MAX_PRONY_TERMS};
use std::path::Path;

/// Check `[viscoelastic]` against the rest of the spec (and that `[tissue]` / `[loading]`
/// do not set what only it sets); messages start with `file:line:` and name the field.
///
/// # Errors
/// No or more than [`MAX_PRONY_TERMS`] terms, `g` and `tau_s` of different lengths, a
/// g_i < 0 or not finite, a tau_i <= 0 or not finite, a speed <= 0 or repeated, a hold
/// or its first point out of range, an unknown mesh level, an unknown or repeated pose.
pub(crate) fn validate(c: &Campaign, text: &str, path: &Path) -> Result<()> {
    let at = |key: &str| format!("{}:{}", path.display(), crate::spec::key_line(text, "viscoelastic", key));
    if c.tissue.prony.is_some() || c.loading.ramp_hold.is_some() {
        let (s, k) = if c.tissue.prony.is_some() { ("tissue", "prony") } else { ("loading", "ramp_hold") };
        bail!(
            "{}:{}: {s}.{k}: set by [viscoelastic] for its runs only, not in the file",
            path.display(),
            crate::spec::key_line(text, s, k).max(crate::spec::key_line(text, &format!("{s}.{k}"), ""))
        );
    }
    let Some(v) = &c.viscoelastic else { return Ok(()) };
    if v.g.is_empty() || v.g.len() > MAX_PRONY_TERMS {
        bail!("{}: viscoelastic.g has {} terms: must be 1 ..= {MAX_PRONY_TERMS}", at("g"), v.g.len());
    }
    if v.tau_s.len() != v.g.len() {
        bail!("{}: viscoelastic.tau_s has {} values, g has {}: one tau_s per g", at("tau_s"), v.tau_s.len(), v.g.len());
    }
    if let Some(g) = v.g.iter().find(|g| !(g.is_finite() && **g >= 0.0)) {
        bail!("{}: viscoelastic.g = {g}: every g_i must be finite and >= 0 (a negative weight is not passive)", at("g"));
    }
    if let Some(t) = v.tau_s.iter().find(|t| !(t.is_finite() && **t > 0.0)) {
        bail!("{}: viscoelastic.tau_s = {t} s: every tau_i must be finite and > 0 s", at("tau_s"));
    }
    let sum: f64 = v.g.iter().sum();
    if sum > needle_contract::PRONY_G_SUM_MAX {
        bail!(
            "{}: viscoelastic.g sums to {sum}: must be <= {} (the instantaneous response at most {} times the long-term one)",
            at("g"),
            needle_contract::PRONY_G_SUM_MAX,
            needle_contract::PRONY_G_SUM_MAX + 1.0
        );
    }
    if v.speeds_mm_per_s.is_empty() {
        bail!("{}: viscoelastic.speeds_mm_per_s is empty: name at least one speed", at("speeds_mm_per_s"));
    }
    for (k, s) in v.speeds_mm_per_s.iter().enumerate() {
        if !(s.is_finite() && *s > 0.0) {
            bail!("{}: viscoelastic.speeds_mm_per_s: {s} mm/s: must be finite and > 0", at("speeds_mm_per_s"));
        }
        if v.speeds_mm_per_s[..k].iter().any(|o| run_name("", *o) == run_name("", *s)) {
            bail!("{}: viscoelastic.speeds_mm_per_s: {s} mm/s is listed twice", at("speeds_mm_per_s"));
        }
    }
    if !(v.hold_s.is_finite() && v.hold_s > 0.0) {
        bail!("{}: viscoelastic.hold_s = {} s: must be finite and > 0", at("hold_s"), v.hold_s);
    }
    if v.hold_steps == 0 || v.hold_steps + c.loading.steps > MAX_LOAD_STEPS {
        bail!(
            "{}: viscoelastic.hold_steps = {}: must be >= 1, with loading.steps at most {MAX_LOAD_STEPS}",
            at("hold_steps"),
            v.hold_steps
        );
    }
    if !(v.hold_first_s.is_finite() && v.hold_first_s > 0.0 && v.hold_first_s <= v.hold_s) {
        bail!("{}: viscoelastic.hold_first_s = {} s: must be in (0, hold_s = {} s]", at("hold_first_s"), v.hold_first_s, v.hold_s);
    }
    if !(v.min_residual_n.is_finite() && v.min_residual_n >= 0.0) {
        bail!("{}: viscoelastic.min_residual_n = {} N: must be finite and >= 0", at("min_residual_n"), v.min_residual_n);
    }
    if !c.mesh.contains_key(&v.mesh) {
        let levels: Vec<&str> = c.mesh.keys().map(String::as_str).collect();
        bail!("{}: viscoelastic.mesh = {:?}: no [mesh.{}] level (levels: {})", at("mesh"), v.mesh, v.mesh, levels.join(", "));
    }
    if v.poses.is_empty() {
        bail!("{}: viscoelastic.poses is empty: name at least one pose (e.g. \"centre\")", at("poses"));
    }
    let every = c.poses();
    for (k, name) in v.poses.iter().enumerate() {
        if v.poses[..k].contains(name) {
            bail!("{}: viscoelastic.poses: {name:?} is listed twice", at("poses"));
        }
        let Some(pose) = every.iter().find(|p| &p.name == name) else {
            bail!("{}: viscoelastic.poses: {name:?} is not a pose of this campaign", at("poses"));
        };
        check_pose_in_block(pose, &c.block, c.needle.diameter_mm / 2.0, c.loading.depth_mm, &at("poses"))?;
    }
    Ok(())
}
