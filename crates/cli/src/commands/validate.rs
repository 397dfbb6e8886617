//! `needle validate`: compare the set's model with the FE runs it was not fitted on.
use anyhow::{Context, Result};
use clap::Args;
use needle_fit::validate as val;
use needle_set::set_folder::SetFolder;
use std::path::PathBuf;
use std::process::ExitCode;

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

/// `needle validate --set DIR [--json]`: compare the set's model with every FE run it was
/// not fitted on; print the table (or JSON). Exit code 1 when a goal is missed.
///
/// # Errors
/// model.toml or the spec is missing or malformed, or a validation run is malformed.
pub fn run(a: ValidateArgs) -> Result<ExitCode> {
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
