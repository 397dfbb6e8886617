//! [`Stiffness`] in fixed point (micro-newtons per millimetre) and
//! [`StiffnessEvaluation`], a fixed-point wrench with its stiffness.
use super::Wrench;
use crate::Status;
use needle_contract::COMPONENT_COUNT;

/// The rate of change of every wrench component with respect to one input measured in
/// mm, in integers: forces in µN/mm, moments in µN·mm/mm (the f32 [`crate::WrenchRate`]
/// times 10^6, rounded).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct WrenchRate {
    /// d fx / d input, µN/mm.
    pub dfx_un_per_mm: i32,
    /// d fy / d input, µN/mm.
    pub dfy_un_per_mm: i32,
    /// d fz / d input, µN/mm.
    pub dfz_un_per_mm: i32,
    /// d mx / d input, µN·mm/mm.
    pub dmx_unmm_per_mm: i32,
    /// d my / d input, µN·mm/mm.
    pub dmy_unmm_per_mm: i32,
    /// d mz / d input, µN·mm/mm.
    pub dmz_unmm_per_mm: i32,
}

impl WrenchRate {
    /// Every rate zero.
    pub const ZERO: Self = Self::from_array([0; COMPONENT_COUNT]);

    /// The six rates in the model's component order (fx, fy, fz, mx, my, mz).
    #[inline]
    #[must_use]
    pub const fn to_array(self) -> [i32; COMPONENT_COUNT] {
        [self.dfx_un_per_mm, self.dfy_un_per_mm, self.dfz_un_per_mm, self.dmx_unmm_per_mm, self.dmy_unmm_per_mm, self.dmz_unmm_per_mm]
    }

    /// Rates from `[fx, fy, fz, mx, my, mz]` (µN/mm and µN·mm/mm).
    #[inline]
    #[must_use]
    pub const fn from_array(a: [i32; COMPONENT_COUNT]) -> Self {
        let [dfx_un_per_mm, dfy_un_per_mm, dfz_un_per_mm, dmx_unmm_per_mm, dmy_unmm_per_mm, dmz_unmm_per_mm] = a;
        Self { dfx_un_per_mm, dfy_un_per_mm, dfz_un_per_mm, dmx_unmm_per_mm, dmy_unmm_per_mm, dmz_unmm_per_mm }
    }
}

/// The wrench's partial derivatives by depth, x and z in fixed point (see
/// [`wrench_and_stiffness`](super::wrench_and_stiffness) for how they are computed and
/// the rules at `x = 0`, `z = 0` and on the domain's edges).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct Stiffness {
    /// d wrench / d depth: `by_depth.dfy_un_per_mm` is the axial stiffness the hand feels.
    pub by_depth: WrenchRate,
    /// d wrench / d x (insertion point moved along x).
    pub by_x: WrenchRate,
    /// d wrench / d z (insertion point moved along z).
    pub by_z: WrenchRate,
}

impl Stiffness {
    /// Every rate zero.
    pub const ZERO: Self = Self { by_depth: WrenchRate::ZERO, by_x: WrenchRate::ZERO, by_z: WrenchRate::ZERO };
}

/// The result of [`wrench_and_stiffness`](super::wrench_and_stiffness): the wrench (the
/// same integers as [`wrench`](super::wrench)), its stiffness and the status.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StiffnessEvaluation {
    /// The reaction wrench (µN, µN·mm); zero when `status.is_error()`.
    pub wrench: Wrench,
    /// Its partial derivatives; zero when `status.is_error()`, and zero along every input
    /// that was clamped to the domain.
    pub stiffness: Stiffness,
    /// As for [`wrench`](super::wrench).
    pub status: Status,
}
