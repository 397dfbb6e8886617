//! Issue 65's checks run on trials the project does not have, such as a rig that samples
//! faster: the calibration must read the tissue, not the sampling rate. Each of the rig's
//! 2 mm/s groups (read in place from `../shared/data/stokes-needle-rig/`, 100 Hz) is
//! calibrated as measured and resampled to 1 kHz (each sample interval split into ten,
//! linear between the measured samples: the same information in ten times the rows,
//! written to a temporary folder, never to the repository). The two stacks must be one
//! tissue:
//!
//! - replayed along each measured trial, their forces differ by at most the group's own
//!   spread (`whole::repeats`: the RMS between its trials, % of its mean peak force),
//!   over the trial from its contact: the rate changes the model less than a repeat of
//!   the tissue does;
//! - the presliding distance (the withdrawals' onsets, read from the stage alone) within
//!   twice the larger of the two calibrations' standard errors over the trials;
//! - the goals met within 2 of each other.
//!
//! The fitted values are compared through the force they give, not one by one: the
//! candidate time constants start at three sampling periods, and 5 s holds tell a 5 s
//! term from a 16 s one with another weight only through that force; the long-term share
//! they leave weighs the withdrawals' friction fit (the muscle's Coulomb level 0.1145 and
//! 0.1116 N/mm, 2.3 standard errors apart). With the tent snapped to its grid the
//! muscle's tent was 0.4 and 0.25 N/mm and its forces 3.1-3.5 % of the peak apart (its
//! spread 3.83 %); refined between the grid points (`whole::tent`), 1.4-2.0 %.
//!
//! Before the relaxation slip distance had a range of its own (`shaft_slip_rule.rs`) this
//! test failed: at 1 kHz skin on muscle met 19 goals against 24 at 100 Hz and the muscle
//! 19 against 16 (the skin's 1 kHz stack had a cutting force of 1.13 N against 0.51 N and
//! its static level 3 times the Coulomb one against 1.75, its force within 2.2 %).
mod common;

use common::{calibrate, group, met, name, replay};
use needle_calibrate::whole::repeats::GroupSpread;
use needle_calibrate::whole::TrialsCalibration;
use std::path::{Path, PathBuf};

const SPLIT: usize = 10;

/// `file` resampled `SPLIT` times finer into `dir` (the header lines kept).
fn resampled(file: &Path, dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let parse = |l: &str| -> Option<Vec<f64>> { l.split(',').map(|x| x.trim().parse().ok()).collect() };
    let (mut out, mut rows) = (String::new(), Vec::new());
    for line in text.lines() {
        match parse(line) {
            Some(row) => rows.push(row),
            None if rows.is_empty() => out.push_str(&format!("{line}\n")),
            None => panic!("{}: a line that is not a sample after the samples: {line}", file.display()),
        }
    }
    for pair in rows.windows(2) {
        for k in 0..SPLIT {
            let u = k as f64 / SPLIT as f64;
            let row: Vec<String> = pair[0].iter().zip(&pair[1]).map(|(a, b)| format!("{:.6}", a + (b - a) * u)).collect();
            out.push_str(&format!("{}\n", row.join(",")));
        }
    }
    if let Some(last) = rows.last() {
        out.push_str(&format!("{}\n", last.iter().map(|x| format!("{x:.6}")).collect::<Vec<_>>().join(",")));
    }
    let to = dir.join(file.file_name().expect("a file name"));
    std::fs::write(&to, out).unwrap_or_else(|e| panic!("{}: {e}", to.display()));
    to
}

/// The RMS difference of the two stacks' forces replayed along `t` from its contact, N.
fn replay_difference_n(a: &TrialsCalibration, b: &TrialsCalibration, t: &needle_calibrate::whole::trials::Trial) -> f64 {
    let (ra, rb) = (replay(a, t), replay(b, t));
    let from = t.phases.contact;
    let d: Vec<f64> = ra.rows.iter().zip(&rb.rows).skip(from).map(|(x, y)| x.force_n - y.force_n).collect();
    (d.iter().map(|x| x * x).sum::<f64>() / d.len().max(1) as f64).sqrt()
}

/// `a` and `b` equal or within twice the larger standard error; else what differs.
fn agree(what: &str, (a, se_a): (f64, Option<f64>), (b, se_b): (f64, Option<f64>)) -> Option<String> {
    let se = se_a.unwrap_or(0.0).max(se_b.unwrap_or(0.0));
    println!("{what}: 100 Hz {a:.5}, 1 kHz {b:.5} (standard error {se:.2e})");
    (a != b && !(se > 0.0 && (a - b).abs() <= 2.0 * se))
        .then(|| format!("{what}: 100 Hz {a}, 1 kHz {b}: more than twice the standard error {se} apart"))
}

#[test]
fn the_skin_calibrated_at_100_hz_and_at_1_khz_is_one_tissue() {
    one_tissue_at_both_rates("skin_2mmps_");
}

#[test]
fn the_muscle_calibrated_at_100_hz_and_at_1_khz_is_one_tissue() {
    one_tissue_at_both_rates("muscle_2mmps_");
}

#[test]
fn skin_on_muscle_calibrated_at_100_hz_and_at_1_khz_is_one_tissue() {
    one_tissue_at_both_rates("skin-on-muscle_2mmps_");
}

/// The module doc's checks on the group of trials whose file names start with `prefix`.
fn one_tissue_at_both_rates(prefix: &str) {
    let files = group(prefix);
    let dir = tempfile::tempdir().expect("a temporary folder");
    let fine: Vec<PathBuf> = files.iter().map(|f| resampled(f, dir.path())).collect();
    let (coarse_c, fine_c) = (calibrate(&files), calibrate(&fine));
    for c in [&coarse_c, &fine_c] {
        let terms: Vec<String> = c.fitted.hold.shaft_prony.iter().map(|(g, tau)| format!("g {g:.3} tau {tau:.4} s")).collect();
        println!("shaft terms: {}", terms.join(", "));
    }
    println!("cutting force {:.4} N at 100 Hz, {:.4} N at 1 kHz", coarse_c.fitted.hold.cutting_n, fine_c.fitted.hold.cutting_n);
    let mut failed: Vec<String> = Vec::new();
    for (j, (a, b)) in coarse_c.fitted.friction.iter().zip(&fine_c.fitted.friction).enumerate() {
        println!("layer {j}: Coulomb level {:.5} N/mm at 100 Hz, {:.5} N/mm at 1 kHz", a.coulomb_n_per_mm, b.coulomb_n_per_mm);
    }
    let (p, q) =
        (coarse_c.fitted.presliding_mm.as_ref().expect("a presliding"), fine_c.fitted.presliding_mm.as_ref().expect("a presliding"));
    failed.extend(agree("presliding distance, mm", (p.mean, p.se), (q.mean, q.se)));
    let spread = GroupSpread::of(&coarse_c.trials).expect("the group's spread");
    for t in &coarse_c.trials {
        let pct = 100.0 * replay_difference_n(&coarse_c, &fine_c, t) / spread.mean_peak_n;
        let own = spread.rms.all_pct;
        println!("{}: the two stacks' forces differ by {pct:.2} % of the mean peak (the group's spread: {own:.2} %)", name(&t.path));
        if pct > own {
            failed.push(format!("{}: the stacks differ by {pct} % of the mean peak, more than the group's spread {own} %", name(&t.path)));
        }
    }
    let (m_coarse, m_fine) = (met(&coarse_c), met(&fine_c));
    println!("goals met: {m_coarse} at 100 Hz, {m_fine} at 1 kHz");
    if m_coarse.abs_diff(m_fine) > 2 {
        failed.push(format!("goals met: {m_coarse} at 100 Hz, {m_fine} at 1 kHz"));
    }
    assert!(failed.is_empty(), "{prefix}: the 100 Hz and 1 kHz stacks are not one tissue:\n{}", failed.join("\n"));
}
