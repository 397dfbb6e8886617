//! A plausible tissue drawn within the spread a stack was fitted with (issue 65 item 3,
//! `needle stack sample`): each value of the spread file ([`crate::spread`]) moved from
//! the stack's by its standard deviation times a standard normal draw, the draw held
//! within [`MAX_SDS`] standard deviations (a tissue like the measured ones, not a tail
//! no trial showed) and so that the value keeps its sign. The values are drawn
//! independently (the trials are too few to tell their correlation). What follows from a
//! drawn value follows it: the track stiffness with the scale (`3 s mu0`), the static
//! friction level with the Coulomb one (by the same difference). A value with one trial
//! (sd 0) stays as it is.
use crate::spread::Row;
use anyhow::{bail, Result};
use needle_codegen::tissue as file;
use std::path::Path;

/// The largest draw, in standard deviations either way.
pub const MAX_SDS: f64 = 2.0;

/// `stack` with each value of `rows` drawn ([`MAX_SDS`], module docs); `normal` gives
/// standard normal draws, one per row in order (a seeded generator: the same seed, the
/// same tissue). The result is checked by the tissue format's reader.
///
/// # Errors
/// A row names a layer the stack does not have (`FILE:LINE` of `spread_path`), or the
/// drawn stack is refused by the format.
pub fn sample(stack: &file::Stack, rows: &[Row], spread_path: &Path, normal: &mut dyn FnMut() -> f64) -> Result<file::Stack> {
    let mut out = stack.clone();
    let n = out.layers.len();
    for r in rows {
        let Some(l) = out.layers.get_mut(r.layer) else {
            bail!(
                "{}:{}: layer {}: the stack {:?} has {n} layers (0 to {})",
                spread_path.display(),
                r.line,
                r.layer,
                stack.name,
                n.saturating_sub(1)
            )
        };
        let z = normal().clamp(-MAX_SDS, MAX_SDS);
        let value = match r.key {
            "stiffness_scale" => &mut l.stiffness_scale,
            "puncture_force_n" => &mut l.puncture_force_n,
            "cutting_force_n" => &mut l.cutting_force_n,
            _ => &mut l.friction_coulomb_n_per_mm,
        };
        let old = *value;
        // the value keeps its sign: a draw below -old / sd is held at 99 % of the way to 0
        let floor = if r.sd > 0.0 { -0.99 * old.abs() / r.sd } else { 0.0 };
        let new = old + r.sd * z.max(floor.min(0.0));
        *value = new;
        match r.key {
            "stiffness_scale" if old > 0.0 => l.track_stiffness_n_per_mm2 *= new / old,
            "friction_coulomb_n_per_mm" => l.friction_static_n_per_mm += new - old,
            _ => {}
        }
    }
    out.description = format!("{} (a tissue drawn within its spread over the trials)", stack.description);
    file::parse_stack_str(&out.to_toml(""), Path::new(&format!("{}.toml", out.name)))
        .map_err(|e| anyhow::anyhow!("the drawn stack is refused by the tissue format: {e}"))?;
    Ok(out)
}
