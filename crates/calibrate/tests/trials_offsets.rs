//! Issue 65's checks run on trials the project does not have, such as a rig whose force
//! sensor is not tared at the start of each trial (or is tared under a load) and whose
//! stage's encoder is not zeroed there: the calibration must read the tissue, not the
//! sensor's or the stage's zero. Two of the rig's 2 mm/s groups (read in place from
//! `../shared/data/stokes-needle-rig/`) are calibrated as measured and with a constant
//! added to every force and another to every position (written to a temporary folder,
//! never to the repository), the force's of either sign and about a tenth of the
//! puncture force:
//!
//! - each shifted trial's calibration says so, naming its file and first line, the force
//!   it read at rest (within the noise of the constant added) and the stage's start;
//! - replayed along each measured trial, the two stacks' forces differ by at most
//!   [`TIE_PCT`] of the trial's peak force: the tare (the force at rest before the stage
//!   moves) beyond its noise is subtracted from every sample (`trial::remove_tare`), and
//!   a start beyond 0.05 mm moved to zero (`trial::zero_travel`), so the shifted copies
//!   are the measured trials less their own tare, up to the rounding of the sums;
//! - the goals met within [`TIE_GOALS`] of each other.
//!
//! Before the tare was subtracted the muscle shifted by +0.25 N met 8 goals against 16:
//! its first layer's scale went from 43.9 to 5.2, its Coulomb level from 0.114 to
//! 0.051 N/mm, and the tent was lost. Before the positions were moved to start at zero,
//! the muscle's stage starting at 40 mm fitted no presliding (no withdrawal turned the
//! force over within the goals' window, 10-20 mm of travel) and a first layer of 6.3 mm
//! instead of 10.9 mm.
mod common;

use common::{calibrate, group, met, name, replay};
use std::path::{Path, PathBuf};

/// The largest RMS difference of the two stacks' replayed forces, % of the trial's peak.
/// The shifted copies lose the rig's own tare with the offset (`trial::remove_tare`
/// subtracts a tare beyond its noise; the measured trials' own, -0.001 to -0.007 N for
/// the muscle, within it, are kept), and the calibration reads that: the muscle's stacks
/// 1.30-1.42 % of the peak apart, goals 16 and 17; skin on muscle 0.02-0.62 %, goals 25
/// and 25. Far below a repeat of the tissue (the groups' spreads, 3.8-9.0 %) and what
/// the uncorrected offsets did (below).
const TIE_PCT: f64 = 2.0;

/// The goals met may differ by this many: a goal that the rig's own tare moves across its
/// limit (the muscle 16 and 17).
const TIE_GOALS: usize = 1;

/// `file` with `offset_n` added to every force and `offset_mm` to every position, written
/// into `dir`.
fn shifted(file: &Path, (offset_n, offset_mm): (f64, f64), dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let mut lines = text.lines();
    let header = lines.next().unwrap_or_else(|| panic!("{}: empty", file.display()));
    let column = |name: &str| header.split(',').position(|c| c.trim() == name).unwrap_or_else(|| panic!("{}: no {name}", file.display()));
    let (force, position) = (column("force_n"), column("position_mm"));
    let mut out = format!("{header}\n");
    for line in lines {
        let row: Vec<String> = line
            .split(',')
            .enumerate()
            .map(|(k, x)| {
                let value = || -> f64 { x.trim().parse().unwrap_or_else(|e| panic!("{}: {line}: {e}", file.display())) };
                match k {
                    _ if k == force => format!("{:.6}", value() + offset_n),
                    _ if k == position => format!("{:.5}", value() + offset_mm),
                    _ => x.to_string(),
                }
            })
            .collect();
        out.push_str(&format!("{}\n", row.join(",")));
    }
    let to = dir.join(file.file_name().expect("a file name"));
    std::fs::write(&to, out).unwrap_or_else(|e| panic!("{}: {e}", to.display()));
    to
}

#[test]
fn the_muscle_read_from_an_untared_sensor_and_a_stage_at_40_mm_is_the_same_tissue() {
    same_tissue("muscle_2mmps_", (0.25, 40.0));
}

#[test]
fn skin_on_muscle_read_from_a_sensor_tared_under_load_is_the_same_tissue() {
    same_tissue("skin-on-muscle_2mmps_", (-0.4, 7.5));
}

/// The module doc's checks on the group whose file names start with `prefix`, shifted by
/// `offsets` (N, mm).
fn same_tissue(prefix: &str, offsets: (f64, f64)) {
    let (offset_n, offset_mm) = offsets;
    let files = group(prefix);
    let dir = tempfile::tempdir().expect("a temporary folder");
    let moved: Vec<PathBuf> = files.iter().map(|f| shifted(f, offsets, dir.path())).collect();
    let (measured, untared) = (calibrate(&files), calibrate(&moved));
    let mut failed: Vec<String> = Vec::new();
    for f in &moved {
        for what in ["the force at rest", "the stage starts at"] {
            match untared.notes.iter().find(|n| n.starts_with(&format!("{}:2: {what}", f.display()))) {
                Some(note) => println!("{note}"),
                None => failed.push(format!("{}: no note \"{what}\": {:?}", f.display(), untared.notes)),
            }
        }
    }
    if let Some(n) = measured.notes.iter().find(|n| n.contains("the force at rest") || n.contains("the stage starts at")) {
        failed.push(format!("the measured trials are tared and zeroed at the start, yet: {n}"));
    }
    for t in &measured.trials {
        let (a, b) = (replay(&measured, t), replay(&untared, t));
        let d: Vec<f64> = a.rows.iter().zip(&b.rows).skip(t.phases.contact).map(|(x, y)| x.force_n - y.force_n).collect();
        let rms = (d.iter().map(|x| x * x).sum::<f64>() / d.len().max(1) as f64).sqrt();
        let peak = t.samples.iter().map(|s| s.force_n).fold(0.0, f64::max);
        let pct = 100.0 * rms / peak;
        println!("{}: the two stacks' forces differ by {rms:.3e} N RMS, {pct:.3} % of its peak (at most {TIE_PCT} %)", name(&t.path));
        if pct.is_nan() || pct > TIE_PCT {
            failed.push(format!("{}: the stacks' forces differ by {pct} % of its peak, more than {TIE_PCT} %", name(&t.path)));
        }
    }
    let (m, u) = (met(&measured), met(&untared));
    println!("goals met: {m} as measured, {u} shifted by {offset_n:+} N and {offset_mm:+} mm");
    if m.abs_diff(u) > TIE_GOALS {
        failed.push(format!("goals met: {m} as measured, {u} shifted by {offset_n:+} N and {offset_mm:+} mm"));
    }
    assert!(failed.is_empty(), "{prefix} shifted by {offset_n:+} N and {offset_mm:+} mm is not the same tissue:\n{}", failed.join("\n"));
}
