//! `needle stack sample`: a tissue drawn within the spread of a stack fitted on several
//! trials ([`needle_calibrate::sample`]), written as a tissue file.
use crate::planned_outputs::{self, Planned};
use anyhow::{Context, Result};
use clap::Args;
use needle_calibrate::{sample, spread};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `needle stack sample`.
#[derive(Args)]
// The fields' doc comments are the --help text, written for the terminal: <name> is a
// placeholder there, not HTML.
#[allow(rustdoc::invalid_html_tags)]
pub struct SampleArgs {
    /// The stack: a tissue file written by `needle calibrate --trials`.
    #[arg(long, value_name = "FILE")]
    pub stack: PathBuf,
    /// Its spread over the trials; default: beside the stack, <name>.spread.csv.
    #[arg(long, value_name = "CSV")]
    pub spread: Option<PathBuf>,
    /// Seed of the draws (the same seed, the same tissue).
    #[arg(long)]
    pub seed: u64,
    /// The drawn tissue file; its stem is the stack's name (lower-case ASCII letters,
    /// digits and '_', starting with a letter).
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    /// Replace an existing file.
    #[arg(long)]
    pub force: bool,
}

/// Runs `needle stack sample`: prints each drawn value beside the stack's.
///
/// # Errors
/// The stack or its spread is refused (`FILE:LINE`), the name is not a stack's, the
/// output is refused or cannot be written (nothing written).
pub fn run(a: SampleArgs) -> Result<ExitCode> {
    let name = a.out.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    crate::commands::calibrate::check_name(&name)
        .with_context(|| format!("--out {}: the file's stem is the stack's name", a.out.display()))?;
    let spread_path = a.spread.clone().unwrap_or_else(|| spread::beside(&a.stack));
    let inputs = [("--stack", a.stack.as_path()), ("--spread", spread_path.as_path())];
    planned_outputs::check(&[Planned { option: "--out", path: &a.out }], None, &inputs, a.force)?;
    let text = std::fs::read_to_string(&a.stack).with_context(|| format!("--stack {}: cannot read", a.stack.display()))?;
    let stack = needle_codegen::tissue::parse_stack_str(&text, &a.stack).map_err(|e| anyhow::anyhow!("{e}"))?;
    let rows = spread::read(&spread_path)?;
    let mut rng = ChaCha8Rng::seed_from_u64(a.seed);
    let mut normal = || standard_normal(&mut rng);
    let renamed = needle_codegen::tissue::Stack { name: name.clone(), ..stack.clone() };
    let drawn = sample::sample(&renamed, &rows, &spread_path, &mut normal)?;
    for r in &rows {
        let (old, new) = (value(&stack, r), value(&drawn, r));
        println!("layer {} {}: {old:.6} -> {new:.6} (sd {:.3e} over {} trials)", r.layer, r.key, r.sd, r.trials);
    }
    let header = format!(
        "Tissue stack `{name}`, written by `needle stack sample` (format: coeffs/README.md, \"Tissue stacks\").\nDrawn from {} within {} (seed {}).",
        a.stack.display(),
        spread_path.display(),
        a.seed
    );
    needle_stdx::fs::write_all_atomic(&[(a.out.as_path(), drawn.to_toml(&header).as_bytes())])?;
    println!("wrote {}", a.out.display());
    Ok(ExitCode::SUCCESS)
}

/// The value of row `r`'s key in `s` (NaN when the layer is missing).
fn value(s: &needle_codegen::tissue::Stack, r: &spread::Row) -> f64 {
    s.layers.get(r.layer).map_or(f64::NAN, |l| match r.key {
        "stiffness_scale" => l.stiffness_scale,
        "puncture_force_n" => l.puncture_force_n,
        "cutting_force_n" => l.cutting_force_n,
        _ => l.friction_coulomb_n_per_mm,
    })
}

/// A standard normal draw (Box-Muller on two uniform draws in (0, 1]).
fn standard_normal(rng: &mut ChaCha8Rng) -> f64 {
    use rand::Rng;
    let u1: f64 = 1.0 - rng.gen::<f64>();
    let u2: f64 = rng.gen::<f64>();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}
