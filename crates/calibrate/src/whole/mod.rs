//! `needle calibrate --trials`: a tissue stack fitted to whole measured trials of one
//! sample and one needle together (issue 65), at any mix of speeds and repeats.
//!
//! 1. each trial is read, screened ([`crate::trial_screen`]), cut into insertion, hold and
//!    withdrawal, its punctures found on the insertion and today's single-curve fit run
//!    on it ([`trials`]): its contact onset and the shape before the first puncture;
//! 2. the first layer: the mean of the trials' pre-puncture scales and puncture forces;
//! 3. the shaft friction per layer from the withdrawals ([`friction`]);
//! 4. each layer directly under another, deflecting after its puncture ([`intervals`]);
//! 5. after the last puncture and the hold: the boundary below and its Prony terms
//!    ([`hold`]); then the shaft's presliding, its distance from the withdrawals' onsets
//!    and its relaxation from the holds ([`presliding`], [`hold::fit_with_shaft`]);
//! 6. each puncture's force against the insertion speed, where the trials have several
//!    ([`speed`]: whether the data show a dependence, said in the notes);
//! 7. the stack replayed along every trial through the library's insertion model
//!    ([`crate::trial_replay`]) and held against it ([`goals`]); a group's repeats and
//!    a prediction's error against their spread: [`repeats`].
//!
//! Every value's uncertainty is the standard error over the trials (their per-trial fits;
//! for the friction's Coulomb and viscous levels the regression's), written beside it
//! in the tissue file ([`annotate`]).
pub mod annotate;
pub mod friction;
pub mod goals;
pub mod hold;
pub mod intervals;
pub mod presliding;
pub mod repeats;
pub mod speed;
pub mod stack;
pub mod stats;
pub mod tent;
pub mod tied;
pub mod trials;

use crate::events::EventRule;
use crate::replay::Check;
use crate::trial_replay::TrialReplay;
use anyhow::{bail, Result};
use needle_haptics::insertion;
use needle_haptics::Pose;
use std::path::PathBuf;

/// What to calibrate.
#[derive(Debug, Clone)]
pub struct TrialsOptions<'a> {
    /// The trial files (`time_s,position_mm,force_n`).
    pub trials: &'a [PathBuf],
    /// The stack's name.
    pub name: String,
    /// The needle's diameter, mm: one value, or one per trial (all equal).
    pub needle_diameter_mm: &'a [f64],
    /// How punctures are found.
    pub rule: EventRule,
    /// The FE tissue's shear modulus, N/mm² (the track stiffness).
    pub fe_shear_modulus_n_per_mm2: f64,
}

/// The result.
#[derive(Debug, Clone)]
pub struct TrialsCalibration {
    /// The trials, prepared.
    pub trials: Vec<trials::Trial>,
    /// What the calibration says about its input (a trial without a hold, another
    /// puncture count...), each naming its file.
    pub notes: Vec<String>,
    /// The fitted stack, its uncertainties and the fits behind it.
    pub fitted: stack::Fitted,
    /// The stack replayed along each trial.
    pub replays: Vec<TrialReplay>,
    /// Each trial's checks.
    pub checks: Vec<Vec<Check>>,
    /// Geometric similarity, measured needle over the FE needle.
    pub similarity: f64,
    /// The first layer's shape values on their range's edge ([`crate::edges::of_trials`]).
    pub edges: Vec<crate::edges::EdgeWarning>,
}

/// Calibrates a stack on the trials of `opts` (module docs).
///
/// # Errors
/// An option out of range, trials of two needles, a trial refused by the reader or the
/// screen (`FILE:LINE`), a trial without a puncture, or a stack the format refuses.
pub fn calibrate_trials(opts: &TrialsOptions<'_>) -> Result<TrialsCalibration> {
    if opts.trials.is_empty() {
        bail!("--trials: give at least one trial file (time_s,position_mm,force_n)");
    }
    let diameter = trials::one_needle(opts.trials, opts.needle_diameter_mm)?;
    crate::limits::check_range("--needle-diameter-mm", diameter, &crate::limits::NEEDLE_DIAMETER_MM, "mm", "the needles there are")?;
    if !(opts.fe_shear_modulus_n_per_mm2.is_finite() && opts.fe_shear_modulus_n_per_mm2 > 0.0) {
        bail!("FE shear modulus {} N/mm^2: must be finite and > 0", opts.fe_shear_modulus_n_per_mm2);
    }
    if !needle_haptics::model_info::FITTED {
        bail!("the library was built without a fitted model: run `needle fit` first");
    }
    let similarity = diameter / f64::from(insertion::FE_NEEDLE_DIAMETER_MM);
    let u = move |d: f64| f64::from(insertion::deflection(&Pose::default(), d as f32, 1.0, similarity as f32).wrench.fy_n);
    let trials: Vec<trials::Trial> =
        opts.trials.iter().map(|p| trials::prepare(p, opts.rule, &u, similarity, true)).collect::<Result<_>>()?;
    let mut notes: Vec<String> = trials.iter().flat_map(|t| t.phases.notes.clone()).collect();
    let mut fitted = stack::fit(&trials, opts, diameter, &u, &mut notes)?;
    notes.extend(speed::of_trials(&trials, fitted.punctures).iter().map(speed::SpeedDependence::note));
    let tent = tent::fit(&mut fitted.stack, diameter, &trials)?;
    tent::annotate(&tent, &fitted.stack, &mut fitted.uncertainty);
    let layers: Vec<insertion::Layer> = fitted.stack.layers.iter().map(crate::to_layer).collect();
    let lib = insertion::Stack { name: &fitted.stack.name, needle_diameter_mm: diameter as f32, layers: &layers };
    let mut replays = Vec::with_capacity(trials.len());
    let mut checks = Vec::with_capacity(trials.len());
    for t in &trials {
        let r = crate::trial_replay::replay(&lib, t.onset_mm(), &t.samples).map_err(|e| anyhow::anyhow!("{}: {e}", t.name()))?;
        checks.push(goals::checks(t, &r, &goals::CALIBRATED));
        replays.push(r);
    }
    let fits: Vec<&[crate::edges::EdgeWarning]> = trials.iter().map(|t| t.fit.edges.as_slice()).collect();
    let edges = fitted
        .stack
        .layers
        .first()
        .map_or_else(Vec::new, |l| crate::edges::of_trials(l.family_weight, l.softening_fraction, l.softening_onset_ratio, &fits));
    Ok(TrialsCalibration { trials, notes, fitted, replays, checks, similarity, edges })
}
