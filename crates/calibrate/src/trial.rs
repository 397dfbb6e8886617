//! A whole measured trial (issue 65): stage travel and axial force against time
//! (`time_s,position_mm,force_n`), read and checked, and cut into its phases: the
//! insertion (the stage advancing), the hold (the stage at rest at its furthest travel)
//! and the withdrawal (the stage returning), each with its speed fitted from the
//! encoder, the tare (the force at rest before the stage moves: the sensor's zero, which
//! [`remove_tare`] subtracts) and the contact (the first sample where the force leaves
//! the tare's noise).
//!
//! Nothing here is fitted to a tissue: the phases come from the stage's position alone,
//! the contact from the force's own noise before the stage moved, so the same code cuts
//! a trial of any speed, travel or hold.

use anyhow::{bail, Context, Result};
use std::ops::Range;
use std::path::Path;

/// One sample of a trial, in the file's order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Time from the trial's start, s.
    pub time_s: f64,
    /// Stage travel, mm (from where the trial started, not from the tissue).
    pub position_mm: f64,
    /// Axial force on the needle, N (positive resisting the insertion).
    pub force_n: f64,
    /// 1-based line in its file.
    pub line: usize,
}

/// The columns a trial file must have, each once.
pub const TRIAL_COLUMNS: [&str; 3] = ["time_s", "position_mm", "force_n"];

/// Fewest samples a trial may have.
pub const MIN_SAMPLES: usize = 50;

/// Largest sample count read (about 28 h at 100 Hz): a bigger file is refused before
/// its rows are kept, so memory stays bounded.
pub const MAX_SAMPLES: usize = 10_000_000;

/// Reads a whole trial.
///
/// # Errors
/// Unreadable file; a missing or repeated column (`FILE:1: ...`); a value that is not a
/// finite number or a time that does not increase (`FILE:LINE: column NAME: ...`); fewer
/// than [`MIN_SAMPLES`] or more than [`MAX_SAMPLES`] samples.
pub fn read_trial(path: &Path) -> Result<Vec<Sample>> {
    let mut reader =
        csv::ReaderBuilder::new().trim(csv::Trim::All).from_path(path).with_context(|| format!("{}: cannot read", path.display()))?;
    let header = reader.headers().with_context(|| format!("{}:1: cannot read the header", path.display()))?.clone();
    let mut index = [0usize; 3];
    for (slot, name) in index.iter_mut().zip(TRIAL_COLUMNS) {
        *slot = crate::measured::column_index(&header, name, &TRIAL_COLUMNS).map_err(|problem| {
            // a curve (position_mm,force_n) is the other format calibrate reads
            let curve = !header.iter().any(|h| h == "time_s") && crate::measured::COLUMNS.iter().all(|c| header.iter().any(|h| h == *c));
            let hint = if curve { ": this is a curve of one insertion (position_mm,force_n): give it with --curve" } else { "" };
            anyhow::anyhow!("{}:1: {problem}{hint}", path.display())
        })?;
    }
    let mut samples: Vec<Sample> = Vec::new();
    for record in reader.records() {
        let record = record.with_context(|| format!("{}: malformed CSV", path.display()))?;
        let line = record.position().map_or(0, |p| p.line() as usize);
        if samples.len() == MAX_SAMPLES {
            bail!("{}:{line}: more than {MAX_SAMPLES} samples: not a trial of an insertion (split it)", path.display());
        }
        let mut v = [0.0f64; 3];
        for ((slot, &i), name) in v.iter_mut().zip(&index).zip(TRIAL_COLUMNS) {
            let text = record.get(i).unwrap_or("");
            let shown: String = text.chars().take(40).collect();
            *slot = text
                .parse()
                .ok()
                .filter(|x: &f64| x.is_finite())
                .with_context(|| format!("{}:{line}: column {name}: {shown:?} is not a finite number", path.display()))?;
        }
        if let Some(last) = samples.last() {
            if v[0] <= last.time_s {
                bail!(
                    "{}:{line}: column time_s: {} s does not follow {} s of line {}: times must increase",
                    path.display(),
                    v[0],
                    last.time_s,
                    last.line
                );
            }
        }
        samples.push(Sample { time_s: v[0], position_mm: v[1], force_n: v[2], line });
    }
    if samples.len() < MIN_SAMPLES {
        bail!("{}: {} samples: a trial needs at least {MIN_SAMPLES}", path.display(), samples.len());
    }
    Ok(samples)
}

/// A trial cut into its phases (index ranges into its samples). A trial without a hold
/// or without a withdrawal has that range empty (and says so in `notes`).
#[derive(Debug, Clone, PartialEq)]
pub struct Phases {
    /// The stage advancing: from the last sample at the start position to the first at
    /// the furthest travel.
    pub insertion: Range<usize>,
    /// The stage at rest at its furthest travel, to the last sample before it starts
    /// back (empty: no hold).
    pub hold: Range<usize>,
    /// The stage returning, to the trial's end (empty: no withdrawal).
    pub withdrawal: Range<usize>,
    /// The first sample of the insertion where the force leaves the tare's noise band.
    pub contact: usize,
    /// The force at rest before the stage moves: the sensor's zero ([`remove_tare`]).
    pub tare: Tare,
    /// The insertion's speed, mm/s (least squares of position against time over its
    /// middle 80 %).
    pub insertion_speed_mm_per_s: f64,
    /// The withdrawal's speed, mm/s (negative: the stage returns), as the insertion's;
    /// 0 without a withdrawal.
    pub withdrawal_speed_mm_per_s: f64,
    /// The hold's duration, s (0 without a hold).
    pub hold_s: f64,
    /// The stage's furthest travel from its start, mm.
    pub travel_mm: f64,
    /// What the trial lacks (no hold, no withdrawal), each a sentence naming the file:
    /// the calibration fits without that phase and says so.
    pub notes: Vec<String>,
}

/// Shortest rest at the furthest travel that counts as a hold, s.
pub const MIN_HOLD_S: f64 = 0.5;

/// Fewest samples of a withdrawal (fewer: the trial has none).
pub const MIN_WITHDRAWAL_SAMPLES: usize = 10;

/// How close to the start or furthest position the stage counts as there, as a
/// fraction of the travel (an encoder's quantisation and the servo's settling are far
/// below it).
pub const AT_REST_FRACTION: f64 = 0.002;

/// The force's noise band of the tare, in standard deviations of the force before the
/// stage moves: the contact is the first sample of the insertion beyond it (and beyond
/// [`CONTACT_FLOOR_N`]).
pub const CONTACT_SIGMAS: f64 = 6.0;

/// The contact's smallest force above the tare, N (a sensor quieter than this still
/// needs a real contact).
pub const CONTACT_FLOOR_N: f64 = 0.005;

/// Cuts `s` into insertion, hold and withdrawal, and finds the contact (module docs).
///
/// # Errors
/// The stage does not advance; no sample before the stage moves to measure the tare on;
/// no contact. A trial without a hold or a withdrawal is not an error: that range is
/// empty and [`Phases::notes`] says so.
pub fn phases(s: &[Sample], what: &str) -> Result<Phases> {
    let (Some(first), Some(max)) = (s.first(), s.iter().map(|x| x.position_mm).reduce(f64::max)) else {
        bail!("{what}: no samples");
    };
    let start = first.position_mm;
    let travel_mm = max - start;
    if travel_mm.is_nan() || travel_mm <= 0.0 {
        bail!("{what}: the stage never advances (position_mm stays at or below {start} mm)");
    }
    let tol = AT_REST_FRACTION * travel_mm;
    let top = s.iter().position(|x| x.position_mm >= max - tol).unwrap_or(0);
    let leave = rest_end(s, top, s.iter().rposition(|x| x.position_mm >= max - tol).unwrap_or(top));
    let begin = s[..top].iter().rposition(|x| x.position_mm <= start + tol).unwrap_or(0);
    if begin < 2 {
        bail!("{what}: the stage moves from its first sample: no tare to measure the force's noise on");
    }
    let fit = |r: Range<usize>| slope(&s[r.clone()]).with_context(|| format!("{what}: samples {r:?}: too few to fit a speed"));
    let insertion = begin..top + 1;
    let mut notes = Vec::new();
    let withdrawal = if leave + MIN_WITHDRAWAL_SAMPLES < s.len() {
        leave..s.len()
    } else {
        let line = s[leave].line;
        notes.push(format!(
            "{what}:{line}: the stage does not return after its furthest travel ({max} mm): no withdrawal (fitted without it)"
        ));
        s.len()..s.len()
    };
    let hold_s = s[leave].time_s - s[top].time_s;
    let (hold, hold_s) = if hold_s >= MIN_HOLD_S {
        (top..leave + 1, hold_s)
    } else {
        let line = s[top].line;
        notes.push(format!(
            "{what}:{line}: the stage rests {hold_s:.3} s at its furthest travel ({max} mm), less than {MIN_HOLD_S} s: no hold (fitted without it)"
        ));
        (top..top, 0.0)
    };
    let insertion_speed_mm_per_s = fit(middle(&insertion))?;
    let withdrawal_speed_mm_per_s = if withdrawal.is_empty() { 0.0 } else { fit(middle(&until_back(s, &withdrawal, start + tol)))? };
    let tare = tare(&s[..begin]);
    let contact =
        contact(s, &tare, &insertion).with_context(|| format!("{what}: the force never leaves the tare's noise during the insertion"))?;
    Ok(Phases { insertion, hold, withdrawal, contact, tare, insertion_speed_mm_per_s, withdrawal_speed_mm_per_s, hold_s, travel_mm, notes })
}

/// The last sample at rest at the furthest travel: `last` (the last within the at-rest
/// tolerance) moved back over the stage's final run of falling positions, which is the
/// withdrawal already under way (a servo accelerates the stage through the tolerance
/// over several samples); not before `top`.
fn rest_end(s: &[Sample], top: usize, last: usize) -> usize {
    let mut k = last;
    while k > top && s[k].position_mm < s[k - 1].position_mm {
        k -= 1;
    }
    k
}

/// The withdrawal up to where the stage is back at its start (`back_mm`; the trial may
/// rest there).
fn until_back(s: &[Sample], w: &Range<usize>, back_mm: f64) -> Range<usize> {
    let end = s[w.clone()].iter().position(|x| x.position_mm <= back_mm).map_or(w.end, |k| w.start + k + 1);
    w.start..end
}

/// The middle 80 % of a range.
fn middle(r: &Range<usize>) -> Range<usize> {
    let cut = r.len() / 10;
    r.start + cut..r.end - cut
}

/// Least-squares slope of position against time, mm/s; `None` under 3 samples.
fn slope(s: &[Sample]) -> Option<f64> {
    if s.len() < 3 {
        return None;
    }
    let n = s.len() as f64;
    let (mt, mp) = s.iter().fold((0.0, 0.0), |(t, p), x| (t + x.time_s / n, p + x.position_mm / n));
    let (stp, stt) = s.iter().fold((0.0, 0.0), |(a, b), x| (a + (x.time_s - mt) * (x.position_mm - mp), b + (x.time_s - mt).powi(2)));
    (stt > 0.0).then(|| stp / stt)
}

/// The force of a trial at rest before its stage moves: the sensor's zero and its noise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tare {
    /// The mean force over the samples before the stage moves, N.
    pub mean_n: f64,
    /// The noise band around it, N: [`CONTACT_SIGMAS`] standard deviations, at least
    /// [`CONTACT_FLOOR_N`].
    pub band_n: f64,
    /// The 1-based line of the trial's first sample (where the tare is read from).
    pub line: usize,
}

/// The tare of `rest`, the samples before the stage moves (at least one: [`phases`]
/// refuses a trial with fewer than two).
fn tare(rest: &[Sample]) -> Tare {
    let n = rest.len().max(1) as f64;
    let mean_n = rest.iter().map(|x| x.force_n).sum::<f64>() / n;
    let sd = (rest.iter().map(|x| (x.force_n - mean_n).powi(2)).sum::<f64>() / n).sqrt();
    Tare { mean_n, band_n: (CONTACT_SIGMAS * sd).max(CONTACT_FLOOR_N), line: rest.first().map_or(0, |x| x.line) }
}

/// Subtracts the tare of `p` from every force of `s` (the trial `what` cut into `p`)
/// when it lies beyond its noise band (a sensor not tared at the start, or tared under a
/// load), and says so in `p`'s notes, naming the file, the line and the force: every
/// force is then from the sensor's zero at rest, and the tare zero. A tare within its
/// band is the zero the rig set, to within the sensor's noise, and is left as it is (the
/// rig's trials: -0.011 to +0.014 N; their stacks, and the FE run of the shipped one,
/// unchanged).
pub fn remove_tare(s: &mut [Sample], p: &mut Phases, what: &str) {
    let Tare { mean_n, band_n, line } = p.tare;
    if mean_n.abs() <= band_n {
        return;
    }
    for x in s.iter_mut() {
        x.force_n -= mean_n;
    }
    p.notes.push(format!(
        "{what}:{line}: the force at rest before the stage moves averages {mean_n:+.4} N, beyond its noise (+-{band_n:.4} N): \
         subtracted from every sample as the sensor's zero"
    ));
    p.tare.mean_n = 0.0;
}

/// A trial whose stage starts further from zero than this, mm, is moved to start at
/// zero: an encoder's count and the servo's settling are far below it (the rig's trials
/// start at -0.009 to +0.012 mm).
pub const START_ZERO_MM: f64 = 0.05;

/// Moves every position of `s` (the trial `what`, cut into `p`) by the first sample's
/// when that lies further from zero than [`START_ZERO_MM`], so that the positions are the
/// stage's travel from where the trial started (the format's `position_mm`), whatever
/// the encoder read there, and says so in `p`'s notes (`FILE:LINE`, the position). The
/// phases and the contact are cut on differences of positions, so they are the same.
pub fn zero_travel(s: &mut [Sample], p: &mut Phases, what: &str) {
    let Some(&Sample { position_mm: start, line, .. }) = s.first() else { return };
    if start.abs() <= START_ZERO_MM {
        return;
    }
    for x in s.iter_mut() {
        x.position_mm -= start;
    }
    p.notes.push(format!(
        "{what}:{line}: the stage starts at {start} mm: every position moved by {:+} mm to be the travel from the start",
        -start
    ));
}

/// The first sample of `insertion` whose force is beyond the noise band of `tare` (the
/// samples before the stage moves).
fn contact(s: &[Sample], tare: &Tare, insertion: &Range<usize>) -> Option<usize> {
    let Tare { mean_n, band_n, .. } = *tare;
    // beyond the band and staying beyond it for the next samples (one spike is not a contact)
    let beyond = |k: usize| s.get(k).is_some_and(|x| x.force_n - mean_n > band_n);
    insertion.clone().find(|&k| (k..k + 5).all(beyond))
}
