//! The shape of a boundary's force before its puncture (issue 64): the material family's
//! member and the pre-puncture softening, fitted with the contact onset and the scale.
//!
//! The boundary pushes back with
//! `F(d) = s S(d) g(d/λ, w) (1 - D(ρ))`, `ρ = S_w(d) / S_w(d_p)`,
//! `D = δ clamp((ρ - r0) / (1 - r0), 0, 1)`:
//! - `S(d)` the FE surrogate's axial force at indentation `d` (scale 1, the measured
//!   needle by geometric similarity `λ`), `g` the family's ratio law for the member of
//!   weight `w` ([`needle_haptics::float::family::ratio`], the library's own f32 code,
//!   at the FE depth `d/λ`), `S_w = S g`;
//! - the softening: the tissue starts to fail before it is punctured, so the force
//!   flattens over the last part of the rise. `ρ` is how far the elastic force is
//!   towards the one that punctures (`S_w(d_p)`, at the measured puncture depth `d_p`);
//!   above `r0` the force loses up to the fraction `δ` at the puncture. The boundary is
//!   punctured when its elastic force reaches `s S_w(d_p)`: the puncture lands at the
//!   measured depth whatever `δ`, and the force there is `s S_w(d_p) (1 - δ)`.
//!   `δ = 0` is no softening (a stack's default).
//!
//! For given `(w, r0, onset)` the force is linear in its unknowns, with the force at
//! the puncture held to the measured peak (`s (1 - δ) S_w(d_p) = F_p`): one
//! least-squares unknown `b = s δ` (the force is `F_p S_w / S_p + b S_w (1 - x(ρ))`).
//! `w` is scanned on [`SQRT_WEIGHTS`], `r0` on [`ONSET_RATIOS`], the onset on a grid of
//! [`ONSET_STEP_MM`] (at `δ = 0` over the whole rise, then within [`REFINE_MM`] of that
//! onset with the softening); the fit is the best candidate whose contact onset matches
//! the measured one within [`ONSET_MATCH_MM`] (the best of all when none does). A
//! candidate's curve is read from a table of `S_w` at [`TABLE_STEP_MM`], linearly
//! interpolated.
use crate::measured::Point;
use needle_haptics::float::family::{ratio, FamilyMember};

/// The weights `w` scanned, as `sqrt(w)`: 0.1 to 1 by 0.05 (w 0.01 to 1, the members
/// the FE covers: below 0.01 the law is not fitted).
pub const SQRT_WEIGHTS: [f64; 19] =
    [0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45, 0.5, 0.55, 0.6, 0.65, 0.7, 0.75, 0.8, 0.85, 0.9, 0.95, 1.0];
/// The largest softening fraction a fit may give (exclusive; the tissue format's and
/// the library's bound).
pub const MAX_FRACTION: f64 = needle_contract::SOFTENING_FRACTION_MAX;
/// The softening's onset ratios `r0` scanned.
pub const ONSET_RATIOS: [f64; 10] = [0.5, 0.55, 0.6, 0.65, 0.7, 0.75, 0.8, 0.85, 0.9, 0.95];
/// The fit is the least-squares best among the candidates whose model curve crosses the
/// onset threshold ([`crate::replay::ONSET_FRACTION`] of the puncture force) within this
/// distance of the measured curve's crossing, mm (the best of all when none does):
/// contact onset is a goal of its own (`needle calibrate`'s checks), which the least
/// squares, weighted by the larger forces, would trade away.
pub const ONSET_MATCH_MM: f64 = 0.25;
/// How far after the measured peak the model's puncture may be placed, mm: the force at
/// the puncture is the measured peak's, where the model punctures; a puncture a little
/// late lets the rise follow the measured one (a digitised or noisy peak), within the
/// puncture position's goal of 0.3 mm (issue 64).
pub const PUNCTURE_LATE_MM: [f64; 3] = [0.0, 0.1, 0.2];
/// Sampling of the `S_w` tables, mm of indentation.
pub const TABLE_STEP_MM: f64 = 0.005;
/// Half width of the onset's refinement with the softening, mm.
pub const REFINE_MM: f64 = 0.5;
/// Onset step, mm.
pub const ONSET_STEP_MM: f64 = 0.01;

/// The pre-puncture softening of a boundary (module docs): `fraction` = `δ`,
/// `onset_ratio` = `r0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Softening {
    /// The force lost at the puncture, as a fraction of the elastic force (0: none).
    pub fraction: f64,
    /// Where the loss starts, as a fraction of the elastic force at the puncture.
    pub onset_ratio: f64,
}

impl Softening {
    /// No softening.
    pub const NONE: Self = Self { fraction: 0.0, onset_ratio: 0.0 };

    /// `1 - D(ρ)`.
    #[must_use]
    pub fn factor(&self, rho: f64) -> f64 {
        if self.fraction <= 0.0 || rho <= self.onset_ratio {
            return 1.0;
        }
        let span = 1.0 - self.onset_ratio;
        let x = if span > 0.0 { ((rho - self.onset_ratio) / span).min(1.0) } else { 1.0 };
        1.0 - self.fraction * x
    }
}

/// The fitted shape of the first boundary.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShapeFit {
    /// Needle position at contact, mm.
    pub onset_mm: f64,
    /// The stiffness scale `s`.
    pub scale: f64,
    /// The family member's weight `w`.
    pub weight: f64,
    /// The softening.
    pub softening: Softening,
    /// The elastic force that punctures, `s S_w(d_p)`, N.
    pub critical_force_n: f64,
    /// Needle position where the model punctures, mm: the measured peak's, or up to the
    /// largest of [`PUNCTURE_LATE_MM`] after it.
    pub puncture_mm: f64,
    /// Sum of squared residuals over the fitted points, N².
    pub sse: f64,
    /// The weights of every candidate within [`RANGE_SSE_RATIO`] of the best's sum of
    /// squares: the fitted range of `weight`, `[low, high]`.
    pub weight_range: [f64; 2],
    /// The fitted range of the softening's fraction, as `weight_range`.
    pub fraction_range: [f64; 2],
    /// The weight of the candidate with the least sum of squares, whatever its class
    /// (the fit keeps a simpler class within [`RANGE_SSE_RATIO`]): whether the data pin
    /// the paper's tissue (`w = 1`, the range's edge: [`crate::edges`]).
    pub least_squares_weight: f64,
}

impl ShapeFit {
    /// The candidate's class, simplest first: 0 the paper's tissue without softening, 1
    /// with softening, 2 another member without, 3 another member with softening. The
    /// fit is the simplest class within [`RANGE_SSE_RATIO`] of the best (a term is kept
    /// only when the data ask for it: Okamura's liver stays the paper's tissue).
    #[must_use]
    pub fn class(&self) -> usize {
        usize::from(self.weight < 1.0) * 2 + usize::from(self.softening.fraction > 0.0)
    }
}

/// A candidate whose sum of squares is within this ratio of the best's counts towards a
/// value's fitted range (its RMS within about 5 % of the best's): the measurement's
/// residuals are correlated over depth (the shape, not noise), so a statistical interval
/// from the point count would be far too narrow.
pub const RANGE_SSE_RATIO: f64 = 1.1;

/// `S_w` at `TABLE_STEP_MM` from 0 to `max_mm`.
struct Table {
    values: Vec<f64>,
}

impl Table {
    fn new(surrogate: &dyn Fn(f64) -> f64, member: &FamilyMember, similarity: f64, max_mm: f64) -> Self {
        let n = (max_mm / TABLE_STEP_MM).ceil().max(1.0) as usize + 2;
        let values = (0..n)
            .map(|i| {
                let d = i as f64 * TABLE_STEP_MM;
                let g = f64::from(ratio((d / similarity) as f32, member).0);
                surrogate(d) * g
            })
            .collect();
        Self { values }
    }

    /// The first depth where the table reaches `value` (linearly interpolated), `None`
    /// when it never does.
    fn crossing(&self, value: f64) -> Option<f64> {
        let i = self.values.iter().position(|v| *v >= value)?;
        let Some(prev) = i.checked_sub(1).and_then(|j| self.values.get(j)) else { return Some(0.0) };
        let next = self.values.get(i)?;
        let t = if next > prev { (value - prev) / (next - prev) } else { 0.0 };
        Some((i as f64 - 1.0 + t) * TABLE_STEP_MM)
    }

    fn at(&self, d: f64) -> f64 {
        if d <= 0.0 {
            return 0.0;
        }
        let x = d / TABLE_STEP_MM;
        let i = x.floor() as usize;
        match (self.values.get(i), self.values.get(i + 1)) {
            (Some(a), Some(b)) => a + (b - a) * (x - i as f64),
            _ => self.values.last().copied().unwrap_or(0.0),
        }
    }
}

/// The candidate's curve at the points (`s = 1`).
fn basis(table: &Table, points: &[Point], onset: f64, peak_depth: f64, soft: Softening) -> Vec<f64> {
    let at_peak = table.at(peak_depth);
    points
        .iter()
        .map(|p| {
            let sw = table.at(p.position_mm - onset);
            let rho = if at_peak > 0.0 { sw / at_peak } else { 0.0 };
            sw * soft.factor(rho)
        })
        .collect()
}

/// `(s, sse)` of the least squares `s b ≈ f`, `s >= 0`.
fn scale_fit(b: &[f64], points: &[Point]) -> (f64, f64) {
    let (mut bb, mut bf, mut ff) = (0.0, 0.0, 0.0);
    for (x, p) in b.iter().zip(points) {
        bb += x * x;
        bf += x * p.force_n;
        ff += p.force_n * p.force_n;
    }
    if bb <= 0.0 || bf <= 0.0 {
        return (0.0, ff);
    }
    let s = bf / bb;
    (s, (ff - s * bf).max(0.0))
}

/// The softened candidate with the force at the puncture held to the measured peak
/// `f_p`: with `a = s`, `b = s δ` and `s (1 - δ) S_w(d_p) = f_p`, the force is
/// `f_p S_w / S_p + b S_w (1 - x(ρ))` (`x` the softening's ramp): one least-squares
/// unknown `b >= 0`. `(sse, s, δ, sse at δ = 0)`, `None` when `S_w(d_p)` is not positive or `δ` would
/// not be below [`MAX_FRACTION`].
fn softened_fit(table: &Table, points: &[Point], onset: f64, d_p: f64, onset_ratio: f64, f_p: f64) -> Option<(f64, f64, f64, f64)> {
    let s_p = table.at(d_p);
    if s_p <= 0.0 || f_p <= 0.0 {
        return None;
    }
    let ramp = Softening { fraction: 1.0, onset_ratio };
    let (mut cc, mut cr, mut rr) = (0.0, 0.0, 0.0);
    for p in points {
        let sw = table.at(p.position_mm - onset);
        let base = f_p * sw / s_p;
        // S_w (1 - x), the column of b (the ramp's factor with fraction 1 is 1 - x)
        let c = sw * ramp.factor(sw / s_p);
        let r = p.force_n - base;
        cc += c * c;
        cr += c * r;
        rr += r * r;
    }
    let b = if cc > 0.0 { (cr / cc).max(0.0) } else { 0.0 };
    let sse = (rr - 2.0 * b * cr + b * b * cc).max(0.0);
    let scale = b + f_p / s_p;
    let fraction = b / scale;
    (fraction < MAX_FRACTION).then_some((sse, scale, fraction, rr))
}

/// Fits the shape of the rise `pre` (contact to the first puncture's peak, the last
/// point the peak). `surrogate(d)` is the axial force at indentation `d` with scale 1 at
/// the measured needle (as [`crate::fit::fit`] takes it), `similarity` the needle's
/// `λ`. `None` when `pre` has fewer than 3 points or no candidate fits a positive scale.
#[must_use]
pub fn fit(pre: &[Point], surrogate: &dyn Fn(f64) -> f64, similarity: f64) -> Option<ShapeFit> {
    fit_members(pre, surrogate, similarity, &SQRT_WEIGHTS)
}

/// [`fit`] over the members `sqrt_weights` (each `sqrt(w)`, in `0..=1`) only.
#[must_use]
pub fn fit_members(pre: &[Point], surrogate: &dyn Fn(f64) -> f64, similarity: f64, sqrt_weights: &[f64]) -> Option<ShapeFit> {
    let (first, peak) = (pre.first()?, pre.last()?);
    if pre.len() < 3 {
        return None;
    }
    let span = peak.position_mm - first.position_mm;
    let threshold = crate::replay::ONSET_FRACTION * peak.force_n;
    let measured_crossing = crate::replay::measured_onset(pre, pre.len() - 1, threshold);
    // every candidate's (sse, weight, fraction), for the fitted ranges
    let mut seen: Vec<(f64, f64, f64)> = Vec::new();
    // per class (ShapeFit::class) the best of all and the best whose contact onset
    // matches the measured one
    let (mut best, mut matched): ([Option<ShapeFit>; 4], [Option<ShapeFit>; 4]) = ([None; 4], [None; 4]);
    for &t in sqrt_weights {
        let member = FamilyMember::new((t * t) as f32)?;
        let table = Table::new(surrogate, &member, similarity, span + PUNCTURE_LATE_MM[PUNCTURE_LATE_MM.len() - 1] + TABLE_STEP_MM);
        let onsets = |lo: f64, hi: f64| {
            let n = ((hi - lo) / ONSET_STEP_MM).floor().max(0.0) as usize;
            (0..n).map(move |k| lo + ONSET_STEP_MM * k as f64)
        };
        // the unsoftened scan's best onset (among those matching the measured onset, when
        // any does): the centre of the softened scan
        let mut plain: Option<(f64, f64)> = None;
        let mut plain_matched: Option<(f64, f64)> = None;
        for onset in onsets(first.position_mm, peak.position_mm) {
            let (scale, sse) = scale_fit(&basis(&table, pre, onset, peak.position_mm - onset, Softening::NONE), pre);
            if plain.is_none_or(|(s, _)| sse < s) {
                plain = Some((sse, onset));
            }
            let crossing = (scale > 0.0).then(|| table.crossing(threshold / scale)).flatten().map(|d| onset + d);
            let near = matches!((crossing, measured_crossing), (Some(c), Some(m)) if (c - m).abs() <= ONSET_MATCH_MM);
            if near && plain_matched.is_none_or(|(s, _)| sse < s) {
                plain_matched = Some((sse, onset));
            }
        }
        let Some((_, centre)) = plain_matched.or(plain) else { continue };
        let lo = (centre - REFINE_MM).max(first.position_mm);
        let hi = (centre + REFINE_MM).min(peak.position_mm);
        for (late, onset_ratio) in PUNCTURE_LATE_MM.iter().flat_map(|l| ONSET_RATIOS.iter().map(move |r| (*l, *r))) {
            for onset in onsets(lo, hi) {
                let d_p = peak.position_mm + late - onset;
                let Some((sse, scale, fraction, plain_sse)) = softened_fit(&table, pre, onset, d_p, onset_ratio, peak.force_n) else {
                    continue;
                };
                seen.push((sse, t * t, fraction));
                let crossing = |scale: f64| table.crossing(threshold / scale).map(|d| onset + d);
                let near =
                    |scale: f64| matches!((crossing(scale), measured_crossing), (Some(c), Some(m)) if (c - m).abs() <= ONSET_MATCH_MM);
                // the candidate and the same without softening (through the peak: s = F_p / S_w(d_p))
                let unsoftened = (plain_sse, peak.force_n / table.at(d_p), 0.0);
                for (sse, scale, fraction) in [(sse, scale, fraction), unsoftened] {
                    let candidate = ShapeFit {
                        onset_mm: onset,
                        scale,
                        weight: t * t,
                        softening: if fraction > 0.0 { Softening { fraction, onset_ratio } } else { Softening::NONE },
                        critical_force_n: scale * table.at(d_p),
                        puncture_mm: peak.position_mm + late,
                        sse,
                        weight_range: [t * t; 2],
                        fraction_range: [fraction; 2],
                        least_squares_weight: t * t,
                    };
                    // the onset threshold is below every onset ratio: the model's crossing is elastic
                    let pool = if near(scale) { &mut matched } else { &mut best };
                    let slot = &mut pool[candidate.class()];
                    if slot.is_none_or(|b| sse < b.sse) {
                        *slot = Some(candidate);
                    }
                }
            }
        }
    }
    choose(matched, best, &seen)
}

/// The fit among the candidates of each class: those whose onset matches when any does;
/// among them the simplest class within [`RANGE_SSE_RATIO`] of the best, with the fitted
/// ranges of `seen` (every candidate's `(sse, weight, fraction)`).
fn choose(matched: [Option<ShapeFit>; 4], best: [Option<ShapeFit>; 4], seen: &[(f64, f64, f64)]) -> Option<ShapeFit> {
    let pool = if matched.iter().any(Option::is_some) { matched } else { best };
    let least = pool.iter().flatten().map(|c| c.sse).fold(f64::INFINITY, f64::min);
    let limit = least * RANGE_SSE_RATIO;
    let least_squares_weight = pool.iter().flatten().find(|c| c.sse <= least).map_or(1.0, |c| c.weight);
    let mut fit = pool.into_iter().flatten().find(|c| c.sse <= limit)?;
    fit.least_squares_weight = least_squares_weight;
    for &(_, w, fraction) in seen.iter().filter(|c| c.0 <= limit) {
        fit.weight_range = [fit.weight_range[0].min(w), fit.weight_range[1].max(w)];
        fit.fraction_range = [fit.fraction_range[0].min(fraction), fit.fraction_range[1].max(fraction)];
    }
    Some(fit)
}

/// The fitted force at needle position `p` (N): the module's law for `fit`.
#[must_use]
pub fn force_at(fit: &ShapeFit, surrogate: &dyn Fn(f64) -> f64, similarity: f64, p: f64) -> f64 {
    let peak_mm = fit.puncture_mm;
    let Some(member) = FamilyMember::new(fit.weight as f32) else { return f64::NAN };
    let sw = |d: f64| if d > 0.0 { surrogate(d) * f64::from(ratio((d / similarity) as f32, &member).0) } else { 0.0 };
    let at_peak = sw(peak_mm - fit.onset_mm);
    let v = sw(p - fit.onset_mm);
    let rho = if at_peak > 0.0 { v / at_peak } else { 0.0 };
    fit.scale * v * fit.softening.factor(rho)
}
