//! `needle calibrate`: a tissue stack fitted to a measured axial force against needle
//! position, with the library's own FE surrogate and insertion model.
//!
//! 1. [`measured::read_curve`] reads the curve (`position_mm`, `force_n`);
//! 2. [`events::punctures`] finds the punctures (a peak, then a drop);
//! 3. [`fit::fit`] fits the contact onset and, per layer, the boundary's stiffness scale
//!    against the surrogate's curve (the scaling law: one linear least-squares
//!    coefficient), the puncture force, cutting and friction;
//! 4. [`replay::replay`] runs the fitted stack through
//!    [`Insertion`](needle_haptics::insertion::Insertion) along the measured insertion,
//!    and [`replay::checks`] holds it against the curve.
//!
//! What a constant-speed axial curve cannot tell apart, and is therefore assumed (stated
//! in the tissue file's `source` and by the command): the friction is all Coulomb at the
//! measured speed (static level = Coulomb level, no viscous term), the stick band is
//! [`STICK_BAND_MM_PER_S`]; the track's lateral stiffness per mm of shaft is Winkler's
//! subgrade modulus of a beam on an elastic solid, `k ≈ E` (Vesic 1961, "Bending of
//! beams resting on isotropic elastic solid", J. Eng. Mech. Div. ASCE 87(2)), with the
//! layer's Young's modulus `E = 3 s mu0` (incompressible; `mu0` of the set's FE tissue,
//! scaled by the layer's `s`): [`WINKLER_E_PER_MU`].
#![forbid(unsafe_code)]
#![deny(missing_docs)]

pub mod edges;
pub mod events;
pub mod fe_loop;
pub mod fit;
pub mod from_model;

pub mod limits;
mod lsq;
pub mod measured;
pub mod published;
pub mod ramp;
pub mod replay;
pub mod runtime_stack;
pub mod sample;
pub mod shape;
pub mod spread;
pub mod trial;
pub mod trial_replay;
pub mod trial_screen;
pub mod whole;

/// Issue 65's checks of a whole trial (`whole::goals`, re-exported where the command and
/// the tests name it).
pub use whole::goals;

use anyhow::{bail, Result};
use needle_codegen::tissue as file;
use needle_haptics::insertion::{self, Karnopp};
use needle_haptics::viscoelastic::{PronyTerm, PronyTerms};
use needle_haptics::Pose;
use std::path::Path;

/// The stick band written into a calibrated stack, mm/s: below the measured speed, so
/// the rendered friction at that speed is the fitted level (an assumption: one speed
/// cannot show the band).
pub const STICK_BAND_MM_PER_S: f64 = 1.0;

/// Young's modulus over shear modulus of an incompressible solid (`E = 2 (1 + ν) μ`,
/// `ν = 1/2`), the factor of the track stiffness `k = E = 3 s mu0`.
pub const WINKLER_E_PER_MU: f64 = 3.0;

/// What to calibrate.
#[derive(Debug, Clone)]
pub struct Options<'a> {
    /// The measured curve.
    pub curve: &'a Path,
    /// The stack's name (the tissue file's stem).
    pub name: String,
    /// Diameter of the measured needle, mm.
    pub needle_diameter_mm: f64,
    /// Insertion speed of the measurement, mm/s.
    pub speed_mm_per_s: f64,
    /// How punctures are found.
    pub rule: events::EventRule,
    /// The FE tissue's initial shear modulus `mu0`, N/mm² (`campaign.toml`), for the
    /// track stiffness.
    pub fe_shear_modulus_n_per_mm2: f64,
}

/// The result: the stack, its replay and the checks.
#[derive(Debug, Clone)]
pub struct Calibration {
    /// The measured points.
    pub points: Vec<measured::Point>,
    /// The punctures found in them.
    pub events: Vec<events::Puncture>,
    /// The fitted values.
    pub fit: fit::Fit,
    /// The tissue file's contents.
    pub stack: file::Stack,
    /// The stack run through the insertion model.
    pub replay: replay::Replay,
    /// Model against measurement.
    pub checks: Vec<replay::Check>,
    /// Geometric similarity factor, measured needle over the FE needle.
    pub similarity: f64,
}

/// Calibrates a stack on the curve of `opts`.
///
/// # Errors
/// The curve cannot be read (with its line) or has numbers no insertion has, it shows
/// no contact or no puncture, an option is outside its range ([`check_options`]), or the
/// library has no fitted model.
pub fn calibrate(opts: &Options<'_>) -> Result<Calibration> {
    check_options(opts)?;
    calibrate_points(opts, measured::read_curve(opts.curve)?)
}

/// Calibrates a stack on `points` (from [`measured::read_curve`] or
/// [`measured::from_columns`]); `opts.curve` only names them in messages and in the
/// tissue file's `description` and `source`.
///
/// # Errors
/// As [`calibrate`], but for reading the curve.
pub fn calibrate_points(opts: &Options<'_>, points: Vec<measured::Point>) -> Result<Calibration> {
    calibrate_points_with_progress(opts, points, &mut |_, _| {})
}

/// [`calibrate_points`], telling `progress` how far the fit's scans are
/// ([`fit::Progress`]).
///
/// # Errors
/// As [`calibrate_points`].
pub fn calibrate_points_with_progress(
    opts: &Options<'_>,
    points: Vec<measured::Point>,
    progress: fit::Progress<'_>,
) -> Result<Calibration> {
    check_options(opts)?;
    measured::check_units(&points, None)?;
    let (start, end) = points.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p.position_mm), hi.max(p.position_mm)));
    limits::check_replay(
        end - start,
        opts.speed_mm_per_s,
        f64::from(insertion::InsertionConfig::DEFAULT_1KHZ.period_s),
        "--speed-mm-per-s",
    )?;
    let events = events::punctures(&points, opts.rule);
    if events.is_empty() {
        bail!(
            "{}: no puncture found (no drop of {:.0} % of a peak within {} mm that stays below it for {} mm): a curve without a puncture cannot calibrate a stack",
            opts.curve.display(),
            100.0 * opts.rule.drop_fraction,
            opts.rule.drop_within_mm,
            opts.rule.stay_below_mm
        );
    }
    let peak = events.first().and_then(|e| points.get(e.peak)).map_or(0.0, |p| p.force_n);
    if peak <= 0.0 {
        bail!("{}: no contact: the force never rises above zero before the first drop", opts.curve.display());
    }
    let similarity = opts.needle_diameter_mm / f64::from(insertion::FE_NEEDLE_DIAMETER_MM);
    let surrogate = |depth_mm: f64| f64::from(insertion::deflection(&Pose::default(), depth_mm as f32, 1.0, similarity as f32).wrench.fy_n);
    let fit = fit::fit_with_progress(&points, &events, &surrogate, similarity, progress);
    if fit.layers.len() > file::MAX_LAYERS {
        bail!(
            "{}: {} punctures would make {} layers; a stack has at most {} (raise --drop-fraction to count only the larger drops)",
            opts.curve.display(),
            events.len(),
            fit.layers.len(),
            file::MAX_LAYERS
        );
    }
    let stack = to_file(opts, &fit);
    // the file the command writes must be the one the build reads
    let text = stack.to_toml("");
    file::parse_stack_str(&text, Path::new(&format!("{}.toml", stack.name)))
        .map_err(|e| anyhow::anyhow!("the calibrated stack is refused by the tissue format: {e}"))?;
    let layers: Vec<insertion::Layer> = stack.layers.iter().map(to_layer).collect();
    let lib_stack = insertion::Stack { name: &stack.name, needle_diameter_mm: opts.needle_diameter_mm as f32, layers: &layers };
    let replay = replay::replay(&lib_stack, fit.onset_mm, start, end, opts.speed_mm_per_s);
    let checks = replay::checks(&points, &events, &replay);
    Ok(Calibration { points, events, fit, stack, replay, checks, similarity })
}

/// The cheap checks of `opts`, before any file is read: every number within its range
/// of [`limits`] (the unit in the message).
///
/// # Errors
/// A value outside its range, or the library has no fitted model.
pub fn check_options(opts: &Options<'_>) -> Result<()> {
    limits::check_range("--needle-diameter-mm", opts.needle_diameter_mm, &limits::NEEDLE_DIAMETER_MM, "mm", "the needles there are")?;
    limits::check_range("--speed-mm-per-s", opts.speed_mm_per_s, &limits::SPEED_MM_PER_S, "mm/s", "a slow robot to a fast hand")?;
    limits::check_range(
        "--drop-fraction",
        opts.rule.drop_fraction,
        &limits::DROP_FRACTION,
        "of the peak force",
        "a fraction: 0.25 is a drop of 25 %",
    )?;
    if !(opts.fe_shear_modulus_n_per_mm2.is_finite() && opts.fe_shear_modulus_n_per_mm2 > 0.0) {
        bail!("FE shear modulus {} N/mm^2: must be finite and > 0", opts.fe_shear_modulus_n_per_mm2);
    }
    if !needle_haptics::model_info::FITTED {
        bail!("the library was built without a fitted model: run `needle fit` first");
    }
    Ok(())
}

fn to_file(opts: &Options<'_>, fit: &fit::Fit) -> file::Stack {
    let source = format!(
        "needle calibrate on {} ({} mm needle at {} mm/s); friction all Coulomb at that speed, stick band {} mm/s assumed; track stiffness = E = 3 s mu0 (Winkler subgrade k ~ E, Vesic 1961)",
        opts.curve.file_name().map(|f| f.to_string_lossy().into_owned()).unwrap_or_default(),
        opts.needle_diameter_mm,
        opts.speed_mm_per_s,
        STICK_BAND_MM_PER_S
    );
    let n = fit.layers.len();
    let layers = fit
        .layers
        .iter()
        .enumerate()
        .map(|(k, l)| {
            let below = fit.layers.get(k + 1).map_or(fit.last_depth_mm.max(l.boundary_mm + 1.0), |b| b.boundary_mm);
            file::Layer {
                name: if k == 0 {
                    "surface to the first internal boundary".into()
                } else if k + 1 == n {
                    format!("below internal boundary {k}")
                } else {
                    format!("internal boundary {k} down")
                },
                thickness_mm: below - l.boundary_mm,
                stiffness_scale: l.scale,
                puncture_force_n: l.puncture_force_n,
                cutting_force_n: l.cutting_force_n,
                friction_static_n_per_mm: l.friction_n_per_mm,
                friction_coulomb_n_per_mm: l.friction_n_per_mm,
                friction_viscous_n_s_per_mm2: 0.0,
                stick_band_mm_per_s: STICK_BAND_MM_PER_S,
                track_stiffness_n_per_mm2: WINKLER_E_PER_MU * l.scale * opts.fe_shear_modulus_n_per_mm2,
                source: source.clone(),
                prony: Vec::new(),
                prony_source: None,
                family_weight: l.family_weight,
                family_weight_range: l.family_weight_range,
                softening_fraction: l.softening.fraction,
                softening_onset_ratio: if l.softening.fraction > 0.0 { l.softening.onset_ratio } else { 0.0 },
                softening_fraction_range: l.softening_fraction_range,
                presliding_mm: None,
                relaxation_slip_mm: None,
                tent_n_per_mm: None,
                shaft_prony: Vec::new(),
            }
        })
        .collect();
    file::Stack {
        format: file::TISSUE_FORMAT,
        name: opts.name.clone(),
        description: format!("calibrated by needle calibrate on {}", opts.curve.display()),
        needle_diameter_mm: opts.needle_diameter_mm,
        layers,
    }
}

/// The library's layer for a file layer (f32, as the build would compile it in).
#[must_use]
pub fn to_layer(l: &file::Layer) -> insertion::Layer {
    insertion::Layer {
        thickness_mm: l.thickness_mm as f32,
        stiffness_scale: l.stiffness_scale as f32,
        puncture_force_n: l.puncture_force_n as f32,
        cutting_force_n: l.cutting_force_n as f32,
        friction: Karnopp {
            static_n_per_mm: l.friction_static_n_per_mm as f32,
            coulomb_n_per_mm: l.friction_coulomb_n_per_mm as f32,
            viscous_n_s_per_mm2: l.friction_viscous_n_s_per_mm2 as f32,
            stick_band_mm_per_s: l.stick_band_mm_per_s as f32,
        },
        track_stiffness_n_per_mm2: l.track_stiffness_n_per_mm2 as f32,
        // the parser checked the terms with the library's rules (on the f32 weights)
        prony: PronyTerms::new(&l.prony.iter().map(|t| PronyTerm { g: t.g as f32, tau_s: t.tau_s as f32 }).collect::<Vec<_>>())
            .unwrap_or(PronyTerms::NONE),
        // the parser checked the weight (0 ..= 1) and the softening's ranges
        family: insertion::FamilyMember::new(l.family_weight as f32).unwrap_or(insertion::FamilyMember::PAPER),
        softening: insertion::Softening { fraction: l.softening_fraction as f32, onset_ratio: l.softening_onset_ratio as f32 },
        // the parser checked the distance's range and the terms
        presliding: l.presliding_mm.map_or(insertion::Presliding::NONE, |d| insertion::Presliding {
            distance_mm: d as f32,
            relaxation_slip_mm: l.relaxation_slip_mm.unwrap_or(d) as f32,
            shaft_prony: PronyTerms::new(
                &l.shaft_prony.iter().map(|t| PronyTerm { g: t.g as f32, tau_s: t.tau_s as f32 }).collect::<Vec<_>>(),
            )
            .unwrap_or(PronyTerms::NONE),
            tent_n_per_mm: l.tent_n_per_mm.unwrap_or(0.0) as f32,
        }),
    }
}
