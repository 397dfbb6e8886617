//! `needle fit`: fit the set's model in its form, write model.toml and the golden vectors.
use anyhow::{Context, Result};
use clap::Args;
use needle_fit::{self as fit};
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
pub fn run(a: FitArgs) -> Result<ExitCode> {
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
    match &out.family {
        fit::family::FamilyFit::None => {}
        fit::family::FamilyFit::Pending(why) => println!("{why}"),
        fit::family::FamilyFit::Law(law) => {
            print!("{}", fit::family::summary(law));
            print!("{}", fit::family_poses::summary(&out.family_poses));
        }
    }
    for (path, text) in &files {
        if path.extension().is_some_and(|e| e == "csv") {
            println!("wrote {} ({} poses)", path.display(), text.lines().count().saturating_sub(1));
        } else {
            println!("wrote {} ({} bytes)", path.display(), text.len());
        }
    }
    Ok(ExitCode::SUCCESS)
}
