//! The ranges a calibration accepts, each with its unit and its reason, checked before
//! any work: a value outside them is a unit slip or a typo (a panic in the solver, an
//! allocation of tens of GB, a scan that never ends), never a measurement.
use anyhow::{bail, Result};
use std::ops::RangeInclusive;

/// Needle diameters, mm: from the finest hypodermic needle (34 G, 0.16 mm) to a 10 mm
/// trocar, with margin on both sides.
pub const NEEDLE_DIAMETER_MM: RangeInclusive<f64> = 0.1..=10.0;

/// Insertion speeds, mm/s: from a slow robot (0.01 mm/s) to a fast hand (1 m/s).
pub const SPEED_MM_PER_S: RangeInclusive<f64> = 0.01..=1000.0;

/// Puncture drop fractions (of the peak force): above 0 (any noise would count) and below
/// 1 (the force cannot drop by more than the whole peak).
pub const DROP_FRACTION: RangeInclusive<f64> = 0.001..=0.999;

/// Largest curve file read, bytes (16 MiB: [`MAX_POINTS`] rows of 160 characters); a
/// larger file (or an endless stream such as `/dev/zero`) is refused after reading this
/// much at most.
pub const MAX_CURVE_BYTES: u64 = 16 << 20;

/// Most points of a curve (a 1 kHz recording of 100 s): the fit scans every candidate
/// onset and boundary against every point, so its time grows with their product; resample
/// a denser recording (every k-th row) to this many.
pub const MAX_POINTS: usize = 100_000;

/// Shortest span of positions, mm: an insertion with a puncture moves further (a shorter
/// span is positions in metres, or all equal).
pub const MIN_SPAN_MM: f64 = 1.0;

/// Longest span of positions, mm: no needle insertion is longer (a longer span is
/// positions in micrometres or another unit).
pub const MAX_SPAN_MM: f64 = 500.0;

/// Largest |force|, N: needle insertion forces are tens of N at most (a larger one is
/// a spike of the sensor, or forces in mN).
pub const MAX_FORCE_N: f64 = 500.0;

/// Largest step back of the position from one row to the next, mm: a digitised curve
/// jitters back by less (the shipped Okamura curve: 0.098 mm at most); a larger step is
/// rows out of order.
pub const MAX_BACKWARD_MM: f64 = 1.0;

/// Most ticks of the replay through the insertion model (at 1 kHz: 5,000 s of
/// insertion; 80 MB of samples): the span over the speed.
pub const MAX_REPLAY_TICKS: f64 = 5e6;

/// Refuses `value` of option `name` outside `range` (`unit` in the message), NaN included.
///
/// # Errors
/// The value is not a number in the range: `NAME VALUE: must be a number from LO to HI UNIT (WHY)`.
pub fn check_range(name: &str, value: f64, range: &RangeInclusive<f64>, unit: &str, why: &str) -> Result<()> {
    if !range.contains(&value) {
        bail!("{name} {value}: must be a number from {} to {} {unit} ({why})", range.start(), range.end());
    }
    Ok(())
}

/// Refuses a replay of `span_mm` at `speed_mm_per_s` longer than [`MAX_REPLAY_TICKS`] ticks of `period_s`.
///
/// # Errors
/// Too many ticks, with the speed and the span in the message.
pub fn check_replay(span_mm: f64, speed_mm_per_s: f64, period_s: f64, speed_option: &str) -> Result<()> {
    let ticks = span_mm / (speed_mm_per_s * period_s);
    if ticks.is_nan() || ticks > MAX_REPLAY_TICKS {
        bail!(
            "{speed_option} {speed_mm_per_s}: the replay of {span_mm:.3} mm of positions at {speed_mm_per_s} mm/s takes {ticks:.3e} ticks at {:.0} Hz, more than {MAX_REPLAY_TICKS:e} (a speed in m/s? or positions in another unit?)",
            1.0 / period_s
        );
    }
    Ok(())
}
