//! Bad whole trials (issue 65, "Bad input"): a measured rig trial
//! (`../shared/data/stokes-needle-rig/`, read in place; a missing folder fails) copied
//! into a temporary folder with one fault put in; each is refused naming `FILE:LINE`, or
//! (no hold, no withdrawal) fitted without that phase and said so; and trials of two
//! needles are refused together.
use needle_calibrate::events::EventRule;
use needle_calibrate::whole::{calibrate_trials, TrialsOptions};
use std::path::{Path, PathBuf};

fn rig(name: &str) -> PathBuf {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/stokes-needle-rig").join(name);
    assert!(p.is_file(), "{}: the measured rig trials live beside the checkout", p.display());
    p
}

const TRIAL: &str = "skin_2mmps_0deg_needle2_trial1.csv";

/// The trial's lines (header first) with `edit` applied to the data rows
/// (`rows[k]` is file line `k + 2`), written to `dir/name`.
fn faulty(dir: &Path, name: &str, edit: &dyn Fn(&mut Vec<String>)) -> PathBuf {
    let text = std::fs::read_to_string(rig(TRIAL)).expect("read the rig trial");
    let mut lines = text.lines();
    let header = lines.next().unwrap_or_default().to_string();
    let mut rows: Vec<String> = lines.map(str::to_string).collect();
    edit(&mut rows);
    let p = dir.join(name);
    std::fs::write(&p, format!("{header}\n{}\n", rows.join("\n"))).expect("write");
    p
}

fn opts(files: &[PathBuf], d: &[f64]) -> String {
    let mu0 = needle_codegen::tissue::read_fe_shear_modulus(&PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../coeffs/default"))
        .ok()
        .flatten()
        .unwrap_or(f64::NAN);
    let o = TrialsOptions {
        trials: files,
        name: "bad".into(),
        needle_diameter_mm: d,
        rule: EventRule::default(),
        fe_shear_modulus_n_per_mm2: mu0,
    };
    match calibrate_trials(&o) {
        Ok(c) => format!("OK {}", c.notes.join(" | ")),
        Err(e) => format!("ERR {e:#}"),
    }
}

fn set(rows: &mut [String], k: usize, column: usize, value: &str) {
    let mut cells: Vec<String> = rows[k].split(',').map(str::to_string).collect();
    cells[column] = value.to_string();
    rows[k] = cells.join(",");
}

#[test]
fn each_fault_is_named_with_its_file_and_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let cases: Vec<(PathBuf, String)> = vec![
        (faulty(d, "nan.csv", &|r| set(r, 1000, 2, "NaN")), "nan.csv:1002: column force_n: \"NaN\" is not a finite number".into()),
        (
            faulty(d, "back.csv", &|r| {
                let t = r[999].split(',').next().unwrap_or_default().to_string();
                set(r, 1000, 0, &t);
            }),
            "back.csv:1002: column time_s:".into(),
        ),
        (
            faulty(d, "gap.csv", &|r| {
                r.drain(1000..1030);
            }),
            "gap.csv:1002: column time_s:".into(),
        ),
        (
            faulty(d, "jump.csv", &|r| {
                let p: f64 = r[1000].split(',').nth(1).and_then(|x| x.parse().ok()).unwrap_or(0.0);
                set(r, 1000, 1, &format!("{}", p + 5.0));
            }),
            "jump.csv:1002: column position_mm:".into(),
        ),
        (
            faulty(d, "clipped.csv", &|r| {
                for k in 800..806 {
                    set(r, k, 2, "9.5");
                }
            }),
            "clipped.csv:802: column force_n: 9.5 N for 5 samples in a row".into(),
        ),
        (
            faulty(d, "curve.csv", &|r| {
                for row in r.iter_mut() {
                    *row = row.split(',').skip(1).collect::<Vec<_>>().join(",");
                }
            }),
            "this is a curve of one insertion (position_mm,force_n): give it with --curve".into(),
        ),
    ];
    for (path, want) in &cases {
        let got = if path.ends_with("curve.csv") {
            // the curve's header is written over: its rows keep two columns
            let text = std::fs::read_to_string(path).expect("read");
            std::fs::write(path, text.replacen("time_s,position_mm,force_n", "position_mm,force_n", 1)).expect("write");
            opts(std::slice::from_ref(path), &[1.27])
        } else {
            opts(std::slice::from_ref(path), &[1.27])
        };
        assert!(got.starts_with("ERR") && got.contains(want.as_str()), "want {want:?}, got {got:?}");
    }
}

#[test]
fn a_trial_without_hold_or_withdrawal_is_fitted_without_it_and_said() {
    let dir = tempfile::tempdir().expect("tempdir");
    let text = std::fs::read_to_string(rig(TRIAL)).expect("read");
    let rows: Vec<&str> = text.lines().collect();
    // cut where the stage first reaches its furthest travel: no hold, no withdrawal
    let max = rows.iter().skip(1).filter_map(|l| l.split(',').nth(1)?.parse::<f64>().ok()).fold(f64::MIN, f64::max);
    let top =
        rows.iter().position(|l| l.split(',').nth(1).and_then(|x| x.parse::<f64>().ok()).is_some_and(|p| p >= max)).unwrap_or(rows.len());
    let p = dir.path().join("insertion_only.csv");
    std::fs::write(&p, rows[..=top].join("\n")).expect("write");
    let got = opts(&[p], &[1.27]);
    assert!(got.starts_with("OK"), "{got}");
    assert!(got.contains("no withdrawal (fitted without it)") && got.contains("no hold (fitted without it)"), "{got}");
}

#[test]
fn trials_of_two_needles_are_refused() {
    let a = rig(TRIAL);
    let b = rig("muscle_2mmps_0deg_needle2_trial1.csv");
    let got = opts(&[a.clone(), b.clone()], &[1.27, 0.9]);
    assert!(
        got.contains("trials of different needle diameters") && got.contains("muscle_2mmps_0deg_needle2_trial1.csv: needle 0.9 mm"),
        "{got}"
    );
    let dir = tempfile::tempdir().expect("tempdir");
    let other = dir.path().join("skin_2mmps_0deg_needle3_trial1.csv");
    std::fs::copy(&a, &other).expect("copy");
    let got = opts(&[a, other], &[1.27]);
    assert!(got.contains("its name says needle3, but") && got.contains("trials of different needles"), "{got}");
}
