//! The model's tilt angles from a needle direction or an orientation quaternion, as a
//! device's kinematics gives them.
//!
//! Convention (the FE campaign's, `crates/fe/src/spec.rs`): the needle is rotated
//! first by `theta_x` about x, then by `theta_z` about z, so its axis from tip to hub is
//! `a = (-sin θz cos θx, cos θz cos θx, sin θx)` (vertical: `+y`). Hence, for a unit `a`,
//!
//! ```text
//! theta_x = asin(a_z),    theta_z = atan2(-a_x, a_y)
//! ```
//!
//! (valid for `|theta_x| < 90°`; a twist of the needle about its own axis does not enter
//! the model and is ignored).
//!
//! [`exact`] uses `libm` (correctly rounded or close: < 1 ulp); with the `fast-math`
//! feature the plain functions of this module use `fast`: `micromath`'s `atan2`
//! approximation for both angles (its error in degrees, and in the resulting wrench, is
//! bounded by the `orientation_fast_math` test), cheaper on cores without an FPU. The
//! model's own evaluation never uses it.
use crate::Pose;

/// Needle tilts, degrees.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Tilt {
    /// Rotation about x, degrees.
    pub theta_x_deg: f32,
    /// Rotation about z, degrees.
    pub theta_z_deg: f32,
}

const DEG_PER_RAD: f32 = 180.0 / core::f32::consts::PI;

/// Why no tilt could be taken from a needle axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum AxisError {
    /// A component is NaN or infinite, or the squared length overflows.
    NotFinite,
    /// The axis (or the quaternion) has zero length.
    Zero,
    /// The axis points sideways or downwards (`a_y <= 0`): a tilt of 90 degrees or more,
    /// outside any needle's reach.
    NotUpward,
}

impl core::fmt::Display for AxisError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Self::NotFinite => "needle axis not finite (NaN or infinite component)",
            Self::Zero => "needle axis of zero length",
            Self::NotUpward => "needle axis not upward (a_y <= 0: tilt of 90 degrees or more)",
        })
    }
}

impl core::error::Error for AxisError {}

/// The squared length of `axis` when a tilt can be taken from it.
fn checked_length2(axis: [f32; 3]) -> Result<f32, AxisError> {
    let [ax, ay, az] = axis;
    let n2 = ax * ax + ay * ay + az * az;
    if !n2.is_finite() || !ay.is_finite() {
        Err(AxisError::NotFinite)
    } else if n2 <= 0.0 {
        Err(AxisError::Zero)
    } else if ay <= 0.0 {
        Err(AxisError::NotUpward)
    } else {
        Ok(n2)
    }
}

/// The unit axis (tip to hub) of the orientation quaternion `q = [w, x, y, z]` (the
/// rotation from the vertical needle): `q (0, 1, 0) q*`, computed without normalising `q`
/// first (the tilt functions normalise the axis).
#[must_use]
pub fn axis_of_quaternion(q: [f32; 4]) -> [f32; 3] {
    let [w, x, y, z] = q;
    // R(q) * (0, 1, 0) for a unit quaternion: the second column of the rotation matrix,
    // scaled by |q|^2 for a non-unit one.
    [2.0 * (x * y - w * z), (w * w - x * x + y * y - z * z), 2.0 * (y * z + w * x)]
}

macro_rules! tilt_impl {
    ($sqrt:path, $asin:path, $atan2:path) => {
        /// The tilts of the needle whose axis (tip to hub, any length) is `axis`.
        ///
        /// # Errors
        /// [`super::AxisError`]: `axis` is not finite, zero, or points downwards or
        /// sideways (`a_y <= 0`: the tilt would be 90° or more, outside any needle's reach).
        pub fn tilt_from_axis(axis: [f32; 3]) -> Result<super::Tilt, super::AxisError> {
            let [ax, ay, az] = axis;
            let n = $sqrt(super::checked_length2(axis)?);
            let sz = az / n;
            let sz = if sz > 1.0 {
                1.0
            } else if sz < -1.0 {
                -1.0
            } else {
                sz
            };
            Ok(super::Tilt { theta_x_deg: $asin(sz) * super::DEG_PER_RAD, theta_z_deg: $atan2(-ax, ay) * super::DEG_PER_RAD })
        }

        /// The tilts of the orientation quaternion `q = [w, x, y, z]` (any non-zero
        /// length), see [`super::axis_of_quaternion`].
        ///
        /// # Errors
        /// As [`tilt_from_axis`].
        pub fn tilt_from_quaternion(q: [f32; 4]) -> Result<super::Tilt, super::AxisError> {
            tilt_from_axis(super::axis_of_quaternion(q))
        }
    };
}

/// `libm` versions (the default).
pub mod exact {
    tilt_impl!(needle_fpu::sqrtf, libm::asinf, libm::atan2f);
}

/// `micromath` approximations (feature `fast-math`): both angles from `micromath`'s
/// `atan2` (`theta_x = atan2(a_z, sqrt(a_x² + a_y²))`, the same angle as the `asin` form
/// without its ill-conditioned `asin` approximation; the square root is `libm`'s).
#[cfg(feature = "fast-math")]
pub mod fast {
    /// As [`super::exact::tilt_from_axis`], with `micromath::F32Ext::atan2`.
    ///
    /// # Errors
    /// As [`super::exact::tilt_from_axis`].
    pub fn tilt_from_axis(axis: [f32; 3]) -> Result<super::Tilt, super::AxisError> {
        let [ax, ay, az] = axis;
        super::checked_length2(axis)?;
        let h = needle_fpu::sqrtf(ax * ax + ay * ay);
        Ok(super::Tilt {
            theta_x_deg: micromath::F32Ext::atan2(az, h) * super::DEG_PER_RAD,
            theta_z_deg: micromath::F32Ext::atan2(-ax, ay) * super::DEG_PER_RAD,
        })
    }

    /// As [`super::exact::tilt_from_quaternion`], with [`tilt_from_axis`] above.
    ///
    /// # Errors
    /// As [`super::exact::tilt_from_axis`].
    pub fn tilt_from_quaternion(q: [f32; 4]) -> Result<super::Tilt, super::AxisError> {
        tilt_from_axis(super::axis_of_quaternion(q))
    }
}

#[cfg(not(feature = "fast-math"))]
pub use exact::{tilt_from_axis, tilt_from_quaternion};
#[cfg(feature = "fast-math")]
pub use fast::{tilt_from_axis, tilt_from_quaternion};

/// The pose of a needle entering at (`x_mm`, `z_mm`) on the surface with axis `axis` (tip
/// to hub) at `depth_mm`.
///
/// # Errors
/// As [`tilt_from_axis`].
pub fn pose_from_axis(x_mm: f32, z_mm: f32, axis: [f32; 3], depth_mm: f32) -> Result<Pose, AxisError> {
    tilt_from_axis(axis).map(|t| Pose::new(x_mm, z_mm, t.theta_x_deg, t.theta_z_deg, depth_mm))
}
