//! [`Sample`]: what one control-loop tick read, computed and commanded.
use super::LoopFlags;
use crate::{Pose, Status, Wrench};

/// The record of one tick, returned by the tick and sent to telemetry.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Sample {
    /// Tick count: 1 for the first tick, wrapping after `u32::MAX`.
    pub tick: u32,
    /// The pose evaluated this tick; on a stale or missing pose, the last pose the
    /// source delivered (all zero before the first one).
    pub pose: Pose,
    /// The model's wrench this tick; zero when the pose was stale or missing (the model
    /// was not evaluated) or the model returned an error.
    pub wrench: Wrench,
    /// The model's status this tick ([`Status::OK`] when it was not evaluated).
    pub model: Status,
    /// What the loop did and why.
    pub flags: LoopFlags,
    /// The force commanded to the motors (fx, fy, fz), N, after the limit and the ramp.
    pub force_cmd_n: [f32; 3],
}
