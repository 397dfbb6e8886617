//! `needle calibrate`: a tissue stack fitted to a measured axial force (needle-calibrate),
//! written into the set's `tissue/` and checked against the curve.
pub mod figure;
pub mod json;
pub mod trials;
pub mod trials_figure;

use crate::compiled_set::check_compiled_set_except;
use crate::planned_outputs::{self, Planned};
use anyhow::{Context, Result};
use clap::Args;
use needle_calibrate::{events::EventRule, Options};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};

/// Fit a tissue stack to a measured axial force against needle position.
#[derive(Args)]
// The fields' doc comments are the --help text, written for the terminal: <set>, <pose>
// and [section] are placeholders and campaign.toml sections there, not HTML or links.
#[allow(rustdoc::invalid_html_tags, rustdoc::broken_intra_doc_links)]
pub struct CalibrateArgs {
    /// The set whose FE surrogate is scaled (the one compiled in).
    #[arg(long, default_value = "coeffs/default")]
    pub set: PathBuf,
    /// The measured curve: CSV with columns position_mm and force_n, in the order of the
    /// insertion (at most 100,000 points and 16 MiB; positions spanning 1 to 500 mm;
    /// |force| <= 500 N).
    #[arg(long, required_unless_present = "trials", conflicts_with = "trials")]
    pub curve: Option<PathBuf>,
    /// Whole measured trials of one tissue sample and one needle, calibrated together:
    /// CSVs with columns time_s, position_mm (stage travel) and force_n; insertion, hold
    /// and withdrawal are found from the position against time, the contact by the fit;
    /// any mix of speeds and repeats.
    #[arg(long, num_args = 1.., value_name = "TRIAL")]
    pub trials: Vec<PathBuf>,
    /// Name of the stack (the tissue file is <set>/tissue/<name>.toml): lower-case ASCII
    /// letters, digits and '_', starting with a letter.
    #[arg(long)]
    pub name: String,
    /// Diameter of the measured needle, mm, 0.1 to 10 (the FE needle is carried to it by
    /// geometric similarity); with --trials one value, or one per trial (all equal).
    #[arg(long, allow_negative_numbers = true, num_args = 1.., required = true)]
    pub needle_diameter_mm: Vec<f64>,
    /// Insertion speed of the measurement, mm/s, 0.01 to 1000 (--curve only: a trial's
    /// speeds are measured from its time).
    #[arg(long, allow_negative_numbers = true, required_unless_present = "trials", conflicts_with = "trials")]
    pub speed_mm_per_s: Option<f64>,
    /// Smallest drop that counts as a puncture, fraction of the peak force, 0.001 to 0.999.
    #[arg(long, default_value_t = EventRule::default().drop_fraction, allow_negative_numbers = true)]
    pub drop_fraction: f64,
    /// Write the stack here instead of <set>/tissue/<name>.toml (the figure then goes beside
    /// it, x.toml -> x.svg, unless --figure).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Write the figure here instead of beside --out (x.svg), or without --out
    /// <set>/figures/calibration-<name>.svg (--curve:
    /// the curve, the model and the residual against position, and before the first
    /// puncture against depth; --trials: per trial the measured and the model force
    /// against time over insertion, hold and withdrawal, the punctures, the residual).
    #[arg(long)]
    pub figure: Option<PathBuf>,
    /// Replace an existing stack or figure (without it, an existing one is refused before
    /// the fit).
    #[arg(long)]
    pub force: bool,
    /// Write the stack and figure even when a calibration goal is missed (exit 1 still);
    /// without it, a missed goal writes nothing.
    #[arg(long)]
    pub write_on_miss: bool,
    /// Print one JSON document instead of the text: the fitted values (with --trials their
    /// uncertainties), the values on their range's edge (warnings), each check, the model
    /// force per measured row (of each trial).
    #[arg(long)]
    pub json: bool,
}

/// Where a calibration of stack `name` writes its stack and its figure: the stack to
/// `out`, else the set's `<set>/tissue/<name>.toml`; the figure to `figure`, else beside
/// an `out` stack (`x.toml` -> `x.svg`: a stack sent out of the set leaves the set
/// unchanged), else the set's `<set>/figures/calibration-<name>.svg`.
#[must_use]
pub fn output_paths(set: &Path, name: &str, out: Option<&Path>, figure: Option<&Path>) -> (PathBuf, PathBuf) {
    let stack = out.map_or_else(|| set.join(needle_codegen::tissue::TISSUE_DIR).join(format!("{name}.toml")), Path::to_path_buf);
    let svg = match (figure, out) {
        (Some(f), _) => f.to_path_buf(),
        (None, Some(o)) => o.with_extension("svg"),
        (None, None) => set.join("figures").join(format!("calibration-{name}.svg")),
    };
    (stack, svg)
}

/// Runs `needle calibrate`: the options, the name and the outputs are checked first (no
/// fit for a run that cannot end in a file), the fit reports its progress on stderr,
/// the stack and figure are written last, together or not at all; exit 1 when a
/// calibration goal is missed (nothing written, unless `--write-on-miss`).
///
/// # Errors
/// The set is not the compiled-in one, an option is out of range, an output is refused,
/// the curve is refused, or the files cannot be written.
pub fn run(a: CalibrateArgs) -> Result<ExitCode> {
    let (Some(curve), Some(speed)) = (a.curve.clone(), a.speed_mm_per_s) else { return trials::run_trials(&a) };
    let [needle_diameter_mm] = a.needle_diameter_mm[..] else {
        anyhow::bail!("--needle-diameter-mm: {} values: --curve is one measurement of one needle (one value)", a.needle_diameter_mm.len())
    };
    let rule = EventRule { drop_fraction: a.drop_fraction, ..EventRule::default() };
    let mut opts = Options {
        curve: &curve,
        name: a.name.clone(),
        needle_diameter_mm,
        speed_mm_per_s: speed,
        rule,
        // checked below, once the set is
        fe_shear_modulus_n_per_mm2: 1.0,
    };
    // the cheap checks first: options, name, set, outputs
    needle_calibrate::check_options(&opts)?;
    check_name(&a.name)?;
    check_compiled_set_except(&a.set, Some(&a.name))?;
    opts.fe_shear_modulus_n_per_mm2 = needle_codegen::tissue::read_fe_shear_modulus(&a.set)?
        .with_context(|| format!("{}: no campaign.toml: the FE tissue's shear modulus sets the track stiffness", a.set.display()))?;
    let mu0 = opts.fe_shear_modulus_n_per_mm2;
    let (out, figure) = output_paths(&a.set, &a.name, a.out.as_deref(), a.figure.as_deref());
    let planned = [Planned { option: "--out", path: &out }, Planned { option: "--figure", path: &figure }];
    planned_outputs::check(&planned, Some(&a.set), &[("--curve", &curve)], a.force)?;
    let points = needle_calibrate::measured::read_curve(&curve)?;
    let c = needle_calibrate::calibrate_points_with_progress(&opts, points, &mut progress_on_stderr())?;
    let all_met = c.checks.iter().all(needle_calibrate::replay::Check::met);
    if a.json {
        println!("{}", serde_json::to_string_pretty(&self::json::curve_calibration(&c))?);
        for e in &c.fit.edges {
            eprintln!("warning: {e}");
        }
    } else {
        print_fit(&c, needle_diameter_mm, mu0);
        print_checks(&c.checks);
    }
    let say = |s: String| if a.json { eprintln!("{s}") } else { println!("{s}") };
    if !all_met && !a.write_on_miss {
        say("result: FAIL (a goal is missed): nothing written (--write-on-miss writes the stack and figure anyway)".into());
        return Ok(ExitCode::from(1));
    }
    let header = format!(
        "Tissue stack `{}`, written by `needle calibrate` (format: coeffs/README.md, \"Tissue stacks\").\nMeasured curve: {}; needle {} mm at {} mm/s.",
        a.name,
        curve.display(),
        needle_diameter_mm,
        speed
    );
    let stack = c.stack.to_toml(&header);
    let svg = self::figure::svg(&c, &a.name, "measured")?;
    needle_stdx::fs::write_all_atomic(&[(&out, stack.as_bytes()), (&figure, svg.as_bytes())])?;
    say(format!("wrote {}", out.display()));
    say(format!("wrote {}", figure.display()));
    say(format!(
        "result: {}",
        if all_met { "every calibration goal met" } else { "FAIL (a goal is missed; written with --write-on-miss)" }
    ));
    Ok(if all_met { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

/// Prints the fitted values of a `--curve` calibration: the similarity, the contact,
/// each layer, the first boundary's shape and the values on their range's edge.
fn print_fit(c: &needle_calibrate::Calibration, needle_diameter_mm: f64, mu0: f64) {
    println!(
        "{} points, {} punctures; geometric similarity: measured needle {} mm / FE needle {} mm = {:.4} (lengths x {:.4}, forces x {:.4}; exact when the block scales too)",
        c.points.len(),
        c.events.len(),
        needle_diameter_mm,
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
    if let Some(l) = c.fit.layers.first() {
        println!(
            "layer 0 shape: family member w = {:.4} (fitted range {}), softening fraction {:.4}{}",
            l.family_weight,
            l.family_weight_range.map_or("not fitted".into(), |[lo, hi]| format!("{lo:.4} to {hi:.4}")),
            l.softening.fraction,
            if l.softening.fraction > 0.0 {
                format!(" from {:.2} of the puncture's elastic force", l.softening.onset_ratio)
            } else {
                String::new()
            }
        );
    }
    for e in &c.fit.edges {
        println!("warning: {e}");
    }
}

/// Refuses a `--name` that cannot name a stack, before any work.
///
/// # Errors
/// The name breaks [`needle_codegen::tissue::STACK_NAME_RULE`].
pub fn check_name(name: &str) -> Result<()> {
    if !needle_codegen::tissue::is_stack_name(name) {
        anyhow::bail!("--name {name:?}: {}", needle_codegen::tissue::STACK_NAME_RULE);
    }
    Ok(())
}

/// A progress callback for the fit's scans: a line on stderr at most every
/// [`PROGRESS_EVERY`], from the first [`PROGRESS_EVERY`] on (a short fit prints nothing).
pub fn progress_on_stderr() -> impl FnMut(usize, usize) {
    let start = Instant::now();
    let mut last = start;
    move |done, total| {
        let now = Instant::now();
        if now.duration_since(last) >= PROGRESS_EVERY {
            last = now;
            eprintln!(
                "fitting: {done} of {total} candidate depths scanned ({:.0} %, {:.0} s)",
                100.0 * done as f64 / total.max(1) as f64,
                now.duration_since(start).as_secs_f64()
            );
        }
    }
}

/// How often a long fit reports its progress.
pub const PROGRESS_EVERY: Duration = Duration::from_secs(1);

/// Prints each check (measured, model, error, goal, met) and says whether all are met.
pub fn print_checks(checks: &[needle_calibrate::replay::Check]) -> bool {
    let mut all_met = true;
    for check in checks {
        let met = check.met();
        all_met &= met;
        if check.model.is_nan() {
            // the model has no such event (a puncture it never made): no number to compare
            println!(
                "{:<58} measured {:>9.4}  model: none (the model does not puncture here)  (goal {} {})  MISSED",
                check.what, check.measured, check.goal, check.unit
            );
            continue;
        }
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
