//! Whole measured trials (issue 65): the rig's 23 trials (`../shared/data/stokes-needle-rig/`,
//! read in place: no licence to copy them) are read and cut into insertion, hold and
//! withdrawal by `needle_calibrate::trial`. The facts checked are the rig's, from the file
//! names and the data's README, not from the code: each trial's speed (`<speed>mmps` in
//! its name), the 5 s hold and the 24.3-25.0 mm of travel the README states, and contact
//! "at about 4-7 mm" of travel.

// a test binary uses only `workspace` of the shared walker
#[allow(dead_code)]
mod source_walk;

use needle_calibrate::trial::{phases, read_trial};
use std::path::PathBuf;

fn rig_trials() -> Vec<PathBuf> {
    let dir = source_walk::workspace().join("../shared/data/stokes-needle-rig");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e} (the measured rig trials live beside the checkout)", dir.display()))
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "csv"))
        .collect();
    files.sort();
    assert_eq!(files.len(), 23, "{}: the README lists 23 trials", dir.display());
    files
}

/// `<sample>_<speed>mmps_...`: the speed the file name states, mm/s.
fn named_speed(p: &std::path::Path) -> f64 {
    let name = p.file_stem().and_then(|s| s.to_str()).unwrap_or_default();
    let field = name.split('_').find(|f| f.ends_with("mmps")).unwrap_or_else(|| panic!("{name}: no <speed>mmps field"));
    field.trim_end_matches("mmps").parse().unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn every_rig_trial_is_cut_into_its_phases_at_its_named_speed() {
    for path in rig_trials() {
        let what = path.display().to_string();
        let s = read_trial(&path).unwrap_or_else(|e| panic!("{e:#}"));
        let p = phases(&s, &what).unwrap_or_else(|e| panic!("{e:#}"));
        // the name gives the nominal speed: the stage set to 3 mm/s runs at 2.91 (the
        // two-point speed below says so for every 3 mm/s trial), hence 5 %; the fitted
        // speed must match the two-point speed between 5 and 20 mm of travel to 0.5 %
        let v = named_speed(&path);
        let (a, b) = (s.iter().find(|x| x.position_mm >= 5.0), s.iter().find(|x| x.position_mm >= 20.0));
        let two_point = a.zip(b).map_or(f64::NAN, |(a, b)| (b.position_mm - a.position_mm) / (b.time_s - a.time_s));
        assert!(
            (p.insertion_speed_mm_per_s / two_point - 1.0).abs() < 0.005,
            "{what}: insertion at {} mm/s, two-point {two_point}",
            p.insertion_speed_mm_per_s
        );
        assert!((p.insertion_speed_mm_per_s / v - 1.0).abs() < 0.05, "{what}: insertion at {} mm/s, named {v}", p.insertion_speed_mm_per_s);
        assert!(
            (p.withdrawal_speed_mm_per_s / -v - 1.0).abs() < 0.05,
            "{what}: withdrawal at {} mm/s, named {v}",
            p.withdrawal_speed_mm_per_s
        );
        assert!((p.hold_s - 5.0).abs() < 0.5, "{what}: hold of {} s (the rig holds 5 s)", p.hold_s);
        assert!((24.2..=25.1).contains(&p.travel_mm), "{what}: travel {} mm (the README: 24.3-25.0 mm)", p.travel_mm);
        // the contact is where the force starts to build: flat (as tared) until 0.5 mm
        // before it, and at least 0.1 N 3 mm after it (the smallest rise over 3 mm of any
        // trial is several tenths of a newton)
        let at = s.get(p.contact).map_or(f64::NAN, |x| x.position_mm);
        let tare = s.get(..p.insertion.start).map_or(0.0, |t| t.iter().map(|x| x.force_n).sum::<f64>() / t.len() as f64);
        let before: Vec<f64> = s[p.insertion.clone()].iter().filter(|x| x.position_mm < at - 0.5).map(|x| x.force_n - tare).collect();
        let mean_before = before.iter().sum::<f64>() / before.len().max(1) as f64;
        assert!(mean_before.abs() < 0.02, "{what}: the force before the contact at {at} mm is not flat: mean {mean_before} N");
        let after = s[p.insertion.clone()].iter().find(|x| x.position_mm >= at + 3.0).map_or(f64::NAN, |x| x.force_n - tare);
        assert!(after > 0.1, "{what}: 3 mm past the contact at {at} mm the force is {after} N");
        assert!(p.insertion.end <= p.hold.end && p.hold.start < p.withdrawal.start, "{what}: phases in order: {p:?}");
        // the hold ends before the stage starts back: its last sample is not below the
        // one before it, and the withdrawal's first move is (the stage's servo takes
        // several samples to leave the at-rest tolerance: those are the withdrawal's)
        let at = |i: usize| s.get(i).map_or(f64::NAN, |x| x.position_mm);
        let last = p.hold.end - 1;
        assert!(at(last) >= at(last - 1), "{what}: the hold's last sample (line {}) is already moving back", s[last].line);
        assert!(at(last + 1) < at(last), "{what}: the sample after the hold (line {}) has not moved back", s[last + 1].line);
    }
}

#[test]
fn bad_trials_are_refused_with_file_line_and_column() {
    let dir = tempfile::tempdir().expect("tempdir");
    let write = |name: &str, text: &str| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).expect("write");
        p
    };
    let rows: String = (0..60).map(|k| format!("{},{},0.1\n", f64::from(k) * 0.01, f64::from(k) * 0.02)).collect();
    let cases = [
        (write("dup.csv", &format!("time_s,position_mm,force_n,time_s\n{rows}")), "dup.csv:1: column \"time_s\" appears 2 times"),
        (write("missing.csv", &format!("time_s,position_mm\n{rows}")), "missing.csv:1: no column \"force_n\""),
        (
            write("nan.csv", &format!("time_s,position_mm,force_n\n{rows}0.9,1.0,NaN\n")),
            "nan.csv:62: column force_n: \"NaN\" is not a finite number",
        ),
        (
            write("back.csv", &format!("time_s,position_mm,force_n\n{rows}0.5,1.0,0.1\n")),
            "back.csv:62: column time_s: 0.5 s does not follow 0.59 s of line 61",
        ),
        (write("short.csv", "time_s,position_mm,force_n\n0,0,0\n1,1,1\n"), "short.csv: 2 samples: a trial needs at least 50"),
    ];
    for (path, want) in cases {
        let e = read_trial(&path).err().map(|e| format!("{e:#}")).unwrap_or_default();
        assert!(e.contains(want), "want {want:?}, got {e:?}");
    }
    let ramp: Vec<needle_calibrate::trial::Sample> =
        read_trial(&write("ramp.csv", &format!("time_s,position_mm,force_n\n{rows}"))).expect("a ramp reads");
    let e = phases(&ramp, "ramp.csv").err().map(|e| format!("{e:#}")).unwrap_or_default();
    assert!(e.contains("ramp.csv: the stage moves from its first sample"), "{e}");
}
