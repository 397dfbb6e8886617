//! [`Wrench`] in fixed point (micro-newtons) and the fixed-point [`Evaluation`].
use crate::Status;
use needle_contract::COMPONENT_COUNT;

/// Reaction wrench of the tissue on the needle in integers: forces in micro-newtons
/// (µN, 10^-6 N), moments in micro-newton millimetres (µN·mm), about the needle's
/// reference point; frame and meaning as in [`crate::Wrench`].
///
/// Range: the code generator proves every component's magnitude below 2^30 µN
/// (1073 N, or N·mm) over the whole domain, or refuses the model; resolution 1 µN, far
/// below the model's error bound ([`tables::ERROR_BOUND_MICRO`](super::tables::ERROR_BOUND_MICRO)).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Wrench {
    /// Force along x, µN.
    pub fx_un: i32,
    /// Force along y (up), µN.
    pub fy_un: i32,
    /// Force along z, µN.
    pub fz_un: i32,
    /// Moment about x, µN·mm.
    pub mx_unmm: i32,
    /// Moment about y, µN·mm.
    pub my_unmm: i32,
    /// Moment about z, µN·mm.
    pub mz_unmm: i32,
}

impl Wrench {
    /// The zero wrench.
    pub const ZERO: Self = Self::from_array([0; COMPONENT_COUNT]);

    /// The six components in the model's order: `[fx_un, fy_un, fz_un, mx_unmm, my_unmm, mz_unmm]`.
    #[inline]
    #[must_use]
    pub const fn to_array(self) -> [i32; COMPONENT_COUNT] {
        [self.fx_un, self.fy_un, self.fz_un, self.mx_unmm, self.my_unmm, self.mz_unmm]
    }

    /// A wrench from `[fx_un, fy_un, fz_un, mx_unmm, my_unmm, mz_unmm]` (µN and µN·mm).
    #[inline]
    #[must_use]
    pub const fn from_array(a: [i32; COMPONENT_COUNT]) -> Self {
        let [fx_un, fy_un, fz_un, mx_unmm, my_unmm, mz_unmm] = a;
        Self { fx_un, fy_un, fz_un, mx_unmm, my_unmm, mz_unmm }
    }
}

/// The result of a fixed-point evaluation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Evaluation {
    /// The reaction wrench (µN, µN·mm); zero when `status.is_error()`.
    pub wrench: Wrench,
    /// Saturation flags of the inputs, or `NO_MODEL | ERROR` when no model is compiled in.
    pub status: Status,
}
