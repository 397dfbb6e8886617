//! Issue 65's checks run on trials the project does not have, such as a rig whose force
//! sensor is not tared at the start of each trial (or is tared under a load): the
//! calibration must read the tissue, not the sensor's zero. Two of the rig's 2 mm/s
//! groups (read in place from `../shared/data/stokes-needle-rig/`) are calibrated as
//! measured and with a constant added to every force (written to a temporary folder,
//! never to the repository), of either sign and about a tenth of the puncture force:
//!
//! - each shifted trial's calibration says so, naming its file and first line and the
//!   force it read at rest (within the noise of the constant added);
//! - replayed along each measured trial, the two stacks' forces differ by at most
//!   [`ROUNDING_N`]: the tare is the force at rest before the stage moves, subtracted from
//!   every sample (`trial::remove_tare`), so the shifted copies are the measured trials up
//!   to the rounding of the sum;
//! - the same goals are met.
//!
//! Before the tare was subtracted the muscle shifted by +0.25 N met 8 goals against 16:
//! its first layer's scale went from 43.9 to 5.2, its Coulomb level from 0.114 to
//! 0.051 N/mm, and the tent was lost.
mod common;

use common::{calibrate, group, name, replay};
use needle_calibrate::whole::TrialsCalibration;
use std::path::{Path, PathBuf};

/// The largest RMS difference of the two stacks' replayed forces, N: what rounding the
/// shifted forces (written with six decimals) and subtracting the tare again leaves, far
/// below the sensor's noise (0.003-0.006 N at rest).
const ROUNDING_N: f64 = 1e-4;

/// `file` with `offset_n` added to every force, written into `dir`.
fn shifted(file: &Path, offset_n: f64, dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let mut lines = text.lines();
    let header = lines.next().unwrap_or_else(|| panic!("{}: empty", file.display()));
    let column = header.split(',').position(|c| c.trim() == "force_n").unwrap_or_else(|| panic!("{}: no force_n", file.display()));
    let mut out = format!("{header}\n");
    for line in lines {
        let row: Vec<String> = line
            .split(',')
            .enumerate()
            .map(|(k, x)| {
                if k == column {
                    let f: f64 = x.trim().parse().unwrap_or_else(|e| panic!("{}: {line}: {e}", file.display()));
                    format!("{:.6}", f + offset_n)
                } else {
                    x.to_string()
                }
            })
            .collect();
        out.push_str(&format!("{}\n", row.join(",")));
    }
    let to = dir.join(file.file_name().expect("a file name"));
    std::fs::write(&to, out).unwrap_or_else(|e| panic!("{}: {e}", to.display()));
    to
}

/// The goals met over every trial.
fn met(c: &TrialsCalibration) -> usize {
    c.checks.iter().flatten().filter(|k| k.met()).count()
}

#[test]
fn the_muscle_read_from_an_untared_sensor_is_the_same_tissue() {
    same_tissue("muscle_2mmps_", 0.25);
}

#[test]
fn skin_on_muscle_read_from_a_sensor_tared_under_load_is_the_same_tissue() {
    same_tissue("skin-on-muscle_2mmps_", -0.4);
}

/// The module doc's checks on the group whose file names start with `prefix`, shifted by
/// `offset_n`.
fn same_tissue(prefix: &str, offset_n: f64) {
    let files = group(prefix);
    let dir = tempfile::tempdir().expect("a temporary folder");
    let moved: Vec<PathBuf> = files.iter().map(|f| shifted(f, offset_n, dir.path())).collect();
    let (measured, untared) = (calibrate(&files), calibrate(&moved));
    let mut failed: Vec<String> = Vec::new();
    for f in &moved {
        let said = untared.notes.iter().find(|n| n.starts_with(&format!("{}:2: the force at rest", f.display())));
        match said {
            Some(note) => println!("{note}"),
            None => failed.push(format!("{}: no note of its tare: {:?}", f.display(), untared.notes)),
        }
    }
    if let Some(n) = measured.notes.iter().find(|n| n.contains("the force at rest")) {
        failed.push(format!("the measured trials are tared at the start, yet: {n}"));
    }
    for t in &measured.trials {
        let (a, b) = (replay(&measured, t), replay(&untared, t));
        let d: Vec<f64> = a.rows.iter().zip(&b.rows).skip(t.phases.contact).map(|(x, y)| x.force_n - y.force_n).collect();
        let rms = (d.iter().map(|x| x * x).sum::<f64>() / d.len().max(1) as f64).sqrt();
        println!("{}: the two stacks' forces differ by {rms:.3e} N RMS (at most {ROUNDING_N:.0e})", name(&t.path));
        if rms.is_nan() || rms > ROUNDING_N {
            failed.push(format!("{}: the stacks' forces differ by {rms} N RMS, more than {ROUNDING_N} N", name(&t.path)));
        }
    }
    let (m, u) = (met(&measured), met(&untared));
    println!("goals met: {m} as measured, {u} shifted by {offset_n:+} N");
    if m != u {
        failed.push(format!("goals met: {m} as measured, {u} shifted by {offset_n:+} N"));
    }
    assert!(failed.is_empty(), "{prefix} shifted by {offset_n:+} N is not the same tissue:\n{}", failed.join("\n"));
}
