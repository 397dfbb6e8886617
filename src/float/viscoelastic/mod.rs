//! Quasi-linear viscoelasticity (Fung): the elastic response passed through a Prony
//! series relaxation function, updated once per tick.
//!
//! **Normalisation** (FEBio's, and the tissue files'): the elastic response `S_e(t)` is
//! the *long-term* (fully relaxed) one, and the relaxation function relative to it is
//!
//! ```text
//! G(t) = 1 + sum_i g_i exp(-t / tau_i)        g_i >= 0, tau_i > 0 s, at most 3 terms
//! S(t) = S_e(t) + sum_i h_i(t),   h_i(t) = integral_0^t g_i exp(-(t - s) / tau_i) dS_e(s)
//! ```
//!
//! so a step of the input is at first `1 + sum g_i` times the long-term response and
//! relaxes to it. Published weights normalised by the instantaneous response
//! (Abaqus-style, `sum g'_i < 1`) convert with
//! [`PronyTerms::from_instantaneous_normalised`] (`g_i = g'_i / (1 - sum g'_j)`).
//!
//! **The update** (exact for an input linear over the tick of `dt` s, the recursion FEBio
//! uses): with `a_i = exp(-dt / tau_i)` and `b_i = g_i (1 - a_i) / (dt / tau_i)`,
//!
//! ```text
//! h_i <- a_i h_i + b_i (S_e(n+1) - S_e(n))        S(n+1) = S_e(n+1) + sum_i h_i
//! ```
//!
//! `a_i` and `b_i` are computed once per configuration ([`QlvCoefficients::new`], `libm`
//! in f32: the same bits on every target); a tick is two products and two sums per term
//! and component, no division, no branch on the data. A filter starts at rest with a
//! zero input (the first tick's input is a ramp from 0). With every `g_i >= 0` the filter
//! only dissipates (the relaxation function is a sum of decaying exponentials: a
//! positive-real map from the input's rate to the output).
//!
//! [`Qlv`] filters one scalar, [`WrenchQlv`] the six components of a wrench with one set
//! of coefficients; [`QlvState`] is the per-wrench state alone, stepped with coefficients
//! held elsewhere (the insertion's per-layer coefficients).

use needle_contract::{COMPONENT_COUNT, MAX_PRONY_TERMS, PRONY_G_SUM_MAX};

#[cfg(not(feature = "viscoelastic"))]
pub(crate) mod identity;

/// Most Prony terms of a relaxation function.
pub const MAX_TERMS: usize = MAX_PRONY_TERMS;

/// [`PRONY_G_SUM_MAX`] in f32 (9, exact): the weights are summed in f32, in order.
#[allow(clippy::cast_possible_truncation)] // 9.0 is exact in f32
const G_SUM_MAX: f32 = PRONY_G_SUM_MAX as f32;

/// Why Prony terms or a filter could not be made.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum QlvError {
    /// More than [`MAX_TERMS`] terms.
    TermCount,
    /// A weight `g_i` not finite and >= 0.
    Weight,
    /// A time constant `tau_s` not finite and > 0.
    TimeConstant,
    /// The weights' sum above `PRONY_G_SUM_MAX` (9: instantaneous response at most 10
    /// times the long-term one), or an instantaneous-normalised sum not below 1.
    WeightSum,
    /// The tick period not finite and > 0.
    Tick,
}

impl core::fmt::Display for QlvError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Self::TermCount => "Prony terms: at most 3",
            Self::Weight => "Prony weight g: must be finite and >= 0",
            Self::TimeConstant => "Prony time constant tau_s: must be finite and > 0 s",
            Self::WeightSum => "Prony weights: the sum of g (long-term normalisation) must be <= 9 (instantaneous-normalised: < 0.9)",
            Self::Tick => "viscoelastic filter: the tick period must be finite and > 0 s",
        })
    }
}

impl core::error::Error for QlvError {}

/// One term of the relaxation function, `g exp(-t / tau_s)` (long-term normalisation).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PronyTerm {
    /// Weight relative to the long-term response (>= 0).
    pub g: f32,
    /// Time constant, s (> 0).
    pub tau_s: f32,
}

/// A checked relaxation function: 0 to [`MAX_TERMS`] terms (0: elastic), each
/// `g >= 0`, `tau_s > 0`, the weights' sum (f32, in order) at most 9.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PronyTerms {
    terms: [PronyTerm; MAX_TERMS],
    count: u8,
}

impl PronyTerms {
    /// No terms: the elastic response passes unchanged.
    pub const NONE: Self = Self { terms: [PronyTerm { g: 0.0, tau_s: 0.0 }; MAX_TERMS], count: 0 };

    /// The terms in the long-term normalisation (FEBio's `g1..g6`, `t1..t6` with
    /// `g0 = 1`).
    ///
    /// # Errors
    /// [`QlvError::TermCount`], [`QlvError::Weight`], [`QlvError::TimeConstant`],
    /// [`QlvError::WeightSum`].
    pub fn new(terms: &[PronyTerm]) -> Result<Self, QlvError> {
        if terms.len() > MAX_TERMS {
            return Err(QlvError::TermCount);
        }
        let mut out = Self::NONE;
        for (slot, t) in out.terms.iter_mut().zip(terms) {
            if !(t.g.is_finite() && t.g >= 0.0) {
                return Err(QlvError::Weight);
            }
            if !(t.tau_s.is_finite() && t.tau_s > 0.0) {
                return Err(QlvError::TimeConstant);
            }
            *slot = *t;
        }
        if !Self::sum_within_bound(&out.terms) {
            return Err(QlvError::WeightSum);
        }
        // terms.len() <= MAX_TERMS = 3 (checked above)
        out.count = u8::try_from(terms.len()).map_err(|_| QlvError::TermCount)?;
        Ok(out)
    }

    /// [`new`](Self::new) at compile time, for tables: the first `count` of `terms` (the
    /// rest ignored), `None` where `new` gives an error.
    #[must_use]
    pub const fn from_array(terms: [PronyTerm; MAX_TERMS], count: u8) -> Option<Self> {
        const fn ok(t: PronyTerm, used: bool) -> bool {
            !used || (t.g.is_finite() && t.g >= 0.0 && t.tau_s.is_finite() && t.tau_s > 0.0)
        }
        let [t0, t1, t2] = terms;
        let used = [count > 0, count > 1, count > 2];
        if count as usize > MAX_TERMS || !ok(t0, used[0]) || !ok(t1, used[1]) || !ok(t2, used[2]) {
            return None;
        }
        let z = PronyTerm { g: 0.0, tau_s: 0.0 };
        let terms = [if used[0] { t0 } else { z }, if used[1] { t1 } else { z }, if used[2] { t2 } else { z }];
        if !Self::sum_within_bound(&terms) {
            return None;
        }
        Some(Self { terms, count })
    }

    /// The weights' sum rule of [`new`](Self::new) and [`from_array`](Self::from_array), on
    /// the terms with unused slots zero: `(g_0 + g_1) + g_2 <= 9` in f32 (an unused `+0.0`
    /// changes no sum of weights `>= 0`). f32, not f64: no core here has an f64 FPU, and
    /// soft f64 cost every image with the filter 1.1-1.6 KB of flash (`needle firmware
    /// size`).
    const fn sum_within_bound(terms: &[PronyTerm; MAX_TERMS]) -> bool {
        let [a, b, c] = terms;
        (a.g + b.g) + c.g <= G_SUM_MAX
    }

    /// The terms from weights normalised by the instantaneous response (Abaqus-style:
    /// `G(t) / G_0 = 1 - sum g'_i (1 - exp(-t / tau_i))`, `sum g'_i < 1`), converted by
    /// [`needle_contract::prony_long_term_from_instantaneous`].
    ///
    /// # Errors
    /// As [`new`](Self::new); [`QlvError::WeightSum`] also for `sum g'_i >= 1`.
    pub fn from_instantaneous_normalised(terms: &[PronyTerm]) -> Result<Self, QlvError> {
        if terms.len() > MAX_TERMS {
            return Err(QlvError::TermCount);
        }
        let mut g = [0.0f64; MAX_TERMS];
        for (slot, t) in g.iter_mut().zip(terms) {
            if !(t.g.is_finite() && t.g >= 0.0) {
                return Err(QlvError::Weight);
            }
            *slot = f64::from(t.g);
        }
        let long = needle_contract::prony_long_term_from_instantaneous(g).ok_or(QlvError::WeightSum)?;
        let mut converted = [PronyTerm::default(); MAX_TERMS];
        for ((slot, t), g) in converted.iter_mut().zip(terms).zip(long) {
            #[allow(clippy::cast_possible_truncation)] // the nearest f32 of the f64 weight
            let g = g as f32;
            *slot = PronyTerm { g, tau_s: t.tau_s };
        }
        Self::new(converted.get(..terms.len()).unwrap_or(&[]))
    }

    /// All [`MAX_TERMS`] slots (those past [`len`](Self::len) zero) and the count, for
    /// compile-time conversions (the fixed-point stacks).
    #[must_use]
    pub const fn as_array(&self) -> ([PronyTerm; MAX_TERMS], u8) {
        (self.terms, self.count)
    }

    /// The number of terms.
    #[must_use]
    pub const fn len(&self) -> usize {
        self.count as usize
    }

    /// Whether there is no term (elastic).
    #[must_use]
    pub const fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// The terms.
    #[must_use]
    pub fn as_slice(&self) -> &[PronyTerm] {
        self.terms.get(..usize::from(self.count)).unwrap_or(&[])
    }

    /// `1 + sum g_i`: the instantaneous response over the long-term one.
    #[must_use]
    pub fn instantaneous_ratio(&self) -> f32 {
        1.0 + self.as_slice().iter().map(|t| t.g).sum::<f32>()
    }
}

/// The per-tick coefficients of a relaxation function at one tick period: `a_i`, `b_i`
/// of the module's recursion (unused terms `a = b = 0`).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct QlvCoefficients {
    a: [f32; MAX_TERMS],
    b: [f32; MAX_TERMS],
    /// `rho = 1 + sum 2 b_i / (1 + a_i)`: [`effective_stiffness_ratio`](Self::effective_stiffness_ratio).
    rho: f32,
    count: u8,
}

impl QlvCoefficients {
    /// No terms: the filter passes its input.
    pub const NONE: Self = Self { a: [0.0; MAX_TERMS], b: [0.0; MAX_TERMS], rho: 1.0, count: 0 };

    /// `a_i = exp(-dt / tau_i)`, `b_i = g_i (1 - a_i) / (dt / tau_i)` for the tick period
    /// `tick_s` (`1 - a_i` as `-expm1(-dt / tau_i)`: no cancellation for `tau_i >> dt`).
    ///
    /// # Errors
    /// [`QlvError::Tick`] for a period not finite and > 0.
    pub fn new(terms: &PronyTerms, tick_s: f32) -> Result<Self, QlvError> {
        if !(tick_s.is_finite() && tick_s > 0.0) {
            return Err(QlvError::Tick);
        }
        let mut out = Self { count: terms.count, ..Self::NONE };
        for ((a, b), t) in out.a.iter_mut().zip(out.b.iter_mut()).zip(terms.as_slice()) {
            // tau_s > 0 and tick_s > 0 (checked): x > 0, or +inf / 0 at f32's ends
            let x = tick_s / t.tau_s;
            *a = libm::expf(-x);
            // x = 0 (tau_s >> tick_s beyond f32): the limit b = g
            *b = if x > 0.0 { t.g * (-libm::expm1f(-x) / x) } else { t.g };
            if !b.is_finite() {
                *b = 0.0; // x = +inf: the term relaxes within the tick
            }
        }
        // 0 <= a_i <= 1, so 1 + a_i >= 1: no division by zero; unused terms add 0
        out.rho = 1.0 + 2.0 * out.b[0] / (1.0 + out.a[0]) + 2.0 * out.b[1] / (1.0 + out.a[1]) + 2.0 * out.b[2] / (1.0 + out.a[2]);
        Ok(out)
    }

    /// Whether there is any term (without, [`QlvState::step`] passes its input).
    #[must_use]
    pub fn is_active(&self) -> bool {
        self.count > 0
    }

    /// `1 + sum b_i`: the output's change per change of the input within one tick (the
    /// filter's stiffness ratio over a tick, for a passivity guard).
    #[must_use]
    pub fn tick_gain(&self) -> f32 {
        1.0 + self.b[0] + self.b[1] + self.b[2]
    }

    /// `rho`, the filter's worst-case stiffness ratio in a sampled loop (1 without
    /// terms): an elastic force of stiffness `K` passed through the filter is, for
    /// Colgate's passivity condition of a zero-order-hold loop at the filter's tick `T`,
    /// the same as a spring of stiffness `rho K`.
    ///
    /// Colgate and Schenkel's general condition for a virtual environment `H(z)`
    /// (force per position) on a device of damping `b` is
    /// `b > T / (2 (1 - cos wT)) Re[(1 - e^{-iwT}) H(e^{iwT})]` for every `w` in
    /// `(0, pi/T]`. Per unit stiffness the filter is
    /// `H(z) = 1 + sum_i b_i (1 - z^-1) / (1 - a_i z^-1)`, and with `c = cos wT`
    ///
    /// ```text
    /// Re[(1 - e^{-iwT}) H] / (1 - c) = 1 + sum_i 2 b_i (a_i - c) / (1 + a_i² - 2 a_i c)
    /// ```
    ///
    /// Each term's derivative by `c` is `2 b_i (a_i² - 1) / (1 + a_i² - 2 a_i c)² <= 0`
    /// (`0 <= a_i < 1`), so every term, and their sum, is largest at `c = -1` (the
    /// Nyquist frequency): `rho = 1 + sum_i 2 b_i / (1 + a_i)`, exact, not a bound. With
    /// `x_i = T / tau_i` it is `1 + sum_i g_i tanh(x_i / 2) / (x_i / 2)`: `g_i` for
    /// `tau_i >> T` (the instantaneous stiffness), `2 g_i tau_i / T` for `tau_i << T`
    /// (the term is then a damper `g_i K tau_i`, which Colgate's condition charges as
    /// `2 g_i K tau_i / T`), never above `1 + sum g_i`. Computed once, in
    /// [`new`](Self::new) (f32).
    #[must_use]
    pub fn effective_stiffness_ratio(&self) -> f32 {
        self.rho
    }

    /// One tick of the three force components' terms driven by input increments
    /// `d` (not inputs): `h_i <- a_i h_i + b_i d`; the filter's viscous part
    /// `sum_i h_i` of each component out. For a passivity guard that feeds the filter
    /// the guarded increments of an elastic force (`control::passivity`).
    #[cfg(feature = "viscoelastic")]
    #[inline]
    pub(crate) fn step_increments(&self, h: &mut [[f32; MAX_TERMS]; 3], d: [f32; 3]) -> [f32; 3] {
        match self.count {
            1 => self.increments_of::<1>(h, d),
            2 => self.increments_of::<2>(h, d),
            _ => self.increments_of::<MAX_TERMS>(h, d),
        }
    }

    /// [`step_increments`](Self::step_increments) with the first `N` terms (the others
    /// are zero and stay zero: `a = b = 0`).
    #[cfg(feature = "viscoelastic")]
    #[inline(always)]
    fn increments_of<const N: usize>(&self, h: &mut [[f32; MAX_TERMS]; 3], d: [f32; 3]) -> [f32; 3] {
        let mut out = [0.0; 3];
        for ((o, h), d) in out.iter_mut().zip(h.iter_mut()).zip(d) {
            // -0.0 is addition's identity (0.0 is not: 0.0 + -0.0 = 0.0): the bits of `h_0 + h_1 + h_2`
            *o = self.terms_of::<N>(h, d, -0.0);
        }
        out
    }

    /// The six components of `w` in place, each with its `[last input, h_0, h_1, h_2]`
    /// in `state`; only the terms there are computed (a layer with one term pays for one).
    #[inline]
    fn step_components(&self, state: &mut [[f32; 1 + MAX_TERMS]; COMPONENT_COUNT], w: &mut [f32; COMPONENT_COUNT]) {
        match self.count {
            1 => self.components_of::<1>(state, w),
            2 => self.components_of::<2>(state, w),
            _ => self.components_of::<MAX_TERMS>(state, w),
        }
    }

    #[inline(always)]
    fn components_of<const N: usize>(&self, state: &mut [[f32; 1 + MAX_TERMS]; COMPONENT_COUNT], w: &mut [f32; COMPONENT_COUNT]) {
        for (o, s) in w.iter_mut().zip(state.iter_mut()) {
            *o = self.one_of::<N>(s, *o);
        }
    }

    /// The first `N` terms: `h_i <- a_i h_i + b_i d`, and `start + h_0 + ... + h_{N-1}`
    /// summed in that order (the order of the three-term sum, so `N = 3` gives the bits
    /// of every term written out; a skipped term is zero).
    #[inline(always)]
    fn terms_of<const N: usize>(&self, h: &mut [f32; MAX_TERMS], d: f32, start: f32) -> f32 {
        let mut sum = start;
        for ((h, a), b) in h.iter_mut().zip(self.a).zip(self.b).take(N) {
            *h = a * *h + b * d;
            sum += *h;
        }
        sum
    }

    /// One component: `h_i <- a_i h_i + b_i d`, the output `elastic + sum h_i`.
    #[inline]
    fn step_one(&self, state: &mut [f32; 1 + MAX_TERMS], elastic: f32) -> f32 {
        self.one_of::<MAX_TERMS>(state, elastic)
    }

    /// [`step_one`](Self::step_one) with the first `N` terms.
    #[inline(always)]
    fn one_of<const N: usize>(&self, state: &mut [f32; 1 + MAX_TERMS], elastic: f32) -> f32 {
        let [last, h @ ..] = state;
        let d = elastic - *last;
        *last = elastic;
        self.terms_of::<N>(h, d, elastic)
    }
}

/// One scalar through the filter.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Qlv {
    coefficients: QlvCoefficients,
    /// `[last input, h_0, h_1, h_2]`.
    state: [f32; 1 + MAX_TERMS],
}

impl Qlv {
    /// A filter at rest for `terms` ticked every `tick_s` s.
    ///
    /// # Errors
    /// [`QlvError::Tick`].
    pub fn new(terms: &PronyTerms, tick_s: f32) -> Result<Self, QlvError> {
        Ok(Self { coefficients: QlvCoefficients::new(terms, tick_s)?, state: [0.0; 1 + MAX_TERMS] })
    }

    /// One tick: the elastic (long-term) response at the end of the tick in, the
    /// viscoelastic response out (same unit).
    pub fn step(&mut self, elastic: f32) -> f32 {
        self.coefficients.step_one(&mut self.state, elastic)
    }

    /// Back to rest: no stored response, the last input 0.
    pub fn reset(&mut self) {
        self.state = [0.0; 1 + MAX_TERMS];
    }

    /// The coefficients in use.
    #[must_use]
    pub fn coefficients(&self) -> &QlvCoefficients {
        &self.coefficients
    }
}

/// The filter state of the six components of a wrench (`[fx, fy, fz, mx, my, mz]`, the
/// [`Wrench::to_array`](crate::Wrench::to_array) order), stepped with coefficients held
/// elsewhere: 24 f32, at rest when zero.
///
/// **Held ticks** ([`hold`](Self::hold)): a tick whose input is not known (the insertion's
/// glitch tick) relaxes every term over the input held at the last one; the next
/// [`step`](Self::step) takes its input's change as a ramp over the `n` ticks since the
/// last step (`n - 1` held): `b_i` times `(1 + a_i + ... + a_i^(n-1)) / n`, exact for an
/// input that changed at a constant rate over them (the module's recursion over `n` ticks
/// of `d / n` each), and without held ticks the plain recursion.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct QlvState {
    /// Per component `[last input, h_0, h_1, h_2]`.
    state: [[f32; 1 + MAX_TERMS]; COMPONENT_COUNT],
    /// Ticks held since the last step.
    held: u32,
    /// Per term `1 + a_i + ... + a_i^held` (valid while `held > 0`).
    ramp: [f32; MAX_TERMS],
    /// Whether a step with terms ran since the last reset (when not, every value is
    /// still zero and [`reset`](Self::reset) has nothing to clear: a stack without
    /// terms pays no 24 stores a tick).
    stored: bool,
}

impl QlvState {
    /// At rest.
    pub const REST: Self = Self { state: [[0.0; 1 + MAX_TERMS]; COMPONENT_COUNT], held: 0, ramp: [0.0; MAX_TERMS], stored: false };

    /// One tick of every component with `coefficients`: the elastic wrench in, the
    /// viscoelastic wrench out (after held ticks, the input's change as a ramp over them:
    /// the type's "Held ticks"). Without terms the input is returned and the state left
    /// at rest.
    pub fn step(&mut self, coefficients: &QlvCoefficients, elastic: [f32; COMPONENT_COUNT]) -> [f32; COMPONENT_COUNT] {
        let mut out = elastic;
        if coefficients.is_active() {
            if self.held == 0 {
                self.filter(coefficients, &mut out);
            } else {
                self.after_held(coefficients, &mut out);
            }
        }
        out
    }

    /// The six components in place. Out of line: inlined into the insertion's step, its
    /// registers and stack slots made every step dearer, with or without terms (M4F:
    /// the elastic step 25-72 instructions and 48 B of stack; docs/insertion.md).
    #[inline(never)]
    fn filter(&mut self, coefficients: &QlvCoefficients, w: &mut [f32; COMPONENT_COUNT]) {
        self.stored = true;
        coefficients.step_components(&mut self.state, w);
    }

    /// The step after held ticks: `b_i` times the ramp's weight
    /// `(1 + a_i + ... + a_i^held) / (held + 1)` (the type's "Held ticks"); no tick held
    /// after it. Out of line: the step's usual path stays as it was.
    #[inline(never)]
    fn after_held(&mut self, coefficients: &QlvCoefficients, w: &mut [f32; COMPONENT_COUNT]) {
        // held >= 1: n >= 2 (as f32: exact to 2^24, then within 1e-7)
        let n = self.held as f32 + 1.0;
        self.held = 0;
        let mut ramped = *coefficients;
        for (b, r) in ramped.b.iter_mut().zip(self.ramp) {
            *b *= r / n;
        }
        self.filter(&ramped, w);
    }

    /// One tick with the input unknown (the type's "Held ticks"): the step's recursion
    /// over the input held at the last tick's (its change zero: each term relaxes,
    /// `h_i <- a_i h_i`), so the state follows time. Without terms nothing changes.
    pub fn hold(&mut self, coefficients: &QlvCoefficients) {
        if !coefficients.is_active() {
            return;
        }
        let mut input = self.state.map(|s| s[0]);
        self.filter(coefficients, &mut input);
        if self.held == 0 {
            self.ramp = [1.0; MAX_TERMS];
        }
        self.held = self.held.saturating_add(1);
        for (r, a) in self.ramp.iter_mut().zip(coefficients.a) {
            *r = a * *r + 1.0;
        }
    }

    /// Back to rest.
    pub fn reset(&mut self) {
        if self.stored {
            *self = Self::REST;
        }
    }
}

/// A wrench through the filter, one set of coefficients for the six components.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WrenchQlv {
    coefficients: QlvCoefficients,
    state: QlvState,
}

impl WrenchQlv {
    /// A filter at rest for `terms` ticked every `tick_s` s.
    ///
    /// # Errors
    /// [`QlvError::Tick`].
    pub fn new(terms: &PronyTerms, tick_s: f32) -> Result<Self, QlvError> {
        Ok(Self { coefficients: QlvCoefficients::new(terms, tick_s)?, state: QlvState::REST })
    }

    /// One tick: the elastic wrench (`[fx, fy, fz, mx, my, mz]`, N and N·mm) in, the
    /// viscoelastic one out.
    pub fn step(&mut self, elastic: [f32; COMPONENT_COUNT]) -> [f32; COMPONENT_COUNT] {
        self.state.step(&self.coefficients, elastic)
    }

    /// Back to rest.
    pub fn reset(&mut self) {
        self.state.reset();
    }
}
