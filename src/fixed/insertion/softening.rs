//! [`Softening`] in integers: the f32 layer's pre-puncture softening
//! ([`crate::float::insertion::Softening`], whose module states the law) converted once,
//! in `const` evaluation on the build host.
//!
//! Forces in µN Q16 as the rest of the fixed-point insertion. The loss at the boundary's
//! force `F` is `min(max(F - onset, 0), span) * slope >> 32` in Q30 (`span = (1 - r0)
//! F_crit`, `slope = fraction 2^62 / span`: the product stays below `fraction 2^62 <
//! 2^61`), at most `fraction` (Q30); the wrench is multiplied by `2^30 - loss` (Q30).
use crate::fixed::arith::scale_q30;
use crate::fixed::depth_extension::round_i64;
use crate::float::insertion as f32_insertion;

const Q16: f64 = 65536.0;
const Q30: f64 = (1u64 << 30) as f64;
const MICRO: f64 = 1.0e6;

/// A layer's softening in integers (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Softening {
    /// The boundary force that punctures, µN Q16 (the layer's puncture force without
    /// softening).
    pub critical_q16: i64,
    /// Where the loss starts, µN Q16; the span from it to the puncture is
    /// `critical_q16 - onset_q16` (module docs).
    pub onset_q16: i64,
    /// `fraction 2^62 / span` (module docs).
    pub slope: i64,
    /// The share lost at the puncture, Q30 (0: none; below 2^29). An `i32`: a compiled-in
    /// stack holds one softening per layer slot (flash, issue 64).
    pub fraction_q30: i32,
}

#[cfg_attr(not(feature = "tissue-shape"), allow(dead_code))]
impl Softening {
    /// A softening out of range (`critical_q16 = 0`, which [`Softening::in_range`] refuses;
    /// also the empty layer's).
    pub const REFUSED: Self = Self { critical_q16: 0, onset_q16: 0, slope: 0, fraction_q30: 0 };

    /// The f32 layer's softening, its force that punctures from `puncture_force_q16` (the
    /// layer's, already in µN Q16). `const`: the compiled-in stacks are converted at
    /// compile time. A softening out of range gives `critical_q16 = 0`, which
    /// [`Softening::in_range`] refuses.
    #[must_use]
    pub const fn from_f32(s: &f32_insertion::Softening, puncture_force_n: f32, puncture_force_q16: i64) -> Self {
        let (fraction, ratio) = (s.fraction as f64, s.onset_ratio as f64);
        if fraction == 0.0 {
            return Self { critical_q16: puncture_force_q16, onset_q16: 0, slope: 0, fraction_q30: 0 };
        }
        if !(fraction > 0.0 && fraction < f32_insertion::Softening::FRACTION_MAX as f64 && ratio >= 0.0 && ratio < 1.0) {
            return Self::REFUSED;
        }
        let critical_n = puncture_force_n as f64 / (1.0 - fraction);
        let critical_q16 = round_i64(critical_n * MICRO * Q16);
        let onset_q16 = round_i64(ratio * critical_n * MICRO * Q16);
        let span_q16 = critical_q16 - onset_q16;
        if span_q16 <= 0 {
            return Self::REFUSED;
        }
        let slope = round_i64(fraction * (1u64 << 62) as f64 / span_q16 as f64);
        // fraction < FRACTION_MAX (one half): below 2^29
        Self { critical_q16, onset_q16, slope, fraction_q30: round_i64(fraction * Q30) as i32 }
    }

    /// Whether the integers are sane: a positive force that punctures, and a fraction in
    /// `0 .. 2^29` (one half) with a positive span.
    #[must_use]
    pub fn in_range(&self) -> bool {
        self.critical_q16 > 0
            && (0..1 << 29).contains(&self.fraction_q30)
            && (self.fraction_q30 == 0 || (self.span_q16() > 0 && self.slope > 0 && self.onset_q16 >= 0))
    }

    /// The force from the start of the loss to the puncture, µN Q16.
    #[inline]
    fn span_q16(&self) -> i64 {
        self.critical_q16.saturating_sub(self.onset_q16)
    }

    /// Whether the layer softens at all.
    #[inline]
    pub(super) fn active(&self) -> bool {
        self.fraction_q30 > 0
    }

    /// `1 - D` in Q30 at the boundary's force `force_q16` (module docs).
    #[inline]
    pub(super) fn factor_q30(&self, force_q16: i64) -> i64 {
        // max then min, not clamp: a span below 0 (refused by `in_range`) must not panic
        let over = force_q16.saturating_sub(self.onset_q16).max(0).min(self.span_q16());
        // over <= span: over * slope <= fraction 2^62 < 2^61
        let loss = (over.saturating_mul(self.slope) >> 32).min(i64::from(self.fraction_q30));
        (1 << 30) - loss
    }

    /// Each component of `w` (Q16 forces and moments of any size) times `factor_q30`
    /// ([`scale_q30`]).
    #[inline]
    pub(super) fn apply(factor_q30: i64, w: &mut [i64; 6]) {
        scale_q30(w, factor_q30);
    }
}
