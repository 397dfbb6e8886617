//! [`Stiffness`]: how the reaction wrench changes with depth and with the insertion point,
//! and [`StiffnessEvaluation`], a wrench with its stiffness.
use crate::{Status, Wrench};
use needle_contract::COMPONENT_COUNT;

/// The rate of change of every wrench component with respect to one input measured in
/// mm: forces in N/mm, moments in N·mm/mm.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WrenchRate {
    /// d fx / d input, N/mm.
    pub dfx_n_per_mm: f32,
    /// d fy / d input, N/mm.
    pub dfy_n_per_mm: f32,
    /// d fz / d input, N/mm.
    pub dfz_n_per_mm: f32,
    /// d mx / d input, N·mm/mm.
    pub dmx_nmm_per_mm: f32,
    /// d my / d input, N·mm/mm.
    pub dmy_nmm_per_mm: f32,
    /// d mz / d input, N·mm/mm.
    pub dmz_nmm_per_mm: f32,
}

impl WrenchRate {
    /// Every rate `+0.0`.
    pub const ZERO: Self = Self::from_array([0.0; COMPONENT_COUNT]);

    /// The six rates in the model's component order (fx, fy, fz, mx, my, mz).
    #[inline]
    #[must_use]
    pub const fn to_array(self) -> [f32; COMPONENT_COUNT] {
        [self.dfx_n_per_mm, self.dfy_n_per_mm, self.dfz_n_per_mm, self.dmx_nmm_per_mm, self.dmy_nmm_per_mm, self.dmz_nmm_per_mm]
    }

    /// Rates from `[fx, fy, fz, mx, my, mz]` (N/mm and N·mm/mm).
    #[inline]
    #[must_use]
    pub const fn from_array(a: [f32; COMPONENT_COUNT]) -> Self {
        let [dfx_n_per_mm, dfy_n_per_mm, dfz_n_per_mm, dmx_nmm_per_mm, dmy_nmm_per_mm, dmz_nmm_per_mm] = a;
        Self { dfx_n_per_mm, dfy_n_per_mm, dfz_n_per_mm, dmx_nmm_per_mm, dmy_nmm_per_mm, dmz_nmm_per_mm }
    }
}

/// The exact partial derivatives of the model's wrench at a pose (the model is a
/// polynomial in depth and in `|x|`, `|z|`; see
/// [`wrench_and_stiffness`](crate::wrench_and_stiffness) for the rules at `x = 0`,
/// `z = 0` and on the domain's edges).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Stiffness {
    /// d wrench / d depth_mm: `by_depth.dfy_n_per_mm` is the axial stiffness the hand
    /// feels (the reaction `fy_n` points up, against the insertion, and grows with depth).
    pub by_depth: WrenchRate,
    /// d wrench / d x_mm (insertion point moved along x).
    pub by_x: WrenchRate,
    /// d wrench / d z_mm (insertion point moved along z).
    pub by_z: WrenchRate,
}

impl Stiffness {
    /// Every rate `+0.0`.
    pub const ZERO: Self = Self { by_depth: WrenchRate::ZERO, by_x: WrenchRate::ZERO, by_z: WrenchRate::ZERO };
}

/// The result of [`wrench_and_stiffness`](crate::wrench_and_stiffness): the wrench (the
/// same bits as [`wrench`](crate::wrench)), its stiffness and the status.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct StiffnessEvaluation {
    /// The reaction wrench (N, N·mm); zero when `status.is_error()`.
    pub wrench: Wrench,
    /// Its partial derivatives; zero when `status.is_error()`, and zero along every input
    /// that was clamped to the domain.
    pub stiffness: Stiffness,
    /// As for [`wrench`](crate::wrench).
    pub status: Status,
}
