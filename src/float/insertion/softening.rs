//! [`Softening`]: a boundary's force flattening before its puncture (the tissue starting
//! to fail; issue 64, coeffs/README.md, "Tissue stacks").
//!
//! The boundary's axial force `F` (after the viscoelastic filter, plus the cutting force
//! carried onto it) is measured against the force that punctures it,
//! `F_crit = puncture_force_n / (1 - fraction)`, as `ρ = F / F_crit`. Above
//! `ρ = onset_ratio` the boundary's wrench loses a share that grows linearly to
//! `fraction` at `ρ = 1`, where it is punctured: the force just before the puncture is
//! `puncture_force_n`, reached where the elastic force reaches `F_crit`. Written once per
//! layer as [`SofteningTerms`] (no division per tick):
//! `factor = 1 - min(max((F - onset_n) slope_per_n, 0), fraction)`,
//! `onset_n = onset_ratio F_crit`, `slope_per_n = fraction / ((1 - onset_ratio) F_crit)`.
//! [`Softening::NONE`] (`fraction = 0`): `F_crit = puncture_force_n`, no factor: the
//! insertion without softening, bit for bit.

/// The pre-puncture softening of a boundary (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Softening {
    /// The share of the boundary's force lost at the puncture, `0 <= fraction <`
    /// [`Softening::FRACTION_MAX`] (0: none).
    pub fraction: f32,
    /// Where the loss starts, as a share of the force that punctures, `0 <= onset_ratio < 1`.
    pub onset_ratio: f32,
}

impl Softening {
    /// No softening.
    pub const NONE: Self = Self { fraction: 0.0, onset_ratio: 0.0 };
    /// The largest fraction a stack may give (the force at the puncture keeps at least
    /// half the elastic one).
    pub const FRACTION_MAX: f32 = needle_contract::SOFTENING_FRACTION_MAX as f32;

    /// Whether the values are in range (the tissue file's check, for a stack built at run
    /// time).
    #[must_use]
    pub fn is_valid(&self) -> bool {
        (0.0..Self::FRACTION_MAX).contains(&self.fraction) && (0.0..1.0).contains(&self.onset_ratio)
    }
}

// Only the `tissue-shape` feature's insertion reads them (its unit tests run either way).
#[cfg_attr(not(feature = "tissue-shape"), allow(dead_code))]
/// A layer's softening as the tick computes it (module docs), from
/// [`SofteningTerms::new`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct SofteningTerms {
    /// The force that punctures, N.
    pub(crate) critical_n: f32,
    onset_n: f32,
    slope_per_n: f32,
    fraction: f32,
}

#[cfg_attr(not(feature = "tissue-shape"), allow(dead_code))]
impl SofteningTerms {
    /// Nothing: a layer slot not in use.
    pub(crate) const NONE: Self = Self { critical_n: 0.0, onset_n: 0.0, slope_per_n: 0.0, fraction: 0.0 };

    /// The terms of a layer punctured at `puncture_force_n` (> 0) with `s`; `None` for a
    /// softening out of range ([`Softening::is_valid`]) or a force that is not finite and > 0.
    pub(crate) fn new(puncture_force_n: f32, s: &Softening) -> Option<Self> {
        if !(s.is_valid() && puncture_force_n.is_finite() && puncture_force_n > 0.0) {
            return None;
        }
        if s.fraction == 0.0 {
            return Some(Self { critical_n: puncture_force_n, ..Self::NONE });
        }
        // 1 - fraction > 1/2 and 1 - onset_ratio > 0 (is_valid)
        let critical_n = puncture_force_n / (1.0 - s.fraction);
        let span_n = (1.0 - s.onset_ratio) * critical_n;
        let slope_per_n = s.fraction / span_n;
        if !(critical_n.is_finite() && slope_per_n.is_finite()) {
            return None;
        }
        Some(Self { critical_n, onset_n: s.onset_ratio * critical_n, slope_per_n, fraction: s.fraction })
    }

    /// Whether the layer softens at all.
    #[inline]
    pub(crate) fn active(&self) -> bool {
        // `fraction > 0.0` on the bits: `new` stores `+0.0` or a positive fraction, so a
        // positive fraction is exactly nonzero bits (an integer test, not a float compare:
        // the M4F's loop tick)
        self.fraction.to_bits() != 0
    }

    /// `1 - D` at the boundary's axial force `force_n` (below `critical_n`): the loss
    /// `min(max(x, 0), fraction)` of `x = (F - onset) slope`, written as two compares
    /// (`f32::max` and `min` are calls into the float library on the Cortex-M4F, whose
    /// FPU has no min or max: about 25 instructions of a loop tick, issue 64). The same
    /// factor for every `x`: a NaN or `x <= 0` loses nothing (`1 - 0`, whatever the sign
    /// of a zero), above `fraction` the loss is `fraction`.
    #[inline]
    pub(crate) fn factor(&self, force_n: f32) -> f32 {
        let x = (force_n - self.onset_n) * self.slope_per_n;
        let loss = if x > 0.0 {
            if x < self.fraction {
                x
            } else {
                self.fraction
            }
        } else {
            0.0
        };
        1.0 - loss
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The factor against the module's law in f64, and its ends: 1 up to the onset, `1 -
    /// fraction` at the puncture force.
    #[test]
    fn the_factor_follows_the_law_and_reaches_the_puncture_force() {
        let s = Softening { fraction: 0.2, onset_ratio: 0.6 };
        let t = SofteningTerms::new(2.0, &s);
        assert!(t.is_some(), "a valid softening has terms");
        let Some(t) = t else { return };
        assert!((f64::from(t.critical_n) - 2.5).abs() < 1e-6, "F_crit = 2 / 0.8: {}", t.critical_n);
        for k in 0..=100 {
            let f = 2.5 * f64::from(k) / 100.0;
            let rho = f / 2.5;
            let want = 1.0 - 0.2 * ((rho - 0.6) / 0.4).clamp(0.0, 1.0);
            let got = f64::from(t.factor(f as f32));
            assert!((got - want).abs() < 1e-6, "F {f}: {got} vs {want}");
        }
        assert!((f64::from(t.critical_n * t.factor(t.critical_n)) - 2.0).abs() < 1e-6, "the force at the puncture is puncture_force_n");
        assert!(SofteningTerms::new(1.0, &Softening { fraction: 0.5, onset_ratio: 0.5 }).is_none(), "fraction at its maximum");
        assert!(SofteningTerms::new(1.0, &Softening { fraction: 0.1, onset_ratio: 1.0 }).is_none(), "onset at the puncture");
        assert!(SofteningTerms::new(1.0, &Softening { fraction: f32::NAN, onset_ratio: 0.5 }).is_none(), "NaN");
        assert_eq!(SofteningTerms::new(1.5, &Softening::NONE).map(|t| (t.critical_n, t.active())), Some((1.5, false)));
    }

    /// The factor's compares give the bits of `1 - min(max(x, 0), fraction)` for every
    /// kind of `x`: NaN, the infinities, both zeros, below and above the fraction.
    #[test]
    fn the_factor_is_the_min_max_form_bit_for_bit() {
        let terms = SofteningTerms::new(2.0, &Softening { fraction: 0.2, onset_ratio: 0.6 });
        assert!(terms.is_some(), "a valid softening has terms");
        let Some(t) = terms else { return };
        let forces = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 0.0, -0.0, 1.5, t.onset_n, 2.0, 2.4, t.critical_n, 3.0, 1e30, -1e30];
        let steps = (0..=1000).map(|k| k as f32 * 0.003);
        for f in forces.into_iter().chain(steps) {
            let want = 1.0 - ((f - t.onset_n) * t.slope_per_n).max(0.0).min(t.fraction);
            assert_eq!(t.factor(f).to_bits(), want.to_bits(), "F {f}");
        }
    }
}
