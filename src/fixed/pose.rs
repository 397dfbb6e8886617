//! [`Pose`] in fixed point: the five pose inputs as Q16.16 integers.

/// The needle's pose in fixed point: each input is an `i32` in Q16.16, the value in mm or
/// degrees times 65536 ([`Pose::ONE`]). Frame and meaning as in [`crate::Pose`].
///
/// | field | unit | scale | domain (saturated beyond) |
/// | --- | --- | --- | --- |
/// | `x_mm_q16`, `z_mm_q16` | mm | 2^-16 mm (15.3 nm) | `±12 mm` = `±786_432` |
/// | `theta_x_deg_q16`, `theta_z_deg_q16` | degree | 2^-16 ° | `±15°` = `±983_040` |
/// | `depth_mm_q16` | mm | 2^-16 mm | `0 ..= 6 mm` = `0 ..= 393_216` |
///
/// Every `i32` is a valid input: values outside the domain are clamped to it and
/// reported in the [`Status`](crate::Status) (`SAT_*` flags), as in the f32 evaluator.
/// There is no NaN in integers, so [`fixed::wrench`](super::wrench) never reports
/// `ERROR` for a pose (only `NO_MODEL | ERROR` when no model is compiled in).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct Pose {
    /// x of the insertion point on the top surface, mm × 65536.
    pub x_mm_q16: i32,
    /// z of the insertion point on the top surface, mm × 65536.
    pub z_mm_q16: i32,
    /// Tilt about x away from the y axis, degrees × 65536.
    pub theta_x_deg_q16: i32,
    /// Tilt about z away from the y axis, degrees × 65536.
    pub theta_z_deg_q16: i32,
    /// Insertion depth along the needle's axis, mm × 65536.
    pub depth_mm_q16: i32,
}

impl Pose {
    /// 1 mm or 1 degree in Q16.16.
    pub const ONE: i32 = 1 << 16;

    /// A pose from its five Q16.16 inputs (mm, mm, degrees, degrees, mm, each × 65536).
    #[inline]
    #[must_use]
    pub const fn new(x_mm_q16: i32, z_mm_q16: i32, theta_x_deg_q16: i32, theta_z_deg_q16: i32, depth_mm_q16: i32) -> Self {
        Self { x_mm_q16, z_mm_q16, theta_x_deg_q16, theta_z_deg_q16, depth_mm_q16 }
    }

    /// The five inputs in contract order `[x, z, theta_x, theta_z, depth]`.
    #[inline]
    #[must_use]
    pub const fn to_array(self) -> [i32; 5] {
        [self.x_mm_q16, self.z_mm_q16, self.theta_x_deg_q16, self.theta_z_deg_q16, self.depth_mm_q16]
    }
}
