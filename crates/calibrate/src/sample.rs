//! A plausible tissue drawn within the spread a stack was fitted with (issue 65 item 3,
//! `needle stack sample`): each value of the spread file ([`crate::spread`]) moved from
//! the stack's by its standard deviation times a standard normal draw, the draw held
//! within [`MAX_SDS`] standard deviations (a tissue like the measured ones, not a tail
//! no trial showed) and so that the value keeps its sign. The values are drawn
//! independently (the trials are too few to tell their correlation). What follows from a
//! drawn value follows it: the track stiffness with the scale (`3 s mu0`), the static
//! friction level with the Coulomb one (by the same difference). A value with one trial
//! (sd 0) stays as it is.
use crate::spread::{self, Row};
use anyhow::{bail, Context, Result};
use needle_codegen::tissue as file;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::path::{Path, PathBuf};

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

/// A tissue file drawn within its spread file ([`sample_file`]).
#[derive(Debug, Clone)]
pub struct Drawn {
    /// The stack as read.
    pub stack: file::Stack,
    /// The drawn stack, named as asked.
    pub drawn: file::Stack,
    /// The spread's rows, in the file's order.
    pub rows: Vec<Row>,
    /// The spread file read.
    pub spread_path: PathBuf,
    /// The seed of the draws.
    pub seed: u64,
}

impl Drawn {
    /// The drawn stack's tissue file text, its header saying where it was drawn from.
    #[must_use]
    pub fn to_toml(&self, stack_path: &Path) -> String {
        let header = format!(
            "Tissue stack `{}`, written by `needle stack sample` (format: coeffs/README.md, \"Tissue stacks\").\nDrawn from {} within {} (seed {}).",
            self.drawn.name,
            stack_path.display(),
            self.spread_path.display(),
            self.seed
        );
        self.drawn.to_toml(&header)
    }
}

/// The tissue file `stack_path` drawn within its spread (`spread_path`, default
/// [`spread::beside`] it) with the seeded draws of [`seeded_normal`], named `name`: the
/// one draw every front end makes (`needle stack sample`, Python), so the same files and
/// seed give the same tissue everywhere.
///
/// # Errors
/// A file cannot be read or is refused (`FILE:LINE`), `name` is not a stack's name, or
/// the drawn stack is refused by the format.
pub fn sample_file(stack_path: &Path, spread_path: Option<&Path>, name: &str, seed: u64) -> Result<Drawn> {
    if !file::is_stack_name(name) {
        bail!("name {name:?}: {}", file::STACK_NAME_RULE);
    }
    let spread_path = spread_path.map_or_else(|| spread::beside(stack_path), Path::to_path_buf);
    let text = std::fs::read_to_string(stack_path).with_context(|| format!("{}: cannot read the stack", stack_path.display()))?;
    let stack = file::parse_stack_str(&text, stack_path).map_err(|e| anyhow::anyhow!("{e}"))?;
    let rows = spread::read(&spread_path)?;
    let renamed = file::Stack { name: name.to_string(), ..stack.clone() };
    let drawn = sample(&renamed, &rows, &spread_path, &mut seeded_normal(seed))?;
    Ok(Drawn { stack, drawn, rows, spread_path, seed })
}

/// The value of row `r`'s key in `s` (NaN when the layer is missing).
#[must_use]
pub fn value(s: &file::Stack, r: &Row) -> f64 {
    s.layers.get(r.layer).map_or(f64::NAN, |l| match r.key {
        "stiffness_scale" => l.stiffness_scale,
        "puncture_force_n" => l.puncture_force_n,
        "cutting_force_n" => l.cutting_force_n,
        _ => l.friction_coulomb_n_per_mm,
    })
}

/// Standard normal draws from `seed` (ChaCha8, Box-Muller on two uniform draws in (0, 1]).
pub fn seeded_normal(seed: u64) -> impl FnMut() -> f64 {
    use rand::Rng;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    move || {
        let u1: f64 = 1.0 - rng.gen::<f64>();
        let u2: f64 = rng.gen::<f64>();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}
