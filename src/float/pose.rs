//! [`Pose`]: where the needle is and how far it has gone in.

/// The needle's pose relative to the tissue block (frame of `docs/architecture.md` §3: origin at
/// the centre of the block's top surface, y up, the top surface is the x-z plane).
///
/// The model's domain is `|x_mm|, |z_mm| <= 12`, `|theta_x_deg|, |theta_z_deg| <= 15`,
/// `0 <= depth_mm <= 6` (see [`model_info`](crate::model_info)); an evaluation clamps
/// each input to it and reports which ones it clamped in the
/// [`Status`](crate::Status). NaN or infinite inputs give a zero wrench and
/// [`Status::ERROR`](crate::Status::ERROR).
///
/// `Pose::default()` is the centred, vertical needle touching the surface (all zero).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Pose {
    /// x of the insertion point on the top surface, in mm.
    pub x_mm: f32,
    /// z of the insertion point on the top surface, in mm.
    pub z_mm: f32,
    /// Tilt of the needle away from the y axis by a rotation about x, in degrees.
    pub theta_x_deg: f32,
    /// Tilt of the needle away from the y axis by a rotation about z, in degrees.
    pub theta_z_deg: f32,
    /// Insertion depth along the needle's own axis, in mm (0: the tip touches the surface).
    pub depth_mm: f32,
}

impl Pose {
    /// A pose from its five inputs (mm, mm, degrees, degrees, mm).
    #[inline]
    #[must_use]
    pub const fn new(x_mm: f32, z_mm: f32, theta_x_deg: f32, theta_z_deg: f32, depth_mm: f32) -> Self {
        Self { x_mm, z_mm, theta_x_deg, theta_z_deg, depth_mm }
    }
}
