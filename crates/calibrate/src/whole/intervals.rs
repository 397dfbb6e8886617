//! The intervals between two punctures: after puncture `k` the tip cuts layer `k` (its
//! cutting force `c`) with the shaft's friction (known, from the withdrawals), and the
//! layer directly below deflects at once from its boundary `b` (scale `s` of the FE
//! surrogate), until it punctures. Per trial `b` is scanned and, for each candidate,
//! `c` and `s` are the least squares under the constraint that the model reaches the
//! measured puncture force at the measured puncture depth (`c + s u(d_peak - b) = P`,
//! `P` the peak less the friction there: the model punctures where the trial did).
use super::friction::{lengths, LayerFriction};
use super::trials::Trial;

/// Grid step of a boundary scan, mm.
pub const BOUNDARY_STEP_MM: f64 = 0.02;

/// What one trial's interval gave.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntervalFit {
    /// The next boundary's depth, mm.
    pub boundary_mm: f64,
    /// Its stiffness scale.
    pub scale: f64,
    /// The cutting force of the layer cut in the interval, N.
    pub cutting_n: f64,
    /// The next layer's puncture threshold (the peak less the friction), N.
    pub puncture_n: f64,
    /// The depth of the next puncture's peak, mm.
    pub peak_mm: f64,
}

/// The friction force at depth `d` for the punctured layers' `bounds` (the next boundary
/// at `next`), at speed `v`, N.
#[must_use]
pub fn friction_n(friction: &[LayerFriction], bounds: &[f64], next: f64, d: f64, v: f64) -> f64 {
    lengths(bounds, next, d).iter().zip(friction).map(|(l, f)| l * f.at(v)).sum()
}

/// The surrogate at `depth_mm` of indentation, zero before contact.
pub fn indent(u: &dyn Fn(f64) -> f64, depth_mm: f64) -> f64 {
    if depth_mm > 0.0 {
        u(depth_mm)
    } else {
        0.0
    }
}

/// Interval `k` of trial `t` (from puncture `k`'s bottom to puncture `k + 1`'s peak);
/// `bounds` the upper boundaries of layers `0..=k`. `None` when the trial has no
/// puncture `k + 1` or no candidate deflects.
#[must_use]
pub fn fit(t: &Trial, k: usize, bounds: &[f64], friction: &[LayerFriction], u: &dyn Fn(f64) -> f64) -> Option<IntervalFit> {
    let (e, next) = (t.events.get(k)?, t.events.get(k + 1)?);
    let onset = t.onset_mm();
    let v = t.phases.insertion_speed_mm_per_s;
    let rows: Vec<(f64, f64)> = t.points.get(e.bottom..=next.peak)?.iter().map(|p| (p.position_mm - onset, p.force_n)).collect();
    let &(d_peak, f_peak) = rows.last()?;
    let top = bounds.last().copied().unwrap_or(0.0);
    let lo = rows.first().map_or(top, |r| r.0).max(top);
    let mut best: Option<(f64, IntervalFit)> = None;
    let steps = ((d_peak - lo) / BOUNDARY_STEP_MM).floor().max(0.0) as usize;
    for i in 0..steps {
        let b = lo + BOUNDARY_STEP_MM * i as f64;
        let p = f_peak - friction_n(friction, bounds, b, d_peak, v);
        let r: Vec<(f64, f64)> = rows.iter().map(|&(d, f)| (indent(u, d - b), f - friction_n(friction, bounds, b, d, v))).collect();
        let Some((sse, scale, cutting)) = constrained(&r, indent(u, d_peak - b), p) else { continue };
        if best.as_ref().is_none_or(|(s, _)| sse < *s) {
            best = Some((sse, IntervalFit { boundary_mm: b, scale, cutting_n: cutting, puncture_n: p, peak_mm: d_peak }));
        }
    }
    best.map(|(_, f)| f)
}

/// `c + s u_i ≈ r_i` in least squares with `c + s u_p = p`, `c, s >= 0`; rows `(u_i,
/// r_i)`. `(sse, s, c)`, `None` when `p <= 0` or the boundary is not deflected at the
/// peak (`u_p <= 0`).
fn constrained(rows: &[(f64, f64)], u_p: f64, p: f64) -> Option<(f64, f64, f64)> {
    if p <= 0.0 || u_p <= 0.0 {
        return None;
    }
    let (num, den) = rows.iter().fold((0.0, 0.0), |(n, d), &(ui, ri)| {
        let w = ui - u_p;
        (n + (ri - p) * w, d + w * w)
    });
    let mut s = if den > 0.0 { (num / den).max(0.0) } else { 0.0 };
    let mut c = p - s * u_p;
    if c < 0.0 {
        c = 0.0;
        s = p / u_p;
    }
    if s <= 0.0 {
        return None;
    }
    let sse = rows.iter().map(|&(ui, ri)| (c + s * ui - ri).powi(2)).sum();
    Some((sse, s, c))
}
