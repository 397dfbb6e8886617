//! [`PoseSource`]: where the control loop reads the needle's pose each tick.
use crate::Pose;

/// Why a [`PoseSource`] has no fresh pose this tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum PoseFault {
    /// The last pose is too old (for example an encoder read that timed out, or a
    /// kinematics update that did not arrive since the previous tick).
    Stale,
    /// No pose at all (encoders not homed, sensor disconnected).
    Missing,
}

impl core::fmt::Display for PoseFault {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Self::Stale => "pose stale: the last pose is older than one tick",
            Self::Missing => "pose missing: no pose available (encoders not homed or sensor disconnected)",
        })
    }
}

impl core::error::Error for PoseFault {}

/// A source of the needle's pose, implemented by the board from its encoders and
/// kinematics.
///
/// The control loop calls [`read_pose`](Self::read_pose) exactly once per tick, from
/// the loop's context (typically a timer interrupt): it must not block.
pub trait PoseSource {
    /// The pose now, or why there is none.
    ///
    /// # Errors
    /// [`PoseFault::Stale`] or [`PoseFault::Missing`]: the loop then ramps its output to
    /// zero and reports the fault in its flags.
    fn read_pose(&mut self) -> Result<Pose, PoseFault>;
}

impl<T: PoseSource + ?Sized> PoseSource for &mut T {
    #[inline]
    fn read_pose(&mut self) -> Result<Pose, PoseFault> {
        T::read_pose(self)
    }
}
