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
    /// Measured curves (position_mm,force_n) or whole trials (time_s,position_mm,force_n)
    /// to place among the material family's members: also draws family-measured.svg,
    /// each curve's local power-law exponent before its first puncture from the contact
    /// the calibration fits (the set must be the compiled-in one).
    #[arg(long, num_args = 1.., value_name = "CSV", requires = "needle_diameter_mm")]
    pub measured: Vec<PathBuf>,
    /// Diameter of the measured needle, mm (with --measured): the depths are carried to
    /// the FE needle by geometric similarity.
    #[arg(long, allow_negative_numbers = true)]
    pub needle_diameter_mm: Option<f64>,
}

/// Run `needle plot`.
///
/// # Errors
/// The set cannot be read or a figure cannot be written.
pub fn run(a: PlotArgs) -> Result<ExitCode> {
    let set = needle_set::set_folder::SetFolder::open(&a.set).with_context(|| format!("needle plot --set {}", a.set.display()))?;
    let mut figures = needle_plot::render_set(&set).with_context(|| format!("needle plot --set {}", a.set.display()))?;
    if !a.measured.is_empty() {
        crate::compiled_set::check_compiled_set(&a.set)?;
        let diameter = a.needle_diameter_mm.unwrap_or(f64::NAN);
        needle_calibrate::limits::check_range(
            "--needle-diameter-mm",
            diameter,
            &needle_calibrate::limits::NEEDLE_DIAMETER_MM,
            "mm",
            "the needles there are",
        )?;
        let shapes: Vec<_> = a.measured.iter().map(|p| measured_shape(p, diameter)).collect::<Result<_>>()?;
        match needle_plot::render_family_measured(&set, &shapes)? {
            Some(f) => figures.push(f),
            None => anyhow::bail!("--measured: the set {} has no material family runs (fe/family/) to place them among", a.set.display()),
        }
    }
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

/// A measured curve or trial before its first puncture, from the contact the
/// calibration fits ([`needle_calibrate::fit::fit`]), depths at the FE needle.
///
/// # Errors
/// The file is refused by its reader (file:line), or it has no puncture.
fn measured_shape(path: &std::path::Path, diameter_mm: f64) -> Result<needle_plot::family::MeasuredShape> {
    use needle_calibrate::{events, fit, measured, whole::trials};
    use needle_haptics::insertion;
    let lambda = diameter_mm / f64::from(insertion::FE_NEEDLE_DIAMETER_MM);
    let u = |d: f64| f64::from(insertion::deflection(&needle_haptics::Pose::default(), d as f32, 1.0, lambda as f32).wrench.fy_n);
    let rule = events::EventRule::default();
    let header = std::fs::read_to_string(path).with_context(|| format!("--measured {}: cannot read", path.display()))?;
    let (points, events, onset) = if header.lines().next().is_some_and(|l| l.contains("time_s")) {
        let t = trials::prepare(path, rule, &u, lambda, true)?;
        let onset = t.onset_mm();
        (t.points, t.events, onset)
    } else {
        let points = measured::read_curve(path)?;
        let events = events::punctures(&points, rule);
        let onset = fit::fit(&points, &events, &u, lambda).onset_mm;
        (points, events, onset)
    };
    let Some(first) = events.first() else {
        anyhow::bail!("--measured {}: no puncture found: the shape before a puncture needs one", path.display())
    };
    let depth_force = points
        .iter()
        .take(first.peak + 1)
        .filter(|p| p.position_mm > onset)
        .map(|p| ((p.position_mm - onset) / lambda, p.force_n))
        .collect();
    // the file and its folder (a digitised curve is often `<source>/position_force.csv`)
    let tail: Vec<String> = path.iter().rev().take(2).map(|c| c.to_string_lossy().into_owned()).collect();
    let label = tail.into_iter().rev().collect::<Vec<_>>().join("/");
    Ok(needle_plot::family::MeasuredShape { label, depth_force })
}
