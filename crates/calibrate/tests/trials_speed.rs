//! Issue 65, item 2: "the puncture force's dependence on speed if the data show one".
//! Skin on muscle calibrated on all its trials at 1, 2 and 3 mm/s together (13, read in
//! place from `../shared/data/stokes-needle-rig/`): the calibration says, per puncture,
//! the line of the trials' peak forces against their speeds and whether the data show a
//! dependence. Held against a line computed here from the raw files (each trial's
//! largest force before 20 mm of travel, where its skin punctures; the nominal speed of
//! its file name), not from the calibration's own event detection.
mod common;

use common::{calibrate, group, name};
use needle_calibrate::whole::speed::{self, SpeedDependence};

/// The slope of the raw files' first peaks against their nominal speeds and its standard
/// error (the test's own least squares).
fn raw_line(files: &[std::path::PathBuf]) -> (f64, f64) {
    let points: Vec<(f64, f64)> = files
        .iter()
        .map(|f| {
            let n = name(f);
            let speed: f64 = n.split('_').find_map(|w| w.strip_suffix("mmps")?.parse().ok()).unwrap_or_else(|| panic!("{n}: no speed"));
            let mut reader = csv::Reader::from_path(f).unwrap_or_else(|e| panic!("{n}: {e}"));
            let peak = reader
                .records()
                .map(|r| r.unwrap_or_else(|e| panic!("{n}: {e}")))
                .map(|r| (r[1].parse::<f64>().expect("position_mm"), r[2].parse::<f64>().expect("force_n")))
                .filter(|(p, _)| *p < 20.0)
                .map(|(_, f)| f)
                .fold(f64::NEG_INFINITY, f64::max);
            (speed, peak)
        })
        .collect();
    let m = points.len() as f64;
    let (mv, mf) = (points.iter().map(|p| p.0).sum::<f64>() / m, points.iter().map(|p| p.1).sum::<f64>() / m);
    let sxx: f64 = points.iter().map(|p| (p.0 - mv).powi(2)).sum();
    let slope = points.iter().map(|p| (p.0 - mv) * (p.1 - mf)).sum::<f64>() / sxx;
    let sse: f64 = points.iter().map(|p| (p.1 - mf - slope * (p.0 - mv)).powi(2)).sum();
    (slope, (sse / (m - 2.0) / sxx).sqrt())
}

#[test]
fn skin_on_muscle_at_three_speeds_says_whether_its_punctures_depend_on_speed() {
    let files = group("skin-on-muscle_");
    assert_eq!(files.len(), 13, "the rig's skin-on-muscle trials at 1, 2 and 3 mm/s");
    let started = std::time::Instant::now();
    let c = calibrate(&files);
    eprintln!("skin on muscle, {} trials at 1-3 mm/s: calibrated in {:.2} s", files.len(), started.elapsed().as_secs_f64());
    for note in &c.notes {
        eprintln!("  note: {note}");
    }
    let lines = speed::of_trials(&c.trials, c.fitted.punctures);
    // asserted: a line per puncture the stack was fitted for, each said in the notes
    assert_eq!(lines.len(), c.fitted.punctures, "{lines:?}");
    for l in &lines {
        assert!(c.notes.contains(&l.note()), "not in the notes: {}", l.note());
    }
    // asserted: the first puncture over every trial, at the three speeds
    let first: &SpeedDependence = &lines[0];
    assert_eq!(first.trials, 13, "{first:?}");
    assert!(first.speeds_mm_per_s[0] < 1.5 && first.speeds_mm_per_s[1] > 2.5, "{first:?}");
    // asserted: the calibration's line agrees with the raw files' (the peaks detected with
    // the event rule against the raw largest force: within 0.05 N per mm/s), and neither
    // shows a dependence (the raw line: slope -0.056 +- 0.099 N per mm/s when measured)
    let (slope, se) = raw_line(&files);
    eprintln!(
        "raw first peaks: slope {slope:+.3} +- {se:.3} N per mm/s; the calibration's: {:+.3} +- {:.3}",
        first.slope_n_s_per_mm, first.standard_error_n_s_per_mm
    );
    assert!((first.slope_n_s_per_mm - slope).abs() <= 0.05, "calibration {first:?} against the raw slope {slope} +- {se}");
    assert!(slope.abs() <= speed::T_SHOWN * se, "the raw files show a dependence: {slope} +- {se}");
    assert!(!first.shown(), "{}", first.note());
}
