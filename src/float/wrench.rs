//! [`Wrench`]: the reaction force and moment of the tissue on the needle.
use needle_contract::COMPONENT_COUNT;

/// Reaction wrench of the tissue on the needle, in the block frame (`docs/architecture.md` §3).
///
/// Forces in newtons, moments in newton millimetres. The model's moments are about the
/// needle's reference point: on the needle axis, `needle.reference_from_tip_mm` from the
/// tip (the hub, 60 mm for the default set; it moves with the needle). Use
/// [`Wrench::about`] for another point.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Wrench {
    /// Force along x, N.
    pub fx_n: f32,
    /// Force along y (up), N.
    pub fy_n: f32,
    /// Force along z, N.
    pub fz_n: f32,
    /// Moment about x, N·mm.
    pub mx_nmm: f32,
    /// Moment about y, N·mm.
    pub my_nmm: f32,
    /// Moment about z, N·mm.
    pub mz_nmm: f32,
}

impl Wrench {
    /// The zero wrench (every component `+0.0`).
    pub const ZERO: Self = Self::from_array([0.0; COMPONENT_COUNT]);

    /// The six components in the model's order: `[fx_n, fy_n, fz_n, mx_nmm, my_nmm, mz_nmm]`.
    #[inline]
    #[must_use]
    pub const fn to_array(self) -> [f32; COMPONENT_COUNT] {
        [self.fx_n, self.fy_n, self.fz_n, self.mx_nmm, self.my_nmm, self.mz_nmm]
    }

    /// A wrench from `[fx_n, fy_n, fz_n, mx_nmm, my_nmm, mz_nmm]` (N and N·mm).
    #[inline]
    #[must_use]
    pub const fn from_array(a: [f32; COMPONENT_COUNT]) -> Self {
        let [fx_n, fy_n, fz_n, mx_nmm, my_nmm, mz_nmm] = a;
        Self { fx_n, fy_n, fz_n, mx_nmm, my_nmm, mz_nmm }
    }

    /// The same wrench with its moments taken about another point.
    ///
    /// `offset_mm` is the vector, in the block frame and in mm, from the current
    /// reference point (the hub for a model wrench) to the new point P. The force is
    /// unchanged; the moment becomes `M_P = M - offset × F`, in N·mm. For example, for a
    /// vertical needle with the hub 60 mm above the tip, the moment about the tip is
    /// `w.about([0.0, -60.0, 0.0])`.
    ///
    /// Plain f32 arithmetic in the order written (`mx - (oy*fz - oz*fy)` etc.); not part
    /// of the bit-exact model contract.
    #[inline]
    #[must_use]
    pub fn about(self, offset_mm: [f32; 3]) -> Self {
        let [ox, oy, oz] = offset_mm;
        let Self { fx_n, fy_n, fz_n, mx_nmm, my_nmm, mz_nmm } = self;
        Self {
            fx_n,
            fy_n,
            fz_n,
            mx_nmm: mx_nmm - (oy * fz_n - oz * fy_n),
            my_nmm: my_nmm - (oz * fx_n - ox * fz_n),
            mz_nmm: mz_nmm - (ox * fy_n - oy * fx_n),
        }
    }
}
