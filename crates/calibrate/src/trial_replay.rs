//! A stack run through the library's f32 insertion model along a whole measured trial:
//! the tip's depth follows the trial's measured position against time (linear between
//! the samples, one tick per period of [`InsertionConfig::DEFAULT_1KHZ`]), so the model
//! sees the trial's insertion, hold and withdrawal at their measured speeds; the model's
//! force is read at each measured row (the tick nearest its time).
use crate::trial::Sample;
use needle_haptics::insertion::{Insertion, InsertionConfig, Phase, Stack};
use needle_haptics::Pose;

/// The model at one measured row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RowModel {
    /// Axial force of the model, N (positive resisting the insertion).
    pub force_n: f64,
    /// The model's phase at that tick.
    pub phase: Phase,
}

/// A puncture the model made.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModelPuncture {
    /// Time of the tick, s (the trial's clock).
    pub time_s: f64,
    /// Needle position (stage travel) at the tick, mm.
    pub position_mm: f64,
    /// The model's axial force of the tick before, N.
    pub force_n: f64,
}

/// The model along a trial.
#[derive(Debug, Clone, PartialEq)]
pub struct TrialReplay {
    /// One per measured row, in order.
    pub rows: Vec<RowModel>,
    /// The model's punctures, in order.
    pub punctures: Vec<ModelPuncture>,
}

/// Runs `stack` along the samples `s` with the tissue's surface at `onset_mm` of stage
/// travel (depth = position - onset; centred vertical needle).
///
/// # Errors
/// The library refuses the stack (the message of
/// [`InsertionError`](needle_haptics::insertion::InsertionError)), or `s` is empty.
pub fn replay(stack: &Stack<'_>, onset_mm: f64, s: &[Sample]) -> Result<TrialReplay, String> {
    let config = InsertionConfig::DEFAULT_1KHZ;
    let mut insertion = Insertion::new(stack, config).map_err(|e| format!("stack {:?}: {e}", stack.name))?;
    let (Some(first), Some(last)) = (s.first(), s.last()) else { return Err("no samples to replay".into()) };
    let period = f64::from(config.period_s);
    let ticks = ((last.time_s - first.time_s) / period).ceil().max(0.0) as usize;
    let mut rows = Vec::with_capacity(s.len());
    let mut punctures = Vec::new();
    let (mut next_row, mut segment, mut last_force) = (0usize, 0usize, 0.0f64);
    for k in 0..=ticks {
        let t = first.time_s + period * k as f64;
        while s.get(segment + 1).is_some_and(|b| b.time_s < t) {
            segment += 1;
        }
        let position = interpolate(s, segment, t);
        let e = insertion.step(&Pose { depth_mm: (position - onset_mm) as f32, ..Pose::default() });
        let force = f64::from(e.wrench.fy_n);
        for _ in 0..e.punctures {
            punctures.push(ModelPuncture { time_s: t, position_mm: position, force_n: last_force });
        }
        last_force = force;
        // every row whose time is nearest this tick
        while s.get(next_row).is_some_and(|r| r.time_s < t + 0.5 * period || k == ticks) {
            rows.push(RowModel { force_n: force, phase: e.phase });
            next_row += 1;
        }
    }
    Ok(TrialReplay { rows, punctures })
}

/// The position at time `t` between samples `k` and `k + 1` (clamped at the ends).
fn interpolate(s: &[Sample], k: usize, t: f64) -> f64 {
    match (s.get(k), s.get(k + 1)) {
        (Some(a), Some(b)) if t > a.time_s => {
            let w = ((t - a.time_s) / (b.time_s - a.time_s)).min(1.0);
            a.position_mm + w * (b.position_mm - a.position_mm)
        }
        (Some(a), _) => a.position_mm,
        _ => 0.0,
    }
}
