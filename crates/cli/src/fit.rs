//! `needle fit`, `needle validate`: fit the model, compare it with FE.
use anyhow::{Context, Result};
use clap::Args;
use needle_fe::results::write_all_atomic;
use needle_fit::{self as fit, validate as val, GOLDEN_FILE, GOLDEN_FIXED_FILE, GOLDEN_STIFFNESS_FILE, MODEL_FILE};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Arguments of `needle fit`.
#[derive(Args)]
pub struct FitArgs {
    /// The set folder (holds campaign.toml and fe/); model.toml, golden-f32.csv and
    /// golden-fixed.csv are written there.
    #[arg(long, value_name = "DIR")]
    pub set: PathBuf,
    /// Regenerate in memory and compare with the files in the set: exit 1 if they differ,
    /// write nothing.
    #[arg(long)]
    pub check: bool,
}

/// Arguments of `needle validate`.
#[derive(Args)]
pub struct ValidateArgs {
    /// The set folder (holds campaign.toml, fe/ and model.toml).
    #[arg(long, value_name = "DIR")]
    pub set: PathBuf,
    /// Print the report as JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// First differing line of two texts (1-based), if any.
fn first_difference(a: &str, b: &str) -> Option<usize> {
    let (mut la, mut lb) = (a.lines(), b.lines());
    let mut n = 0;
    loop {
        n += 1;
        match (la.next(), lb.next()) {
            (None, None) => return if a == b { None } else { Some(n) },
            (x, y) if x != y => return Some(n),
            _ => {}
        }
    }
}

fn check_file(path: &Path, want: &str) -> Result<bool> {
    let have = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) => {
            println!("{}: cannot read ({e}): regenerate with `needle fit`", path.display());
            return Ok(false);
        }
    };
    match first_difference(&have, want) {
        None => {
            println!("{}: up to date", path.display());
            Ok(true)
        }
        Some(line) => {
            println!("{}:{line}: differs from the regenerated file", path.display());
            Ok(false)
        }
    }
}

/// `needle fit --set DIR [--check]`: fit the set's FE sweeps and write `model.toml`,
/// `golden-f32.csv`, `golden-fixed.csv` and `golden-stiffness-f32.csv` all or nothing ([`write_all_atomic`]) (or, with `--check`, compare them). Exit code 0 on
/// success, 1 when `--check` finds a difference.
///
/// # Errors
/// A fitted run is missing (every missing pose is named) or malformed, the spec is
/// invalid, a fit is rank deficient, or a file cannot be written.
pub fn fit(a: FitArgs) -> Result<ExitCode> {
    let out = fit::fit_set(&a.set).with_context(|| format!("needle fit --set {}", a.set.display()))?;
    let model_path = a.set.join(MODEL_FILE);
    let golden_path = a.set.join(GOLDEN_FILE);
    let golden_fixed_path = a.set.join(GOLDEN_FIXED_FILE);
    let golden_stiffness_path = a.set.join(GOLDEN_STIFFNESS_FILE);
    if a.check {
        let ok_model = check_file(&model_path, &out.model_toml)?;
        let ok_golden = check_file(&golden_path, &out.golden_csv)?;
        let ok_fixed = check_file(&golden_fixed_path, &out.golden_fixed_csv)?;
        let ok_stiffness = check_file(&golden_stiffness_path, &out.golden_stiffness_csv)?;
        return Ok(if ok_model && ok_golden && ok_fixed && ok_stiffness { ExitCode::SUCCESS } else { ExitCode::from(1) });
    }
    write_all_atomic(&[
        (&model_path, out.model_toml.as_bytes()),
        (&golden_path, out.golden_csv.as_bytes()),
        (&golden_fixed_path, out.golden_fixed_csv.as_bytes()),
        (&golden_stiffness_path, out.golden_stiffness_csv.as_bytes()),
    ])?;
    print!("{}", fit::summary(&out.model));
    let coupled = fit::coupled_report::measure(&a.set, &out.model)
        .with_context(|| format!("needle fit --set {}: measuring the coupled form", a.set.display()))?;
    print!("{}", fit::coupled_report::to_table(&coupled));
    println!("wrote {} ({} bytes)", model_path.display(), out.model_toml.len());
    println!("wrote {} ({} poses)", golden_path.display(), out.golden_csv.lines().count() - 1);
    println!("wrote {} ({} poses)", golden_fixed_path.display(), out.golden_fixed_csv.lines().count() - 1);
    println!("wrote {} ({} poses)", golden_stiffness_path.display(), out.golden_stiffness_csv.lines().count() - 1);
    Ok(ExitCode::SUCCESS)
}

/// `needle validate --set DIR [--json]`: compare the set's model with every FE run it was
/// not fitted on; print the table (or JSON). Exit code 1 when a goal is missed.
///
/// # Errors
/// model.toml or the spec is missing or malformed, or a validation run is malformed.
pub fn validate(a: ValidateArgs) -> Result<ExitCode> {
    let report = val::validate(&a.set).with_context(|| format!("needle validate --set {}", a.set.display()))?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{}", val::to_table(&report));
    }
    Ok(if report.passed { ExitCode::SUCCESS } else { ExitCode::from(1) })
}
