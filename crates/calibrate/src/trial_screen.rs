//! The checks a whole trial passes before it is fitted (issue 65, "Bad input"): no gap
//! in time longer than [`MAX_GAP_SAMPLES`] samples, no jump of the stage's position, no
//! force clipped at the sensor's limit. Each refusal names `FILE:LINE`, the value and
//! its unit. (Not a finite number and time not increasing are refused by the reader,
//! [`crate::trial::read_trial`].)
use crate::trial::Sample;
use anyhow::{bail, Result};

/// Longest gap between two samples, in the trial's median sampling periods.
pub const MAX_GAP_SAMPLES: f64 = 10.0;

/// A step of the stage faster than this many times its typical moving speed (the median
/// of |dposition/dt| over the samples where it moves) is a jump of the position.
pub const JUMP_SPEED_FACTOR: f64 = 10.0;

/// Smallest step that can be a jump, mm (below it an encoder count and timing jitter).
pub const JUMP_MIN_MM: f64 = 0.05;

/// Samples in a row at the force's extreme that make it clipped (flat at the sensor's
/// limit): raw readings of a strain gauge repeat their largest value this often only
/// when the converter saturates.
pub const CLIPPED_RUN: usize = 5;

/// Checks `s` (the samples of `what`), in the order: gaps, position jumps, clipped force.
///
/// # Errors
/// The first problem found, as `FILE:LINE: column NAME: value unit: why`.
pub fn screen(s: &[Sample], what: &str) -> Result<()> {
    gaps(s, what)?;
    jumps(s, what)?;
    clipped(s, what)
}

fn median(mut v: Vec<f64>) -> Option<f64> {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied()
}

fn gaps(s: &[Sample], what: &str) -> Result<()> {
    let Some(period) = median(s.windows(2).map(|w| w[1].time_s - w[0].time_s).collect()) else { return Ok(()) };
    for w in s.windows(2) {
        let dt = w[1].time_s - w[0].time_s;
        if dt > MAX_GAP_SAMPLES * period {
            bail!(
                "{what}:{}: column time_s: {} s after {} s of line {}: a gap of {dt:.4} s, more than {MAX_GAP_SAMPLES} samples of the trial's {period:.4} s (samples lost?)",
                w[1].line,
                w[1].time_s,
                w[0].time_s,
                w[0].line
            );
        }
    }
    Ok(())
}

fn jumps(s: &[Sample], what: &str) -> Result<()> {
    let speed = |w: &[Sample]| (w[1].position_mm - w[0].position_mm).abs() / (w[1].time_s - w[0].time_s);
    let moving: Vec<f64> = s.windows(2).filter(|w| w[1].position_mm != w[0].position_mm).map(speed).collect();
    let Some(typical) = median(moving) else { return Ok(()) };
    for w in s.windows(2) {
        let step = w[1].position_mm - w[0].position_mm;
        if step.abs() > JUMP_MIN_MM && speed(w) > JUMP_SPEED_FACTOR * typical {
            bail!(
                "{what}:{}: column position_mm: {} mm after {} mm of line {}: a jump of {step:+.3} mm in {:.4} s ({:.1} mm/s, more than {JUMP_SPEED_FACTOR} times the stage's typical {typical:.3} mm/s)",
                w[1].line,
                w[1].position_mm,
                w[0].position_mm,
                w[0].line,
                w[1].time_s - w[0].time_s,
                speed(w)
            );
        }
    }
    Ok(())
}

fn clipped(s: &[Sample], what: &str) -> Result<()> {
    let (lo, hi) = s.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x.force_n), hi.max(x.force_n)));
    for extreme in [hi, lo] {
        let mut run = 0usize;
        for x in s {
            run = if x.force_n == extreme { run + 1 } else { 0 };
            if run == CLIPPED_RUN {
                let first = s.iter().find(|y| y.force_n == extreme).map_or(x.line, |y| y.line);
                bail!(
                    "{what}:{}: column force_n: {extreme} N for {CLIPPED_RUN} samples in a row at the trial's extreme (first at line {first}): the force is clipped at the sensor's limit",
                    x.line + 1 - CLIPPED_RUN
                );
            }
        }
    }
    Ok(())
}
