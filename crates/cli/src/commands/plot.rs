//! `needle plot`: write (or check) the figures of a set.

use anyhow::{Context, Result};
use clap::Args;
use needle_stdx::fs::write_all_atomic;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `needle plot`.
#[derive(Args, Debug)]
// The fields' doc comments are the --help text, written for the terminal: <set>, <pose>
// and [section] are placeholders and campaign.toml sections there, not HTML or links.
#[allow(rustdoc::invalid_html_tags, rustdoc::broken_intra_doc_links)]
pub struct PlotArgs {
    /// Set folder holding campaign.toml, fe/ and model.toml, e.g. coeffs/default.
    #[arg(long, value_name = "DIR")]
    pub set: PathBuf,
    /// Output folder; default: <set>/figures.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Compare with the figures in the output folder instead of writing; exit 1 when one
    /// is missing or differs (stale).
    #[arg(long)]
    pub check: bool,
}

/// Run `needle plot`.
///
/// # Errors
/// The set cannot be read or a figure cannot be written.
pub fn run(a: PlotArgs) -> Result<ExitCode> {
    let figures = needle_set::set_folder::SetFolder::open(&a.set)
        .and_then(|set| needle_plot::render_set(&set))
        .with_context(|| format!("needle plot --set {}", a.set.display()))?;
    let out = a.out.unwrap_or_else(|| a.set.join("figures"));
    if a.check {
        let mut ok = true;
        for (file, svg) in &figures {
            let path = out.join(file);
            match std::fs::read_to_string(&path) {
                Ok(old) if old == *svg => println!("{}: up to date", path.display()),
                Ok(_) => {
                    println!("{}: stale (differs from a fresh rendering; run `needle plot --set {}`)", path.display(), a.set.display());
                    ok = false;
                }
                Err(e) => {
                    println!("{}: missing ({e})", path.display());
                    ok = false;
                }
            }
        }
        return Ok(if ok { ExitCode::SUCCESS } else { ExitCode::from(1) });
    }
    std::fs::create_dir_all(&out).with_context(|| format!("{}: cannot create", out.display()))?;
    // all or none: a failure (a full disk) leaves the old figures as they were
    let paths: Vec<std::path::PathBuf> = figures.iter().map(|(file, _)| out.join(file)).collect();
    let files: Vec<(&std::path::Path, &[u8])> = paths.iter().zip(&figures).map(|(p, (_, svg))| (p.as_path(), svg.as_bytes())).collect();
    write_all_atomic(&files)?;
    for (path, (_, svg)) in paths.iter().zip(&figures) {
        println!("wrote {} ({} bytes)", path.display(), svg.len());
    }
    Ok(ExitCode::SUCCESS)
}
