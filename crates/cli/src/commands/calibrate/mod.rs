//! `needle calibrate`: a tissue stack fitted to a measured axial force (needle-calibrate),
//! written into the set's `tissue/` and checked against the curve.
pub mod figure;

use crate::compiled_set::check_compiled_set;
use anyhow::{Context, Result};
use clap::Args;
use needle_calibrate::{calibrate as run_calibration, events::EventRule, Options};
use std::path::PathBuf;
use std::process::ExitCode;

/// Fit a tissue stack to a measured axial force against needle position.
#[derive(Args)]
// The fields' doc comments are the --help text, written for the terminal: <set>, <pose>
// and [section] are placeholders and campaign.toml sections there, not HTML or links.
#[allow(rustdoc::invalid_html_tags, rustdoc::broken_intra_doc_links)]
pub struct CalibrateArgs {
    /// The set whose FE surrogate is scaled (the one compiled in).
    #[arg(long, default_value = "coeffs/default")]
    pub set: PathBuf,
    /// The measured curve: CSV with columns position_mm and force_n.
    #[arg(long)]
    pub curve: PathBuf,
    /// Name of the stack (the tissue file is <set>/tissue/<name>.toml).
    #[arg(long)]
    pub name: String,
    /// Diameter of the measured needle, mm (the FE needle is carried to it by geometric similarity).
    #[arg(long)]
    pub needle_diameter_mm: f64,
    /// Insertion speed of the measurement, mm/s.
    #[arg(long)]
    pub speed_mm_per_s: f64,
    /// Smallest drop that counts as a puncture, fraction of the peak force.
    #[arg(long, default_value_t = EventRule::default().drop_fraction)]
    pub drop_fraction: f64,
    /// Write the stack here instead of <set>/tissue/<name>.toml.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Write the figure here instead of <set>/figures/calibration-<name>.svg.
    #[arg(long)]
    pub figure: Option<PathBuf>,
}

/// Runs `needle calibrate`; exit 1 when a calibration goal is missed.
///
/// # Errors
/// The set is not the compiled-in one, the curve is refused, or the file cannot be written.
pub fn run(a: CalibrateArgs) -> Result<ExitCode> {
    check_compiled_set(&a.set)?;
    let rule = EventRule { drop_fraction: a.drop_fraction, ..EventRule::default() };
    let mu0 = needle_codegen::tissue::read_fe_shear_modulus(&a.set)?
        .with_context(|| format!("{}: no campaign.toml: the FE tissue's shear modulus sets the track stiffness", a.set.display()))?;
    let opts = Options {
        curve: &a.curve,
        name: a.name.clone(),
        needle_diameter_mm: a.needle_diameter_mm,
        speed_mm_per_s: a.speed_mm_per_s,
        rule,
        fe_shear_modulus_n_per_mm2: mu0,
    };
    let c = run_calibration(&opts)?;
    println!(
        "{} points, {} punctures; geometric similarity: measured needle {} mm / FE needle {} mm = {:.4} (lengths x {:.4}, forces x {:.4}; exact when the block scales too)",
        c.points.len(),
        c.events.len(),
        a.needle_diameter_mm,
        needle_haptics::insertion::FE_NEEDLE_DIAMETER_MM,
        c.similarity,
        c.similarity,
        c.similarity * c.similarity
    );
    println!("contact onset (depth 0) at {:.3} mm of needle position", c.fit.onset_mm);
    for (k, l) in c.fit.layers.iter().enumerate() {
        println!(
            "layer {k}: boundary at {:.3} mm depth, scale s = {:.4}, puncture {:.4} N, cutting {:.4} N, friction {:.5} N/mm, track {:.5} N/mm^2 (= 3 s mu0, assumed)",
            l.boundary_mm,
            l.scale,
            l.puncture_force_n,
            l.cutting_force_n,
            l.friction_n_per_mm,
            needle_calibrate::WINKLER_E_PER_MU * l.scale * mu0
        );
    }
    let all_met = print_checks(&c.checks);
    let out = a.out.unwrap_or_else(|| a.set.join(needle_codegen::tissue::TISSUE_DIR).join(format!("{}.toml", a.name)));
    if let Some(dir) = out.parent() {
        std::fs::create_dir_all(dir).with_context(|| format!("{}: cannot create", dir.display()))?;
    }
    let header = format!(
        "Tissue stack `{}`, written by `needle calibrate` (format: coeffs/README.md, \"Tissue stacks\").\nMeasured curve: {}; needle {} mm at {} mm/s.",
        a.name,
        a.curve.display(),
        a.needle_diameter_mm,
        a.speed_mm_per_s
    );
    needle_stdx::fs::write_atomic(&out, c.stack.to_toml(&header).as_bytes())?;
    println!("wrote {}", out.display());
    let figure = a.figure.unwrap_or_else(|| a.set.join("figures").join(format!("calibration-{}.svg", a.name)));
    if let Some(dir) = figure.parent() {
        std::fs::create_dir_all(dir).with_context(|| format!("{}: cannot create", dir.display()))?;
    }
    let svg = self::figure::svg(&c, &a.name, "measured")?;
    needle_stdx::fs::write_atomic(&figure, svg.as_bytes())?;
    println!("wrote {}", figure.display());
    println!("result: {}", if all_met { "every calibration goal met" } else { "FAIL (a goal is missed)" });
    Ok(if all_met { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

/// Prints each check (measured, model, error, goal, met) and says whether all are met.
pub fn print_checks(checks: &[needle_calibrate::replay::Check]) -> bool {
    let mut all_met = true;
    for check in checks {
        let met = check.met();
        all_met &= met;
        println!(
            "{:<58} measured {:>9.4}  model {:>9.4}  error {:>+8.3} {} (goal {} {})  {}",
            check.what,
            check.measured,
            check.model,
            check.error,
            check.unit,
            check.goal,
            check.unit,
            if met { "ok" } else { "MISSED" }
        );
    }
    all_met
}
