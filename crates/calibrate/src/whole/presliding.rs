//! The shaft's presliding from the trials (the library's `insertion::presliding`, issue
//! 65): its distance from each withdrawal's onset, and the arms of its relaxation along
//! a trial (the columns [`super::hold`] fits the shaft's Prony terms with).
//!
//! **Distance**: when the stage reverses, the model's held shaft force turns over
//! linearly within twice the presliding distance `p`, crossing its midpoint after `p`
//! of travel. Per trial: the force at the reversal (the mean of the
//! [`HOLD_AVERAGE_SAMPLES`] before it), the withdrawal's sliding level (its mean over
//! [`WITHDRAWAL_WINDOW_MM`] of stage travel), and the travel from the reversal to where
//! the force (a moving mean of as many samples) first reaches their midpoint; `p` is the
//! mean over the trials, clamped into the format's range, its standard error beside it.
use super::goals::{HOLD_AVERAGE_SAMPLES, WITHDRAWAL_WINDOW_MM};
use super::stats::Spread;
use super::trials::Trial;
use needle_codegen::tissue::PRESLIDING_MM_RANGE;

/// The library's tick, s (`InsertionConfig::DEFAULT_1KHZ`): the arms are stepped at it.
const TICK_S: f64 = 0.001;

fn mean(v: impl Iterator<Item = f64>) -> Option<f64> {
    let (s, n) = v.fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
    (n > 0).then(|| s / n as f64)
}

/// Trial `t`'s presliding distance from its withdrawal's onset (module docs), mm; `None`
/// without a withdrawal that pulls back past the midpoint.
#[must_use]
pub fn onset_distance(t: &Trial) -> Option<f64> {
    let w = t.phases.withdrawal.clone();
    let s = &t.samples;
    let start = s.get(w.start)?;
    let before = w.start.checked_sub(HOLD_AVERAGE_SAMPLES)?;
    let held = mean((before..w.start).filter_map(|i| s.get(i).map(|x| x.force_n)))?;
    let (lo, hi) = WITHDRAWAL_WINDOW_MM;
    let level = mean(w.clone().filter_map(|i| s.get(i)).filter(|x| (lo..=hi).contains(&x.position_mm)).map(|x| x.force_n))?;
    if level >= held {
        return None;
    }
    let mid = 0.5 * (held + level);
    let half = HOLD_AVERAGE_SAMPLES / 2;
    let moving = |i: usize| mean((i.saturating_sub(half)..i + half).filter(|j| w.contains(j)).filter_map(|j| s.get(j)).map(|x| x.force_n));
    let reached = w.clone().find(|&i| moving(i).is_some_and(|f| f <= mid))?;
    let travel = start.position_mm - s.get(reached)?.position_mm;
    (travel > 0.0).then_some(travel)
}

/// The presliding distance over the trials (module docs): their values, the mean clamped
/// into [`PRESLIDING_MM_RANGE`]; `None` when no trial has one.
#[must_use]
pub fn distance(trials: &[Trial]) -> Option<Spread> {
    let values: Vec<f64> = trials.iter().filter_map(onset_distance).collect();
    if values.is_empty() {
        return None;
    }
    let mut s = Spread::of(values);
    let (lo, hi) = PRESLIDING_MM_RANGE;
    s.mean = s.mean.clamp(lo, hi);
    Some(s)
}

/// The library's arms `z_i` (time constants `taus`, slip distances `slip_mm`) along trial
/// `t`'s measured position, one row per sample: stepped at the library's tick between
/// samples (the position linear between them), `z_i <- clamp(exp(-dt / tau_i) z_i + Δd /
/// p_i)`.
#[must_use]
pub fn arms(t: &Trial, taus: &[f64], slip_mm: &[f64]) -> Vec<Vec<f64>> {
    let decay: Vec<f64> = taus.iter().map(|tau| (-TICK_S / tau).exp()).collect();
    let mut z = vec![0.0; taus.len()];
    let mut out = Vec::with_capacity(t.samples.len());
    let mut last: Option<(f64, f64)> = None;
    for s in &t.samples {
        if let Some((t0, x0)) = last {
            let ticks = ((s.time_s - t0) / TICK_S).round().max(1.0);
            let step = (s.position_mm - x0) / ticks;
            for _ in 0..ticks as usize {
                for ((zi, a), p) in z.iter_mut().zip(&decay).zip(slip_mm) {
                    *zi = (a * *zi + step / p).clamp(-1.0, 1.0);
                }
            }
        }
        last = Some((s.time_s, s.position_mm));
        out.push(z.clone());
    }
    out
}
