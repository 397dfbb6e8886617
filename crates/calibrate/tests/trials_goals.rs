//! Issue 65's goals on the rig's measured trials (`../shared/data/stokes-needle-rig/`
//! beside the checkout, read in place; a missing folder fails): each sample calibrated
//! on all its 2 mm/s trials together and held against each of them; skin on muscle
//! calibrated on its 2 mm/s trials and replaying its 1 and 3 mm/s trials (predicted);
//! and each 2 mm/s trial held out: calibrated on the others of its group, predicted.
//! Every check's numbers are printed (`--nocapture`); what is asserted is said at each
//! assertion.
mod common;

use common::{calibrate, group, prepare, replay};
use needle_calibrate::goals::{self, Goals};
use needle_calibrate::replay::Check;
use needle_calibrate::whole::TrialsCalibration;
use std::path::{Path, PathBuf};

/// The goals met on the rig's trials when this test was last changed (calibrated on all
/// 2 mm/s trials of a sample; skin on muscle's 1 and 3 mm/s trials predicted; each 2 mm/s
/// trial held out), printed by this test: a change that loses a goal fails here (raise
/// them when a change gains). Not the goal, which is every check met; what
/// misses and why: `docs/insertion.md`, "What the model cannot do yet". Predicted went
/// 26 -> 24 when each shaft term's arm got its own slip distance (the one the holds are
/// fitted with): two of skin on muscle's 1 mm/s withdrawal means (goal 15 %) missed, for
/// 5 more repeats met (the measurement notebook).
const MET_AT_LEAST: Met = Met { calibrated: 60, predicted: 25, held_out: 61 };

/// Goals met per set.
struct Met {
    calibrated: usize,
    predicted: usize,
    held_out: usize,
}

fn predict(c: &TrialsCalibration, file: &Path, g: &Goals) -> Vec<Check> {
    let t = prepare(file);
    goals::checks(&t, &replay(c, &t), g)
}

fn show(label: &str, file: &Path, checks: &[Check]) -> (usize, usize) {
    let met = checks.iter().filter(|c| c.met()).count();
    eprintln!(
        "{label} {}: {met} of {} goals met",
        file.file_name().map_or(String::new(), |n| n.to_string_lossy().into_owned()),
        checks.len()
    );
    for c in checks {
        eprintln!(
            "  {:<78} measured {:>8.4} model {:>8.4} error {:>+8.2} {:<2} (goal {}) {}",
            c.what,
            c.measured,
            c.model,
            c.error,
            c.unit,
            c.goal,
            if c.met() { "ok" } else { "MISSED" }
        );
    }
    (met, checks.len())
}

fn find<'a>(checks: &'a [Check], what: &str) -> Vec<&'a Check> {
    checks.iter().filter(|c| c.what.starts_with(what)).collect()
}

#[test]
fn calibrated_at_2_mm_per_s_and_predicted() {
    let (mut totals, mut predicted) = ((0, 0), (0, 0));
    for sample in ["skin_2mmps", "muscle_2mmps", "skin-on-muscle_2mmps"] {
        let files = group(sample);
        let started = std::time::Instant::now();
        let c = calibrate(&files);
        eprintln!("{sample}: calibrated on {} trials in {:.2} s; notes: {:?}", files.len(), started.elapsed().as_secs_f64(), c.notes);
        for (t, checks) in c.trials.iter().zip(&c.checks) {
            let (m, n) = show("calibrated", &t.path, checks);
            totals = (totals.0 + m, totals.1 + n);
            // asserted: the model makes every puncture the stack was fitted for, within
            // the goal's force and position (the 5 % and 0.5 mm); the rest is
            // printed (the hold is not met: see the report)
            let fitted = c.fitted.punctures;
            for k in 1..=fitted {
                for check in find(checks, &format!("puncture {k}:")) {
                    assert!(!check.model.is_nan(), "{}: the model misses puncture {k}", t.name());
                }
            }
        }
        if sample.starts_with("skin-on-muscle") {
            for speed in ["skin-on-muscle_1mmps", "skin-on-muscle_3mmps"] {
                for file in group(speed) {
                    let checks = predict(&c, &file, &goals::PREDICTED);
                    let (m, n) = show("predicted", &file, &checks);
                    predicted = (predicted.0 + m, predicted.1 + n);
                    // asserted: the skin's puncture is made by the model at the other speeds
                    // (the muscle's is missed at 3 mm/s: the stack has no speed dependence
                    // of the puncture force; printed above)
                    assert!(
                        find(&checks, "puncture 1:").iter().all(|c| !c.model.is_nan()),
                        "{}: the model misses the first puncture",
                        file.display()
                    );
                }
            }
        }
    }
    eprintln!("calibrated: {} of {} goals met over the 2 mm/s trials", totals.0, totals.1);
    eprintln!("predicted: {} of {} goals met over skin on muscle's 1 and 3 mm/s trials", predicted.0, predicted.1);
    // asserted: no goal lost against the last measured counts (`MET_AT_LEAST`)
    assert!(totals.0 >= MET_AT_LEAST.calibrated, "calibrated: {} goals met, fewer than {}", totals.0, MET_AT_LEAST.calibrated);
    assert!(predicted.0 >= MET_AT_LEAST.predicted, "predicted: {} goals met, fewer than {}", predicted.0, MET_AT_LEAST.predicted);
}

#[test]
fn each_trial_held_out_and_predicted() {
    let mut totals = (0, 0);
    for sample in ["skin_2mmps", "muscle_2mmps", "skin-on-muscle_2mmps"] {
        let files = group(sample);
        for (k, held) in files.iter().enumerate() {
            let others: Vec<PathBuf> = files.iter().enumerate().filter(|(j, _)| *j != k).map(|(_, f)| f.clone()).collect();
            let c = calibrate(&others);
            let checks = predict(&c, held, &goals::PREDICTED);
            let (m, n) = show("held out", held, &checks);
            totals = (totals.0 + m, totals.1 + n);
            // asserted: the held-out trial replays and the model punctures it
            assert!(!find(&checks, "puncture 1: force").iter().any(|c| c.model.is_nan()), "{}: no first puncture", held.display());
        }
    }
    eprintln!("held out: {} of {} goals met", totals.0, totals.1);
    // asserted: no goal lost against the last measured count (`MET_AT_LEAST`)
    assert!(totals.0 >= MET_AT_LEAST.held_out, "held out: {} goals met, fewer than {}", totals.0, MET_AT_LEAST.held_out);
}
