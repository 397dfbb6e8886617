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
//! For given `(w, δ, r0, onset)` the force is linear in `s` (one least-squares
//! coefficient); `w` is scanned on [`SQRT_WEIGHTS`], the onset as
//! [`crate::fit`] scans it (at `δ = 0`, then within [`REFINE_MM`] of that onset with the
//! softening), `r0` on [`ONSET_RATIOS`]; `δ` follows from the force at the puncture, held to the measured peak ([`softened_fit`]). The curve of a
//! candidate is read from a table of `S_w` at [`TABLE_STEP_MM`], linearly interpolated.
use crate::measured::Point;
use needle_haptics::float::family::{ratio, FamilyMember};

/// The weights `w` scanned, as `sqrt(w)`: 0.1 to 1 by 0.05 (w 0.01 to 1, the members
/// the FE covers: below 0.01 the law is not fitted).
pub const SQRT_WEIGHTS: [f64; 19] =
    [0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45, 0.5, 0.55, 0.6, 0.65, 0.7, 0.75, 0.8, 0.85, 0.9, 0.95, 1.0];
/// The largest softening fraction a fit may give (the force at the puncture keeps at
/// least half the elastic one).
pub const MAX_FRACTION: f64 = 0.5;
/// The softening's onset ratios `r0` scanned.
pub const ONSET_RATIOS: [f64; 10] = [0.5, 0.55, 0.6, 0.65, 0.7, 0.75, 0.8, 0.85, 0.9, 0.95];
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
    pub const NONE: Self = Self { fraction: 0.0, onset_ratio: 1.0 };

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
    /// Sum of squared residuals over the fitted points, N².
    pub sse: f64,
}

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
/// unknown `b >= 0`. `(sse, s, δ)`, `None` when `S_w(d_p)` is not positive or `δ` would
/// not be below [`MAX_FRACTION`].
fn softened_fit(table: &Table, points: &[Point], onset: f64, d_p: f64, onset_ratio: f64, f_p: f64) -> Option<(f64, f64, f64)> {
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
    (fraction < MAX_FRACTION).then_some((sse, scale, fraction))
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
    let mut best: Option<ShapeFit> = None;
    for &t in sqrt_weights {
        let member = FamilyMember::new((t * t) as f32)?;
        let table = Table::new(surrogate, &member, similarity, span + TABLE_STEP_MM);
        let onsets = |lo: f64, hi: f64| {
            let n = ((hi - lo) / ONSET_STEP_MM).floor().max(0.0) as usize;
            (0..n).map(move |k| lo + ONSET_STEP_MM * k as f64)
        };
        let mut plain: Option<(f64, f64)> = None;
        for onset in onsets(first.position_mm, peak.position_mm) {
            let (_, sse) = scale_fit(&basis(&table, pre, onset, peak.position_mm - onset, Softening::NONE), pre);
            if plain.is_none_or(|(s, _)| sse < s) {
                plain = Some((sse, onset));
            }
        }
        let (_, centre) = plain?;
        let lo = (centre - REFINE_MM).max(first.position_mm);
        let hi = (centre + REFINE_MM).min(peak.position_mm);
        for onset_ratio in ONSET_RATIOS {
            for onset in onsets(lo, hi) {
                let d_p = peak.position_mm - onset;
                let Some(c) = softened_fit(&table, pre, onset, d_p, onset_ratio, peak.force_n) else { continue };
                if best.is_none_or(|b| c.0 < b.sse) {
                    let (sse, scale, fraction) = c;
                    let softening = Softening { fraction, onset_ratio };
                    let critical_force_n = scale * table.at(d_p);
                    best = Some(ShapeFit { onset_mm: onset, scale, weight: t * t, softening, critical_force_n, sse });
                }
            }
        }
    }
    best
}

/// The fitted force at needle position `p` (N): the module's law for `fit`.
#[must_use]
pub fn force_at(fit: &ShapeFit, surrogate: &dyn Fn(f64) -> f64, similarity: f64, peak_mm: f64, p: f64) -> f64 {
    let Some(member) = FamilyMember::new(fit.weight as f32) else { return f64::NAN };
    let sw = |d: f64| if d > 0.0 { surrogate(d) * f64::from(ratio((d / similarity) as f32, &member).0) } else { 0.0 };
    let at_peak = sw(peak_mm - fit.onset_mm);
    let v = sw(p - fit.onset_mm);
    let rho = if at_peak > 0.0 { v / at_peak } else { 0.0 };
    fit.scale * v * fit.softening.factor(rho)
}
