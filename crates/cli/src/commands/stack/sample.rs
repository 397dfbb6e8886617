//! `needle stack sample`: a tissue drawn within the spread of a stack fitted on several
//! trials ([`needle_calibrate::sample`]), written as a tissue file.
use crate::planned_outputs::{self, Planned};
use anyhow::{Context, Result};
use clap::Args;
use needle_calibrate::{sample, spread};
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
    let d = sample::sample_file(&a.stack, Some(&spread_path), &name, a.seed).with_context(|| format!("--stack {}", a.stack.display()))?;
    for r in &d.rows {
        let (old, new) = (sample::value(&d.stack, r), sample::value(&d.drawn, r));
        println!("layer {} {}: {old:.6} -> {new:.6} (sd {:.3e} over {} trials)", r.layer, r.key, r.sd, r.trials);
    }
    needle_stdx::fs::write_all_atomic(&[(a.out.as_path(), d.to_toml(&a.stack).as_bytes())])?;
    println!("wrote {}", a.out.display());
    Ok(ExitCode::SUCCESS)
}
