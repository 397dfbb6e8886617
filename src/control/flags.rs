//! [`LoopFlags`]: what the control loop did in a tick, and why.
use core::fmt;

/// Bit flags of one control-loop tick (the model's own [`Status`](crate::Status) is
/// reported beside them).
///
/// | flag | bit | meaning |
/// | --- | --- | --- |
/// | [`POSE_STALE`](Self::POSE_STALE) | `0x0001` | the pose source reported a stale pose: not evaluated |
/// | [`POSE_MISSING`](Self::POSE_MISSING) | `0x0002` | the pose source had no pose: not evaluated |
/// | [`EVAL_ERROR`](Self::EVAL_ERROR) | `0x0004` | the model returned `ERROR` (NaN input or no model) |
/// | [`OVER_LIMIT`](Self::OVER_LIMIT) | `0x0008` | the model's force magnitude was above the device force limit |
/// | [`FORCE_SATURATED`](Self::FORCE_SATURATED) | `0x0010` | the commanded force was scaled down to the limit ([`OverLimit::Saturate`](super::OverLimit::Saturate)) |
/// | [`RAMPING`](Self::RAMPING) | `0x0020` | a fault holds: the command ramps towards zero instead of following the model |
/// | [`DUTY_CLIPPED`](Self::DUTY_CLIPPED) | `0x0040` | a channel's command was beyond full scale and was clipped to the maximum duty |
/// | [`OUTPUT_ERROR`](Self::OUTPUT_ERROR) | `0x0080` | a PWM or pin write returned an error (the other outputs were still written) |
/// | [`DISABLED`](Self::DISABLED) | `0x0100` | the enable pin is low: a fault holds and the ramp has reached zero |
/// | [`STIFFNESS_LIMITED`](Self::STIFFNESS_LIMITED) | `0x0200` | the model's stiffness was above the passivity guard's: its force changes entered the command scaled down ([`Passivity`](super::Passivity)) |
/// | [`POSE_GLITCH`](Self::POSE_GLITCH) | `0x0400` | the insertion rejected the pose as a glitch ([`InsertionFlags`](crate::InsertionFlags): out of its domain, too fast, not finite): not integrated; the passivity guard keeps its state |
///
/// A tick is a *fault* tick when any of `POSE_STALE`, `POSE_MISSING`, `EVAL_ERROR`,
/// `POSE_GLITCH`, or `OVER_LIMIT` with [`OverLimit::RampToZero`](super::OverLimit::RampToZero) is set.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct LoopFlags(u16);

impl LoopFlags {
    /// Nothing to report: the output follows the model.
    pub const OK: Self = Self(0);
    /// The pose source reported a stale pose.
    pub const POSE_STALE: Self = Self(0x0001);
    /// The pose source had no pose.
    pub const POSE_MISSING: Self = Self(0x0002);
    /// The model returned an error status.
    pub const EVAL_ERROR: Self = Self(0x0004);
    /// The model's force magnitude exceeded the device force limit.
    pub const OVER_LIMIT: Self = Self(0x0008);
    /// The command was scaled down to the force limit.
    pub const FORCE_SATURATED: Self = Self(0x0010);
    /// The command ramps towards zero because of a fault.
    pub const RAMPING: Self = Self(0x0020);
    /// A channel was clipped to full duty.
    pub const DUTY_CLIPPED: Self = Self(0x0040);
    /// A PWM or pin write failed.
    pub const OUTPUT_ERROR: Self = Self(0x0080);
    /// The enable pin is low.
    pub const DISABLED: Self = Self(0x0100);
    /// The passivity guard limited the rendered stiffness.
    pub const STIFFNESS_LIMITED: Self = Self(0x0200);
    /// The insertion rejected the pose as a glitch.
    pub const POSE_GLITCH: Self = Self(0x0400);

    /// Every flag with its name, in bit order.
    pub const FLAGS: [(Self, &'static str); 11] = [
        (Self::POSE_STALE, "POSE_STALE"),
        (Self::POSE_MISSING, "POSE_MISSING"),
        (Self::EVAL_ERROR, "EVAL_ERROR"),
        (Self::OVER_LIMIT, "OVER_LIMIT"),
        (Self::FORCE_SATURATED, "FORCE_SATURATED"),
        (Self::RAMPING, "RAMPING"),
        (Self::DUTY_CLIPPED, "DUTY_CLIPPED"),
        (Self::OUTPUT_ERROR, "OUTPUT_ERROR"),
        (Self::DISABLED, "DISABLED"),
        (Self::STIFFNESS_LIMITED, "STIFFNESS_LIMITED"),
        (Self::POSE_GLITCH, "POSE_GLITCH"),
    ];

    /// `true` when no flag is set.
    #[inline]
    #[must_use]
    pub const fn is_ok(self) -> bool {
        self.0 == 0
    }

    /// `true` when at least one flag of `other` is set here.
    #[inline]
    #[must_use]
    pub const fn intersects(self, other: Self) -> bool {
        self.0 & other.0 != 0
    }

    /// These flags with those of `other` added.
    #[inline]
    #[must_use]
    pub const fn with(self, other: Self) -> Self {
        Self(self.0 | other.0)
    }
}

crate::bit_flags::flag_bits!(LoopFlags, u16);

/// The flag names joined by ` | `, or `OK`; bits no flag names in hex.
impl fmt::Display for LoopFlags {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let named = Self::FLAGS.map(|(flag, name)| (u32::from(flag.0), name));
        crate::bit_flags::write_names(f, u32::from(self.0), &named, 4)
    }
}

/// `LoopFlags(0x0021: RAMPING | POSE_STALE)` style.
impl fmt::Debug for LoopFlags {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "LoopFlags({:#06x}: {})", self.0, self)
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for LoopFlags {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(f, "LoopFlags({=u16:#06x})", self.0);
    }
}
