//! [`Passivity`]: the guard that keeps the rendered stiffness inside the bound of a
//! sampled haptic loop.
//!
//! A force field of stiffness `K` rendered by a zero-order hold at period `T` on a device
//! with physical damping `b` is passive only while `K * T / 2 < b` (Colgate and
//! Schenkel): above it, each oscillation of the hand gains energy from the loop. The
//! model knows its stiffness exactly ([`wrench_and_stiffness`](crate::wrench_and_stiffness)),
//! so the loop can check the bound every tick.
//!
//! **The rule** (each tick with a valid model wrench `F_k` and its depth rate `dF/dd`):
//!
//! - `K = |dF/dd| = sqrt(dfx² + dfy² + dfz²)` (N/mm): the stiffness along the insertion,
//!   an upper bound of the stiffness along any direction the needle moves in depth;
//! - `K_g = GUARD_FRACTION * 2 * b / T`: the guard keeps the rendered stiffness at half
//!   the bound, so the device's damping always dominates what the sampling generates (at
//!   the bound itself the loop is only marginally passive);
//! - when `K > K_g`: flag `STIFFNESS_LIMITED`, and the change of the model force since the
//!   last tick enters the command scaled by `K_g / K`: the guard's offset grows by
//!   `(1 - K_g / K) * (F_k - F_{k-1})` and the command is `F_k - offset`. The rendered
//!   force's rate along the depth is then `min(K, K_g)`: it is a function of the path in
//!   depth (the same force when the hand comes back to the same depth), so the guard adds
//!   no energy of its own;
//! - when `K <= K_g` the offset is kept (the command follows the model's changes one to
//!   one); it is cleared when the model force is exactly zero and after any fault (the
//!   first valid tick then follows the model again).
//! - a whole insertion ([`GuardTerms`]) names the dissipative part `D` of its force
//!   (shaft friction and cutting): the rule above applies to the elastic part `F - D`
//!   (with the deflected boundary's stiffness as `K`) and `D` is added back unchanged.
//!   Scaled into the offset, a friction reversal would keep pushing the needle out
//!   after a withdrawal starts. The block surrogate has no `D`: its force is guarded whole.
//! - **with the viscoelastic filter** (feature `viscoelastic`, a deflected layer with
//!   Prony terms): the insertion's force is `F = P + E + V(E) + D`, `E` the boundary's
//!   elastic deflection force (a function of the path, stiffness `K`), `V(E)` the
//!   quasi-linear filter's part (a function of time too: at a fixed position it relaxes),
//!   `P` the preload and the track's hold. The guard limits first and filters after: the
//!   rule above runs on the elastic part `F - D - V` (the insertion names `V` and `E`:
//!   `Insertion::guard_filter`, beside the layer's coefficients), at the stiffness `rho K` (`rho`:
//!   [`QlvCoefficients::effective_stiffness_ratio`](crate::float::viscoelastic::QlvCoefficients::effective_stiffness_ratio),
//!   the filter's worst-case stiffness ratio in a sampled loop, Colgate's general
//!   condition at the Nyquist frequency: `1 + sum 2 b_i / (1 + a_i)`), and the guard's own
//!   filter, the same coefficients, runs on the guarded deflection force `E'` (its
//!   change each tick is `s` times `E`'s, `s = k_g / (rho K)` when limited, else 1); the
//!   command is `E'`'s guarded elastic part `+ V(E') + D`.
//!
//!   Why it is passive: the guarded elastic part is a function of the path again (the
//!   offset integrates `(1 - s) dE` along it; it no longer integrates the relaxing `V`,
//!   which made the old rule's offset depend on time: issue 39, energy delivered to the
//!   hand with `g = 3, 3, 3`, `tau = 1 ms, 10 ms, 0.1 s`, `docs/insertion.md`); a
//!   quasi-linear filter with every `g_i >= 0` on a path function is a generalised
//!   Maxwell body (springs `g_i K'` in series with dampers `g_i K' tau_i` beside the
//!   spring `K'`), which only dissipates in continuous time; sampled, Colgate's condition
//!   `b > T / (2 (1 - cos wT)) Re[(1 - e^{-iwT}) H(e^{iwT})]` for the filter's
//!   `H = K' (1 + sum b_i (1 - z^-1) / (1 - a_i z^-1))` is `b > K' rho(wT) T / 2`, largest
//!   at the Nyquist frequency, so `rho K' <= k_g` keeps the loop at `GUARD_FRACTION` of
//!   the bound at every frequency (a term of `tau_i` near `T` is charged as the damper it
//!   acts as, `2 g_i K tau_i / T`; the old tick gain `1 + sum b_i` was 8.74 for the set
//!   above, `rho` 9.77). The guard's filter rests (nothing stored, last `E` zero) in every
//!   tick without a deflected boundary with terms, exactly when the insertion's filter
//!   rests, and starts without history after a puncture or a fault (relaxed at the first
//!   `E` it sees). Where the limit has not acted since a boundary's first contact it
//!   renders the insertion's own force (within f32 rounding); a layer without terms, the block surrogate and the build without the
//!   feature take the rule above bit for bit (the feature's state is zero-sized without
//!   it). Measured: `host-tests/tests/insertion_energy.rs` (random closed cycles and
//!   Colgate's ratio at `wT` from `0.2 pi` to `pi`).
//! - **with the shaft's presliding** (feature `shaft-presliding`, a layer with a
//!   presliding distance): the insertion's held friction and cutting `H` (a spring that
//!   slips: a function of the path's history, which the rule above would ratchet into
//!   its offset) is neither in `D` nor in the elastic part: the guard renders it through
//!   a bristle of its own (`control::held_bristle`, which states why it is passive) of
//!   stiffness `κ <= HELD_SHARE k_g`, runs the rule above on `F - H` with the deflected
//!   boundary's stiffness charged against `k_g - κ`, and adds the bristle's force along
//!   the axis. A tick with nothing held and the bristle at rest is the rule above bit
//!   for bit.
#[cfg(feature = "shaft-presliding")]
use super::held_bristle::HeldBristle;
use super::ConfigError;
#[cfg(feature = "viscoelastic")]
use crate::float::insertion::FilterTerms;
use crate::float::insertion::{FilterShare, GuardTerms};
#[cfg(feature = "viscoelastic")]
use crate::float::viscoelastic::QlvCoefficients;

/// The fraction of Colgate's bound `2 b / T` the guard renders at most.
pub const GUARD_FRACTION: f32 = 0.5;

/// The device's physical damping and the loop period: the passivity guard's configuration.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Passivity {
    /// Physical damping of the device along the insertion, N·s/mm (finite, > 0).
    pub damping_n_s_per_mm: f32,
    /// The control loop's period, s (finite, > 0; 0.001 at 1 kHz).
    pub period_s: f32,
}

impl Passivity {
    /// Checks the configuration.
    ///
    /// # Errors
    /// [`ConfigError::Passivity`] unless both values are finite and > 0.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let ok = |v: f32| v.is_finite() && v > 0.0;
        if ok(self.damping_n_s_per_mm) && ok(self.period_s) && ok(self.guard_stiffness_n_per_mm()) {
            Ok(())
        } else {
            Err(ConfigError::Passivity)
        }
    }

    /// Colgate's bound `2 b / T`, N/mm: the largest stiffness the loop renders passively
    /// (`+inf` for a zero period, which [`validate`](Self::validate) refuses).
    #[must_use]
    pub fn stiffness_bound_n_per_mm(&self) -> f32 {
        2.0 * self.damping_n_s_per_mm / self.period_s
    }

    /// The stiffness the guard renders at most, `GUARD_FRACTION * 2 b / T`, N/mm.
    #[must_use]
    pub fn guard_stiffness_n_per_mm(&self) -> f32 {
        GUARD_FRACTION * self.stiffness_bound_n_per_mm()
    }
}

/// The guard's state: the offset between model and command, the last model force, and
/// (with the `viscoelastic` feature) the guard's own filter of the guarded deflection.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct Guard {
    offset_n: [f32; 3],
    last_model_n: Option<[f32; 3]>,
    filter: GuardFilter,
    /// The bristle of the shaft's held force (`control::held_bristle`).
    #[cfg(feature = "shaft-presliding")]
    held: HeldBristle,
}

impl Guard {
    /// Forget the history (after a fault): the next tick follows the model.
    pub(crate) fn reset(&mut self) {
        *self = Self::default();
    }

    /// A puncture: forget the deflected boundary's history (the next tick follows the
    /// model), keep the held force's bristle (the shaft still holds).
    #[cfg(feature = "shaft-presliding")]
    pub(crate) fn punctured(&mut self) {
        *self = Self { held: self.held, ..Self::default() };
    }

    /// A puncture: [`reset`](Self::reset) (no held force without the `shaft-presliding`
    /// feature).
    #[cfg(not(feature = "shaft-presliding"))]
    #[inline]
    pub(crate) fn punctured(&mut self) {
        self.reset();
    }

    /// [`apply`](Self::apply) with the shaft's held force `terms.held` rendered by the guard's
    /// bristle (`control::held_bristle`): the rule runs on the rest of the force, with the
    /// deflected boundary's stiffness charged against `k_g - κ` (`κ` the bristle's), and
    /// the bristle's force is added along the axis. A tick with nothing held and the
    /// bristle at rest is [`apply`](Self::apply) bit for bit.
    #[cfg(feature = "shaft-presliding")]
    pub(crate) fn apply_held(&mut self, p: &Passivity, f_n: [f32; 3], terms: &GuardTerms, filter: FilterShare<'_>) -> ([f32; 3], bool) {
        let h = &terms.held;
        if h.force_n == 0.0 && h.stiffness_n_per_mm == 0.0 && self.held.is_at_rest() {
            return self.apply(p, f_n, terms, filter);
        }
        let k_g = p.guard_stiffness_n_per_mm();
        let (r, kappa) = self.held.step(h, k_g);
        let a = h.axis;
        let rest = [f_n[0] - h.force_n * a[0], f_n[1] - h.force_n * a[1], f_n[2] - h.force_n * a[2]];
        // the rule limits the boundary to `k_g - kappa` when it sees its stiffness times
        // `k_g / (k_g - kappa)`; `kappa <= HELD_SHARE k_g < k_g`: a positive divisor
        let boundary = GuardTerms { stiffness_n_per_mm: terms.stiffness_n_per_mm * (k_g / (k_g - kappa)), ..*terms };
        let (g, limited) = self.apply(p, rest, &boundary, filter);
        ([g[0] + r * a[0], g[1] + r * a[1], g[2] + r * a[2]], limited || kappa < h.stiffness_n_per_mm)
    }

    /// The guarded force for the model force `f_n` with its stiffness and dissipative
    /// part `terms` (the module's rule; `filter` the deflected boundary's viscoelastic
    /// filter, [`Insertion::guard_filter`](crate::float::insertion::Insertion::guard_filter)),
    /// and whether the stiffness was limited.
    pub(crate) fn apply(&mut self, p: &Passivity, f_n: [f32; 3], terms: &GuardTerms, filter: FilterShare<'_>) -> ([f32; 3], bool) {
        #[cfg(feature = "viscoelastic")]
        if let Some((c, share)) = filter {
            return self.apply_filtered(p, f_n, terms, c, share);
        }
        let _ = filter;
        self.filter.rest();
        let d = terms.dissipative_n;
        // no dissipative part (the block surrogate): the whole force, bits unchanged
        if d == [0.0; 3] {
            return self.apply_elastic(p, f_n, terms.stiffness_n_per_mm);
        }
        let elastic = [f_n[0] - d[0], f_n[1] - d[1], f_n[2] - d[2]];
        let (g, limited) = self.apply_elastic(p, elastic, terms.stiffness_n_per_mm);
        ([g[0] + d[0], g[1] + d[1], g[2] + d[2]], limited)
    }

    /// The rule with the deflected boundary's viscoelastic filter: the elastic part
    /// `F - D - V` through [`apply_elastic`](Self::apply_elastic) at the effective
    /// stiffness `rho K` (`terms.stiffness_n_per_mm`), then the guard's own filter run on
    /// the guarded deflection force (its increments `s dE`, `s` the rule's scale), then
    /// `D` unchanged.
    #[cfg(feature = "viscoelastic")]
    fn apply_filtered(
        &mut self,
        p: &Passivity,
        f_n: [f32; 3],
        terms: &GuardTerms,
        c: &QlvCoefficients,
        share: &FilterTerms,
    ) -> ([f32; 3], bool) {
        let (d, v) = (terms.dissipative_n, share.viscous_n);
        let elastic = [f_n[0] - d[0] - v[0], f_n[1] - d[1] - v[1], f_n[2] - d[2] - v[2]];
        // the scale the rule gives this tick's change (below), before it records the force
        let k_g = p.guard_stiffness_n_per_mm();
        let k = terms.stiffness_n_per_mm;
        // `k > k_g > 0` (validated), so the division is by a positive, finite number
        let scale = self.last_model_n.map(|_| if k > k_g { k_g / k } else { 1.0 });
        let (g, limited) = self.apply_elastic(p, elastic, k);
        let h = self.filter.step(c, share.deflection_n, scale);
        ([g[0] + h[0] + d[0], g[1] + h[1] + d[1], g[2] + h[2] + d[2]], limited)
    }

    /// The rule on an elastic force `f_n` of stiffness `k_n_per_mm`: its change since the
    /// last tick enters the command times `k_g / k` when limited, else whole (the
    /// filter's scale in [`apply_filtered`](Self::apply_filtered)); nothing without a
    /// last force (the first tick after a reset follows the model).
    fn apply_elastic(&mut self, p: &Passivity, f_n: [f32; 3], k_n_per_mm: f32) -> ([f32; 3], bool) {
        let k_g = p.guard_stiffness_n_per_mm();
        // `k > k_g > 0` (validated), so the division is by a positive, finite number.
        let limited = k_n_per_mm > k_g;
        if let (Some(last), true) = (self.last_model_n, limited) {
            let keep = 1.0 - k_g / k_n_per_mm;
            for ((o, f), l) in self.offset_n.iter_mut().zip(f_n).zip(last) {
                *o += keep * (f - l);
            }
        }
        if f_n == [0.0; 3] {
            self.offset_n = [0.0; 3];
        }
        self.last_model_n = Some(f_n);
        let [o0, o1, o2] = self.offset_n;
        let [f0, f1, f2] = f_n;
        ([f0 - o0, f1 - o1, f2 - o2], limited)
    }
}

/// The guard's own viscoelastic filter of the guarded deflection force: the last
/// deflection force `E` it saw and the terms' state `h_i` per force component. At rest
/// (nothing stored, last `E` 0) whenever the tick has no filter (no boundary with
/// Prony terms deflected: the insertion's filter is at rest too); without history
/// (nothing stored, no last `E`: it starts relaxed at the next `E`) after a puncture
/// and after a fault.
#[cfg(feature = "viscoelastic")]
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct GuardFilter {
    last_deflection_n: Option<[f32; 3]>,
    h_n: [[f32; crate::float::viscoelastic::MAX_TERMS]; 3],
    /// Set by [`rest`](Self::rest), cleared by [`step`](Self::step): a filter at rest
    /// is not written again (a tick without terms pays no 13 stores).
    at_rest: bool,
}

#[cfg(feature = "viscoelastic")]
impl GuardFilter {
    /// At rest as the insertion's filter is without a deflected boundary: nothing
    /// stored, the last deflection force 0 (the next boundary's first force enters
    /// whole, as in the insertion's filter).
    fn rest(&mut self) {
        if !self.at_rest {
            *self = Self { last_deflection_n: Some([0.0; 3]), h_n: [[0.0; crate::float::viscoelastic::MAX_TERMS]; 3], at_rest: true };
        }
    }

    /// One tick: the deflection force `e_n` whose change since the last tick enters the
    /// filter times `scale` (the guard's rule; with `scale` `None`, the first tick after
    /// a reset, or no last force: nothing enters, the filter starts relaxed at `E`);
    /// the filter's viscous force out.
    fn step(&mut self, c: &crate::float::viscoelastic::QlvCoefficients, e_n: [f32; 3], scale: Option<f32>) -> [f32; 3] {
        let d = match (self.last_deflection_n, scale) {
            (Some(l), Some(s)) => [s * (e_n[0] - l[0]), s * (e_n[1] - l[1]), s * (e_n[2] - l[2])],
            _ => [0.0; 3],
        };
        self.last_deflection_n = Some(e_n);
        self.at_rest = false;
        c.step_increments(&mut self.h_n, d)
    }
}

/// Without the `viscoelastic` feature: no filter, nothing stored.
#[cfg(not(feature = "viscoelastic"))]
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct GuardFilter;

#[cfg(not(feature = "viscoelastic"))]
impl GuardFilter {
    /// Nothing to reset.
    #[inline]
    fn rest(&mut self) {}
}
