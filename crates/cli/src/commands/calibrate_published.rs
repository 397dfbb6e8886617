//! `needle calibrate-published`: a tissue stack from a published piecewise force-depth
//! model (needle-calibrate's `published` rules), written into the set's `tissue/`, its
//! published curve sampled into a CSV, and the stack replayed against that curve.
use crate::compiled_set::check_compiled_set_except;
use crate::planned_outputs::{self, Planned};
use anyhow::{Context, Result};
use clap::Args;
use needle_calibrate::from_model::{calibrate_published as derive, ModelOptions};
use std::path::PathBuf;
use std::process::ExitCode;

/// Derive a tissue stack from a published model's force polynomials per layer.
#[derive(Args)]
// The fields' doc comments are the --help text, written for the terminal: <set>, <pose>
// and [section] are placeholders and campaign.toml sections there, not HTML or links.
#[allow(rustdoc::invalid_html_tags, rustdoc::broken_intra_doc_links)]
pub struct CalibratePublishedArgs {
    /// The set whose FE surrogate is scaled (the one compiled in).
    #[arg(long, default_value = "coeffs/default")]
    pub set: PathBuf,
    /// The published pieces: CSV with piece, layer, thickness_mm, c0_n .. c3_n_per_mm3.
    #[arg(long)]
    pub pieces: PathBuf,
    /// The citation of every layer: CSV with layer, source (written into the layer's source),
    /// optionally a layer's published relaxation function (prony_g_instantaneous,
    /// prony_tau_s, prony_source).
    #[arg(long)]
    pub layer_sources: PathBuf,
    /// Name of the stack (the tissue file is <set>/tissue/<name>.toml).
    #[arg(long)]
    pub name: String,
    /// The stack's one-line description.
    #[arg(long)]
    pub description: String,
    /// Diameter of the stack's needle, mm, 0.1 to 10 (the FE needle is carried to it by
    /// geometric similarity).
    #[arg(long, allow_negative_numbers = true)]
    pub needle_diameter_mm: f64,
    /// Speed of the replay along the published curve, mm/s, 0.01 to 1000 (for the
    /// comparison; with --with-prony also the speed at which a layer with terms is fitted).
    #[arg(long, allow_negative_numbers = true)]
    pub replay_speed_mm_per_s: f64,
    /// Write the layers' published Prony terms into the stack (its boundaries then relax:
    /// the library needs its `viscoelastic` feature for it); without, they are named in
    /// prony_source only and the stack is elastic.
    #[arg(long)]
    pub with_prony: bool,
    /// Write the sampled published curve (position_mm, force_n) here.
    #[arg(long)]
    pub sampled_out: PathBuf,
    /// Write the stack here instead of <set>/tissue/<name>.toml (the figure then goes beside
    /// it, x.toml -> x.svg, unless --figure).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Write the figure here instead of beside --out (x.svg), or without --out
    /// <set>/figures/calibration-<name>.svg.
    #[arg(long)]
    pub figure: Option<PathBuf>,
    /// Replace an existing stack, figure or sampled curve (without it, an existing one is
    /// refused before any work).
    #[arg(long)]
    pub force: bool,
}

/// Runs `needle calibrate-published`. The comparison with the published curve is printed,
/// not held to the calibration goals: exit 0 once the files are written. The options,
/// the name and the outputs are checked first; the three files (sampled curve, stack,
/// figure) are written last, all or nothing.
///
/// # Errors
/// The set is not the compiled-in one, an option is out of range, an output or a file
/// is refused, or the files cannot be written.
pub fn run(a: CalibratePublishedArgs) -> Result<ExitCode> {
    super::calibrate::check_name(&a.name)?;
    let checked = ModelOptions {
        pieces: &a.pieces,
        layer_sources: &a.layer_sources,
        name: a.name.clone(),
        description: a.description.clone(),
        needle_diameter_mm: a.needle_diameter_mm,
        replay_speed_mm_per_s: a.replay_speed_mm_per_s,
        with_prony: a.with_prony,
        fe_shear_modulus_n_per_mm2: 1.0,
    };
    needle_calibrate::from_model::check_model_options(&checked)?;
    check_compiled_set_except(&a.set, Some(&a.name))?;
    let mu0 = needle_codegen::tissue::read_fe_shear_modulus(&a.set)?
        .with_context(|| format!("{}: no campaign.toml: the FE tissue's shear modulus sets the track stiffness", a.set.display()))?;
    let opts = ModelOptions {
        pieces: &a.pieces,
        layer_sources: &a.layer_sources,
        name: a.name.clone(),
        description: a.description.clone(),
        needle_diameter_mm: a.needle_diameter_mm,
        replay_speed_mm_per_s: a.replay_speed_mm_per_s,
        with_prony: a.with_prony,
        fe_shear_modulus_n_per_mm2: mu0,
    };
    let (out, figure) = super::calibrate::output_paths(&a.set, &a.name, a.out.as_deref(), a.figure.as_deref());
    let planned = [
        Planned { option: "--sampled-out", path: &a.sampled_out },
        Planned { option: "--out", path: &out },
        Planned { option: "--figure", path: &figure },
    ];
    planned_outputs::check(&planned, Some(&a.set), &[("--pieces", &a.pieces), ("--layer-sources", &a.layer_sources)], a.force)?;
    let c = derive(&opts)?;
    println!(
        "{} published pieces sampled every {} mm ({} points); geometric similarity: needle {} mm / FE needle {} mm = {:.4}",
        needle_calibrate::published::read_pieces(&a.pieces)?.len(),
        needle_calibrate::published::STEP_MM,
        c.points.len(),
        a.needle_diameter_mm,
        needle_haptics::insertion::FE_NEEDLE_DIAMETER_MM,
        c.similarity
    );
    for (l, f) in c.stack.layers.iter().zip(&c.fit.layers) {
        println!(
            "{:<22} top {:>6.2} mm, thickness {:>6.2} mm, s = {:.4}, puncture {:.4} N, cutting {:.4} N, friction {:.5} N/mm, track {:.5} N/mm^2",
            l.name, f.boundary_mm, l.thickness_mm, l.stiffness_scale, l.puncture_force_n, l.cutting_force_n, l.friction_coulomb_n_per_mm, l.track_stiffness_n_per_mm2
        );
    }
    super::calibrate::print_checks(&c.checks);
    let mut sampled = String::from("position_mm,force_n\n");
    for p in &c.points {
        sampled.push_str(&format!("{},{}\n", p.position_mm, p.force_n));
    }
    let header = format!(
        "Tissue stack `{}`, written by `needle calibrate-published` (format: coeffs/README.md, \"Tissue stacks\"; rules: crates/calibrate/src/published.rs).\nPublished model: {} (provenance: its folder's README.md); citations per layer: {}; needle {} mm.",
        a.name,
        a.pieces.display(),
        a.layer_sources.display(),
        a.needle_diameter_mm
    );
    let stack = c.stack.to_toml(&header);
    let svg = super::calibrate::figure::svg(&c, &a.name, "published model (sampled)")?;
    needle_stdx::fs::write_all_atomic(&[(&a.sampled_out, sampled.as_bytes()), (&out, stack.as_bytes()), (&figure, svg.as_bytes())])?;
    for path in [&a.sampled_out, &out, &figure] {
        println!("wrote {}", path.display());
    }
    println!("result: stack derived by the published-model rules (the comparison above is reported, not a goal)");
    Ok(ExitCode::SUCCESS)
}
