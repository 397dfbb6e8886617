//! The quasi-linear viscoelastic filter ([`crate::float::viscoelastic`]: the same
//! normalisation and recursion) in integers, for cores without an FPU.
//!
//! - Terms ([`PronyTerms`]): `g` in Q16 (`i32`), `tau` in whole µs (`u32`, clamped to
//!   [`TAU_MAX_US`], 71.6 min: a slower term relaxes in fixed point as one of 71.6 min
//!   would), converted from the f32 terms in `const` evaluation ([`PronyTerms::from_f32`]).
//!   32-bit fields: every layer slot of every compiled-in stack carries them (flash).
//! - Coefficients ([`QlvCoefficients::new`], once per configuration, integers only):
//!   `x = period / tau` in Q32, `e = exp(-x)` in Q32 (`exp(-1)^floor(x)` times the Taylor
//!   series of the fraction, in `u64`), `a = e` in Q30 and `b = g (1 - e) / x` in Q27
//!   (`(1 - e) / x` by its own series below `x = 1`: no cancellation; `b <= g <= 9`:
//!   below 2^30.2).
//! - The state and the filtered values are µN (or µN·mm) in Q16, `i64`, as the
//!   fixed-point insertion's forces; a tick is, per term and component,
//!   `h <- a h / 2^30 + b d / 2^27` with `d` the input's change over the tick, each
//!   product split as `x = hi 2^16 + lo` so that none exceeds 2^62: `hi` and the change
//!   are clamped to `i32` (2,147 N), where the insertion's output saturates anyway.
//!   Floor rounding: a relaxed term ends within 1 unit of Q16 µN of zero.

use needle_contract::COMPONENT_COUNT;

use super::arith::div_u64;
use super::depth_extension::round_i64;

#[cfg(not(feature = "viscoelastic"))]
pub(crate) mod identity;
use crate::float::viscoelastic::{PronyTerms as F32PronyTerms, MAX_TERMS};

/// Largest time constant, µs (`u32::MAX`: 71.6 min; a longer one is clamped here).
pub const TAU_MAX_US: u32 = u32::MAX;

/// A relaxation function in integers: `g` in Q16 (`0 ..= 9 * 2^16`), `tau` in µs
/// (`1 ..= TAU_MAX_US`); the first `count` are used.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PronyTerms {
    /// Weights relative to the long-term response, Q16.
    pub g_q16: [i32; MAX_TERMS],
    /// Time constants, µs.
    pub tau_us: [u32; MAX_TERMS],
    /// Terms in use (0 to [`MAX_TERMS`]).
    pub count: u8,
}

impl PronyTerms {
    /// No terms: elastic.
    pub const NONE: Self = Self { g_q16: [0; MAX_TERMS], tau_us: [0; MAX_TERMS], count: 0 };

    /// The f32 terms (checked by their constructor) in integers, rounded to nearest;
    /// `const`: the compiled-in stacks are converted at compile time.
    #[must_use]
    pub const fn from_f32(p: &F32PronyTerms) -> Self {
        let (terms, count) = p.as_array();
        let [t0, t1, t2] = terms;
        Self { g_q16: [q16(t0.g), q16(t1.g), q16(t2.g)], tau_us: [micro(t0.tau_s), micro(t1.tau_s), micro(t2.tau_s)], count }
    }

    /// Whether the terms are within the ranges the integer products are argued for
    /// (`Insertion::new` refuses others).
    #[must_use]
    pub fn in_range(&self) -> bool {
        let n = usize::from(self.count);
        let g_max = 9 << 16;
        n <= MAX_TERMS
            && self.g_q16.iter().zip(&self.tau_us).take(n).all(|(&g, &t)| (0..=g_max).contains(&g) && t >= 1)
            && self.g_q16.iter().take(n).map(|&g| i64::from(g)).sum::<i64>() <= i64::from(g_max)
    }
}

/// `v` in Q16, within `0 ..= 9 * 2^16` (the f32 terms' range: `0 <= g <= 9`).
const fn q16(v: f32) -> i32 {
    let q = round_i64(v as f64 * 65536.0);
    if q < 0 {
        0
    } else if q > 9 << 16 {
        9 << 16
    } else {
        q as i32
    }
}

/// `v` s in whole µs, within `1 ..= TAU_MAX_US` (`0` for a value that is not > 0,
/// which the f32 terms never hold).
const fn micro(v: f32) -> u32 {
    let us = v as f64 * 1.0e6;
    if us.is_nan() || us <= 0.0 {
        0
    } else if us >= TAU_MAX_US as f64 {
        TAU_MAX_US
    } else if us < 1.0 {
        1
    } else {
        // below 2^32 (checked above)
        round_i64(us) as u32
    }
}

/// The per-tick coefficients in integers: `a` Q30, `b` Q27 (unused terms 0).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct QlvCoefficients {
    a_q30: [i32; MAX_TERMS],
    b_q27: [i32; MAX_TERMS],
    count: u8,
}

const ONE_Q32: u64 = 1 << 32;

/// `sum_n (-r)^n / ((n + s)! / s!)` in Q32 for `r` in Q32 (`0 <= r <= 2^32`): `exp(-r)`
/// for `s = 0`, `(1 - exp(-r)) / r` for `s = 1`. Sixteen terms (truncation below
/// `1/16! < 2^-44`), positive and negative ones summed apart in `u64` (every term at
/// most 2^32, every product below 2^64), each rounded down (error a few 2^-32). Out of
/// line: one copy for its three uses (on the M0 the fixed-point insertion image with the
/// filter 24,418 -> 24,104 B).
#[inline(never)]
fn alternating_series_q32(r_q32: u64, s: u64) -> u64 {
    let (mut term, mut plus, mut minus) = (ONE_Q32, ONE_Q32, 0_u64);
    for n in 1..=16_u64 {
        // term <= 2^32 and r <= 2^32: the product at most 2^64 (saturating there: 1 unit)
        term = div_u64(term.saturating_mul(r_q32) >> 32, n + s).unwrap_or(0);
        if n % 2 == 1 {
            minus += term;
        } else {
            plus += term;
        }
    }
    plus.saturating_sub(minus)
}

/// `exp(-x)` in Q32 for `x` in Q32 (`x >= 0`): `exp(-1)^k exp(-r)` with `x = k + r`
/// (each product of `e <= 2^32 + 16`, the series' rounding, and `exp(-1) < 0.37 * 2^32`
/// is below 2^63: a plain `u64` product, no saturation test, which cost 362 B on the M0).
fn exp_neg_q32(x_q32: u64) -> u64 {
    let k = x_q32 >> 32;
    // exp(-23) < 2^-33: zero in Q32
    if k >= 23 {
        return 0;
    }
    let inv_e = alternating_series_q32(ONE_Q32, 0);
    let mut e = alternating_series_q32(x_q32 & 0xffff_ffff, 0);
    for _ in 0..k {
        e = e.wrapping_mul(inv_e) >> 32;
    }
    e
}

impl QlvCoefficients {
    /// No terms: the filter passes its input.
    pub const NONE: Self = Self { a_q30: [0; MAX_TERMS], b_q27: [0; MAX_TERMS], count: 0 };

    /// `a = exp(-period / tau)` (Q30) and `b = g (1 - a) / (period / tau)` (Q27) for a
    /// tick of `period_us` µs, in integers; `None` for terms out of range
    /// ([`PronyTerms::in_range`]) or a zero period.
    #[must_use]
    pub fn new(terms: &PronyTerms, period_us: u32) -> Option<Self> {
        if !terms.in_range() || period_us == 0 {
            return None;
        }
        let mut out = Self { count: terms.count, ..Self::NONE };
        let n = usize::from(terms.count);
        for (((a, b), &g), &tau) in out.a_q30.iter_mut().zip(out.b_q27.iter_mut()).zip(&terms.g_q16).zip(&terms.tau_us).take(n) {
            // tau >= 1 (in_range): x = period / tau in Q32, below 2^64
            let x_q32 = div_u64(u64::from(period_us) << 32, u64::from(tau))?;
            let e = exp_neg_q32(x_q32);
            // a <= 2^30 (e <= 2^32): fits i32
            *a = i32::try_from((e + 2) >> 2).ok()?;
            // phi = (1 - e) / x in Q32: its series below x = 1 (no cancellation), else the
            // quotient (1 - e >= 0.63; (1 - e) 2^32 below 2^64, x >= 2^32)
            let phi_q32 =
                if x_q32 < ONE_Q32 { alternating_series_q32(x_q32, 1) } else { div_u64((ONE_Q32 - e.min(ONE_Q32)) << 32, x_q32)? };
            // b = g phi in Q27: g (Q16, <= 9 * 2^16) times phi (<= 2^32) below 2^52
            let g = u64::try_from(g).ok()?;
            *b = i32::try_from((g * phi_q32 + (1 << 20)) >> 21).ok()?;
        }
        Some(out)
    }

    /// Whether there is any term.
    #[must_use]
    pub fn is_active(&self) -> bool {
        self.count > 0
    }

    /// One component, µN Q16: `h <- a h + b d`, out `elastic + sum h`.
    #[inline]
    fn step_one(&self, state: &mut [i64; 1 + MAX_TERMS], elastic_q16: i64) -> i64 {
        let [last, h0, h1, h2] = state;
        let d = split(elastic_q16.saturating_sub(*last));
        *last = elastic_q16;
        let mut out = elastic_q16;
        for ((h, &a), &b) in [h0, h1, h2].into_iter().zip(&self.a_q30).zip(&self.b_q27) {
            *h = mul_split(split(*h), i64::from(a), 30).wrapping_add(mul_split(d, i64::from(b), 27));
            out = out.saturating_add(*h);
        }
        out
    }
}

/// `x = hi 2^16 + lo` with `0 <= lo < 2^16` and `hi` clamped to `i32`.
fn split(x: i64) -> (i64, i64) {
    ((x >> 16).clamp(i64::from(i32::MIN), i64::from(i32::MAX)), x & 0xffff)
}

/// `floor(hi c / 2^(s - 16)) + floor(lo c / 2^s)` for `|hi| <= 2^31`, `0 <= c < 2^31`
/// and `s` 27 or 30: no product reaches 2^62.
fn mul_split((hi, lo): (i64, i64), c: i64, s: u32) -> i64 {
    ((hi * c) >> (s - 16)) + ((lo * c) >> s)
}

/// The filter state of a wrench's six components (`[fx, fy, fz, mx, my, mz]`, µN and
/// µN·mm in Q16): per component `[last input, h_0, h_1, h_2]`; at rest when zero.
///
/// Held ticks ([`hold`](Self::hold)) as the f32 state's
/// ([`crate::float::viscoelastic::QlvState`], "Held ticks"): each term relaxes over the
/// held input, and the next step takes the input's change as a ramp over the `n` ticks
/// since the last step, `b` times the ramp's weight `r = (1 + a + ... + a^(n-1)) / n`
/// (Q30, kept per term by `r <- (a r n + 1) / (n + 1)` at each held tick, rounded down:
/// `a r n < 2^62`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct QlvState {
    state: [[i64; 1 + MAX_TERMS]; COMPONENT_COUNT],
    /// Ticks held since the last step.
    held: u32,
    /// Per term the ramp's weight `r`, Q30 (valid while `held > 0`).
    ramp_q30: [u32; MAX_TERMS],
}

impl QlvState {
    /// At rest.
    pub const REST: Self = Self { state: [[0; 1 + MAX_TERMS]; COMPONENT_COUNT], held: 0, ramp_q30: [0; MAX_TERMS] };

    /// One tick of every component: the elastic wrench (Q16) in, the viscoelastic one
    /// out (after held ticks, the input's change as a ramp over them). Without terms the
    /// input is returned and the state left at rest.
    pub fn step(&mut self, coefficients: &QlvCoefficients, elastic_q16: [i64; COMPONENT_COUNT]) -> [i64; COMPONENT_COUNT] {
        if !coefficients.is_active() {
            return elastic_q16;
        }
        if self.held == 0 {
            return self.filter(coefficients, elastic_q16);
        }
        self.held = 0;
        let mut ramped = *coefficients;
        let n = usize::from(coefficients.count);
        for (b, &r) in ramped.b_q27.iter_mut().zip(&self.ramp_q30).take(n) {
            // b < 2^31, r <= 2^30: the product below 2^61, the result at most b
            *b = ((i64::from(*b) * i64::from(r)) >> 30) as i32;
        }
        self.filter(&ramped, elastic_q16)
    }

    /// The six components' recursion.
    #[inline(never)]
    fn filter(&mut self, coefficients: &QlvCoefficients, elastic_q16: [i64; COMPONENT_COUNT]) -> [i64; COMPONENT_COUNT] {
        let mut out = elastic_q16;
        for (o, s) in out.iter_mut().zip(self.state.iter_mut()) {
            *o = coefficients.step_one(s, *o);
        }
        out
    }

    /// One tick with the input unknown (the type's held ticks): each term relaxes over
    /// the input held at the last tick's, `h <- a h / 2^30` (the step's own product: its
    /// change is zero), so the state follows time. Without terms nothing changes.
    pub fn hold(&mut self, coefficients: &QlvCoefficients) {
        if !coefficients.is_active() {
            return;
        }
        let _ = self.filter(coefficients, self.state.map(|s| s[0]));
        if self.held == 0 {
            self.ramp_q30 = [1 << 30; MAX_TERMS];
        }
        let n = u64::from(self.held) + 1;
        self.held = self.held.saturating_add(1);
        let terms = usize::from(coefficients.count);
        for (r, &a) in self.ramp_q30.iter_mut().zip(&coefficients.a_q30).take(terms) {
            // a, r <= 2^30: a r / 2^30 <= 2^30, times n < 2^32: below 2^62; the mean of
            // weights at most 1 stays at most 2^30
            let ar = (u64::from(a.unsigned_abs()) * u64::from(*r)) >> 30;
            *r = u32::try_from(div_u64(ar * n + (1 << 30), n + 1).unwrap_or(0)).unwrap_or(1 << 30);
        }
    }

    /// Back to rest.
    pub fn reset(&mut self) {
        *self = Self::REST;
    }
}
