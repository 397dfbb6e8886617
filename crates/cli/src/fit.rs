//! `needle fit`, `needle validate`: fit the model, compare it with FE.
use anyhow::{Context, Result};
use clap::Args;
use needle_fit::{self as fit, validate as val};
use needle_set::set_folder::SetFolder;
use needle_stdx::fs::write_all_atomic;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Arguments of `needle fit`.
#[derive(Args)]
pub struct FitArgs {
    /// The set folder (holds campaign.toml and fe/); model.toml and the golden vectors
    /// (golden-f32.csv, golden-fixed.csv, golden-stiffness-f32.csv,
    /// golden-stiffness-fixed.csv) are written there.
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
    /// Depth degree of each run's floor (the smallest error any model that is a
    /// polynomial of this degree in depth at a pose could have on the run), 1 to 10;
    /// default: the contract's degree. Goals and errors do not depend on it.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u8).range(1..=10))]
    pub floor_degree: Option<u8>,
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

/// `needle fit --set DIR [--check]`: fit the set's model in its form and write `model.toml` and
/// the golden vectors ([`fit::FitOutput::files`]) all or nothing ([`write_all_atomic`])
/// (or, with `--check`, compare them). Exit code 0 on success, 1 when `--check` finds a
/// difference.
///
/// # Errors
/// A fitted run is missing (every missing pose is named) or malformed, the spec is
/// invalid, a fit is rank deficient, or a file cannot be written.
pub fn fit(a: FitArgs) -> Result<ExitCode> {
    let set = SetFolder::open(&a.set).with_context(|| format!("needle fit --set {}", a.set.display()))?;
    let out = fit::fit_set(&set).with_context(|| format!("needle fit --set {}", a.set.display()))?;
    let files: Vec<(PathBuf, &str)> = out.files().iter().map(|(name, text)| (a.set.join(name), *text)).collect();
    if a.check {
        let mut same = true;
        for (path, text) in &files {
            same &= check_file(path, text)?;
        }
        return Ok(if same { ExitCode::SUCCESS } else { ExitCode::from(1) });
    }
    let writes: Vec<(&Path, &[u8])> = files.iter().map(|(path, text)| (path.as_path(), text.as_bytes())).collect();
    write_all_atomic(&writes)?;
    print!("{}", fit::summary(&out.model));
    let coupled =
        fit::coupled_report::measure(&set).with_context(|| format!("needle fit --set {}: measuring the coupled form", a.set.display()))?;
    print!("{}", fit::coupled_report::to_table(&coupled));
    print!("{}", fit::unsolved::summary(&out.unsolved));
    print!("{}", fit::depth_extension::law_summary(&out.depth_law));
    for (path, text) in &files {
        if path.extension().is_some_and(|e| e == "csv") {
            println!("wrote {} ({} poses)", path.display(), text.lines().count().saturating_sub(1));
        } else {
            println!("wrote {} ({} bytes)", path.display(), text.len());
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// `needle validate --set DIR [--json]`: compare the set's model with every FE run it was
/// not fitted on; print the table (or JSON). Exit code 1 when a goal is missed.
///
/// # Errors
/// model.toml or the spec is missing or malformed, or a validation run is malformed.
pub fn validate(a: ValidateArgs) -> Result<ExitCode> {
    let floor_degree = a.floor_degree.map_or(needle_contract::DEGREE, usize::from);
    let report = SetFolder::open(&a.set)
        .and_then(|set| val::validate(&set, floor_degree))
        .with_context(|| format!("needle validate --set {}", a.set.display()))?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{}", val::to_table(&report));
    }
    Ok(if report.passed { ExitCode::SUCCESS } else { ExitCode::from(1) })
}
