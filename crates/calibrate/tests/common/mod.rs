//! What the whole-trial tests share: the rig's measured trials (`../shared/data/stokes-
//! needle-rig/` beside the checkout, read in place; a missing folder fails), a
//! calibration on some of them and a stack's replay along another.
#![allow(dead_code)] // each test binary uses its part
use needle_calibrate::events::EventRule;
use needle_calibrate::runtime_stack::OwnedStack;
use needle_calibrate::trial_replay::TrialReplay;
use needle_calibrate::whole::{calibrate_trials, trials, TrialsCalibration, TrialsOptions};
use needle_haptics::{insertion, Pose};
use std::path::{Path, PathBuf};

/// The rig does not state its needle's gauge: the shipped liver's 1.27 mm (18 G) is
/// assumed (it scales the FE surrogate's depth; the fitted scales absorb the rest).
pub const NEEDLE_MM: f64 = 1.27;

pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The rig's folder.
pub fn rig() -> PathBuf {
    root().join("../shared/data/stokes-needle-rig")
}

/// Every trial file of the rig, sorted.
pub fn all_trials() -> Vec<PathBuf> {
    let dir = rig();
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e} (the measured rig trials live beside the checkout)", dir.display()))
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "csv"))
        .collect();
    files.sort();
    files
}

/// The trials whose file name starts with `prefix`, sorted.
pub fn group(prefix: &str) -> Vec<PathBuf> {
    let files: Vec<PathBuf> =
        all_trials().into_iter().filter(|p| p.file_name().and_then(|n| n.to_str()).is_some_and(|n| n.starts_with(prefix))).collect();
    assert!(!files.is_empty(), "{}: no trials {prefix}*", rig().display());
    files
}

/// A file's name, for the printed lines.
pub fn name(file: &Path) -> String {
    file.file_name().map_or(String::new(), |n| n.to_string_lossy().into_owned())
}

/// The stack calibrated on `files` together (`needle calibrate --trials`).
pub fn calibrate(files: &[PathBuf]) -> TrialsCalibration {
    let mu0 = needle_codegen::tissue::read_fe_shear_modulus(&root().join("coeffs/default")).ok().flatten().unwrap_or(f64::NAN);
    let opts = TrialsOptions {
        trials: files,
        name: "rig".into(),
        needle_diameter_mm: &[NEEDLE_MM],
        rule: EventRule::default(),
        fe_shear_modulus_n_per_mm2: mu0,
    };
    calibrate_trials(&opts).unwrap_or_else(|e| panic!("{e:#}"))
}

/// A trial prepared as a replay reads it (its contact by the single-curve fit; no
/// puncture needed).
pub fn prepare(file: &Path) -> trials::Trial {
    let lambda = (NEEDLE_MM / f64::from(insertion::FE_NEEDLE_DIAMETER_MM)) as f32;
    let u = move |d: f64| f64::from(insertion::deflection(&Pose::default(), d as f32, 1.0, lambda).wrench.fy_n);
    trials::prepare(file, EventRule::default(), &u, f64::from(lambda), false).unwrap_or_else(|e| panic!("{e:#}"))
}

/// `c`'s stack run along trial `t` (the library's f32 insertion driven by its measured
/// position against time, as `needle replay` does).
pub fn replay(c: &TrialsCalibration, t: &trials::Trial) -> TrialReplay {
    let layers: Vec<insertion::Layer> = c.fitted.stack.layers.iter().map(needle_calibrate::to_layer).collect();
    let owned = OwnedStack { name: "rig".into(), needle_diameter_mm: NEEDLE_MM as f32, layers };
    needle_calibrate::trial_replay::replay(&owned.as_stack(), t.onset_mm(), &t.samples).unwrap_or_else(|e| panic!("{e}"))
}

/// The goals met over every trial of `c`.
pub fn met(c: &TrialsCalibration) -> usize {
    c.checks.iter().flatten().filter(|k| k.met()).count()
}
