//! `needle insertion-paths`: the golden insertion paths (`examples/common/insertion_paths.rs`,
//! the ones the firmware, the C API and wasm replay) written as scripts for `needle eval
//! --poses FILE --insertion STACK`: one CSV per path, `time_s` and the five pose columns,
//! one row per 1 kHz tick, the depths scaled for the stack as the golden tests scale them.
//! Other programs (the CHAI3D binding's test) replay the same ticks from these files.
#[path = "../../../../examples/common/insertion_paths.rs"]
mod paths;

use crate::planned_outputs::Planned;
use anyhow::Result;
use clap::Args;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

/// Write the golden insertion paths as `needle eval --insertion` scripts.
#[derive(Args)]
// The fields' doc comments are the --help text, written for the terminal: <set>, <pose>
// and [section] are placeholders and campaign.toml sections there, not HTML or links.
#[allow(rustdoc::invalid_html_tags, rustdoc::broken_intra_doc_links)]
pub struct InsertionPathsArgs {
    /// The tissue stack whose depth the paths are scaled to: a compiled-in name (e.g. liver)
    /// or a tissue file (.toml, checked as the build checks a compiled-in one).
    #[arg(long)]
    pub stack: String,
    /// Folder for the scripts: <stack>-path<i>.csv, i = 0..4.
    #[arg(long)]
    pub out_dir: PathBuf,
}

/// The tick period of the paths, s (1 kHz).
pub const PERIOD_S: f64 = 0.001;

/// The script of path `i` for `stack`: `time_s,x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm`,
/// the f32 values in their shortest exact text.
#[must_use]
pub fn script(path: &[paths::Waypoint], stack: &needle_haptics::insertion::Stack<'_>) -> String {
    let mut s = String::from("time_s,x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm\n");
    paths::for_each_tick(path, paths::depth_scale(stack), |tick, p| {
        let _ = writeln!(s, "{:?},{:?},{:?},{:?},{:?},{:?}", f64::from(tick) * PERIOD_S, p[0], p[1], p[2], p[3], p[4]);
    });
    s
}

/// Runs `needle insertion-paths`: the scripts are written all or nothing (an existing
/// script is replaced: they are the paths' own text).
///
/// # Errors
/// No such stack; the folder or a file cannot be written (then none is).
pub fn run(a: InsertionPathsArgs) -> Result<ExitCode> {
    let owned = needle_calibrate::runtime_stack::OwnedStack::resolve("--stack", &a.stack)?;
    let stack = &owned.as_stack();
    let files: Vec<(PathBuf, String)> = paths::PATHS
        .iter()
        .enumerate()
        .map(|(i, path)| (a.out_dir.join(format!("{}-path{i}.csv", stack.name)), script(path, stack)))
        .collect();
    let planned: Vec<Planned<'_>> = files.iter().map(|(p, _)| Planned { option: "--out-dir", path: p }).collect();
    crate::planned_outputs::check(&planned, None, &[], true)?;
    let refs: Vec<(&std::path::Path, &[u8])> = files.iter().map(|(p, t)| (p.as_path(), t.as_bytes())).collect();
    needle_stdx::fs::write_all_atomic(&refs)?;
    for (p, _) in &files {
        println!("wrote {}", p.display());
    }
    Ok(ExitCode::SUCCESS)
}
