//! The passivity guard's bristle for the shaft's presliding (the `shaft-presliding`
//! feature): the held friction and cutting rendered as an elasto-plastic spring of its
//! own, of bounded stiffness, that slips towards zero and never holds more than the
//! insertion does.
//!
//! **The rule** (each tick the guard renders; `H` the insertion's held force along the
//! axis, `K_h` its stiffness, `Δd` the tick's step along the axis: [`HeldTerms`]):
//!
//! 1. `R <- R + κ Δd`, `κ` the bristle's stiffness of the last tick (the one its force
//!    `R` was held at over the step);
//! 2. the new stiffness `κ' = min(K_h, HELD_SHARE k_g)`; when `κ' < κ`, `R <- R κ' / κ`;
//! 3. `R` clamped between 0 and `H` (the plastic slip, and the insertion's relaxation,
//!    its turning over, its shaft growing shorter: the rendered force never exceeds the
//!    held one, nor has the other sign).
//!
//! **Why it is passive**: `V = R² / (2 κ)` (0 with `R = 0`) is what the bristle stores.
//! Step 1 raises it by `R Δd + κ Δd² / 2`, and `R Δd` is exactly the work the hand does
//! against the force `R` held over the step (a zero-order hold); step 2 lowers `R² / κ`
//! (`R` kept when the stiffness grows, scaled with it when it falls) and step 3 moves
//! `R` towards zero at the new stiffness: neither raises `V`. So over any path the hand gets back at
//! most `V` at its start (0: the bristle starts at rest) plus `Σ κ Δd² / 2`, the
//! zero-order hold's share of a spring of stiffness `κ <= HELD_SHARE k_g`, which the
//! device's damping takes (`b / T Σ Δd²`, Colgate's condition `κ T / 2 < b` with
//! `k_g = GUARD_FRACTION 2 b / T`). Nothing here needs the held force to be a function
//! of the path, which it is not (it turns over on a reversal): the old rule, which
//! scaled its changes into the guard's offset like an elastic force's, let the offset
//! ratchet over reversals at depths of different scales and gave it back on the way
//! out (15.8 N·mm delivered, `host-tests/tests/insertion_energy.rs`).
//!
//! While the needle slides, `R` reaches the held force (it is clamped to it) after
//! `H / κ` of travel, so the sliding level is rendered whole; after a reversal it turns
//! over within `2 H / κ` (the insertion's `2 p` when `κ = K_h`). The deflected boundary
//! is guarded within the rest of the guard's stiffness, `k_g - κ'`
//! (`control::passivity`): `κ'` depends on the depth alone (the shaft's length in each
//! layer and the puncture state, not the held force's history), so the boundary's
//! guarded force stays a function of the path.
use crate::float::insertion::HeldTerms;

/// The share of the guard's stiffness `k_g` the held force's bristle renders at most;
/// the deflected boundary has at least the rest.
pub const HELD_SHARE: f32 = 0.5;

/// The bristle's state: the force it renders along the axis and its stiffness.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct HeldBristle {
    force_n: f32,
    stiffness_n_per_mm: f32,
}

impl HeldBristle {
    /// Whether the bristle renders nothing and stores nothing.
    pub(crate) fn is_at_rest(&self) -> bool {
        self.force_n == 0.0 && self.stiffness_n_per_mm == 0.0
    }

    /// One tick of the module's rule for the held force `h` under the guard's stiffness
    /// `k_g_n_per_mm` (> 0): the force `R` to render along the axis (N) and the
    /// stiffness `κ'` it now has (N/mm, at most `HELD_SHARE k_g`).
    pub(crate) fn step(&mut self, h: &HeldTerms, k_g_n_per_mm: f32) -> (f32, f32) {
        let share = HELD_SHARE * k_g_n_per_mm;
        let kappa = if h.stiffness_n_per_mm < share { h.stiffness_n_per_mm } else { share };
        let r = self.force_n + self.stiffness_n_per_mm * h.step_mm;
        // `stiffness > kappa >= 0`: the division is by a positive number
        let r = if kappa < self.stiffness_n_per_mm { r * (kappa / self.stiffness_n_per_mm) } else { r };
        let (lo, hi) = if h.force_n < 0.0 { (h.force_n, 0.0) } else { (0.0, h.force_n) };
        let r = if r > hi {
            hi
        } else if r < lo {
            lo
        } else {
            r
        };
        *self = Self { force_n: r, stiffness_n_per_mm: kappa };
        (r, kappa)
    }
}
