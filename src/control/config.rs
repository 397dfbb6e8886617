//! [`LoopConfig`]: the linear map from force to duty cycles, the force limit, the ramp.

/// What the loop does when the model's force magnitude `|F| = sqrt(fx² + fy² + fz²)` is
/// above the device force limit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum OverLimit {
    /// Command the model's force scaled down to the limit (same direction,
    /// `F * (limit / |F|)`); flags `OVER_LIMIT | FORCE_SATURATED`.
    Saturate,
    /// Treat it as a fault: ramp the previous command towards zero; flags
    /// `OVER_LIMIT | RAMPING`.
    RampToZero,
}

/// How one motor channel's signed command follows the force.
///
/// The channel command is `c = (gains_per_n[0] * fx + gains_per_n[1] * fy) +
/// gains_per_n[2] * fz` in f32, in that order (a fraction of full scale; forces in N),
/// so the gains are in full-scale fractions per newton and carry the channel's sign.
/// The duty is `|c|` of full scale (clipped to 1), the direction pin is high when
/// `(c >= 0) != direction_inverted`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ChannelMap {
    /// Full-scale fraction per newton of `fx`, `fy`, `fz`.
    pub gains_per_n: [f32; 3],
    /// Swap the direction pin's polarity (a motor wired the other way round).
    pub direction_inverted: bool,
}

/// Configuration of a control loop with `N` motor channels.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LoopConfig<const N: usize> {
    /// The linear map of each channel, in channel order.
    pub channels: [ChannelMap; N],
    /// Device force limit on `|F|`, N (> 0, <= `force_limit_max_n`).
    pub force_limit_n: f32,
    /// The largest force limit the host link may set, N (the device's rating).
    pub force_limit_max_n: f32,
    /// What to do above the limit.
    pub over_limit: OverLimit,
    /// During a fault, each commanded force component moves towards zero by at most
    /// this much per tick, N (finite, > 0; a step of `force_limit_max_n` or more cuts to
    /// zero in one tick). Infinity is refused: it is no ramp, and a configuration
    /// computed from a bad value (a division by zero) must not slip through as one.
    pub ramp_step_n: f32,
}

/// Why a [`LoopConfig`] (or a new force limit) was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum ConfigError {
    /// A gain is NaN or infinite.
    Gain,
    /// The force limit is not finite, not > 0, or above `force_limit_max_n`.
    ForceLimit,
    /// The ramp step is NaN or not > 0.
    RampStep,
    /// The passivity guard's damping or period is not finite and > 0.
    Passivity,
}

impl core::fmt::Display for ConfigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Self::Gain => "loop config refused: a channel gain (duty per N) is NaN or infinite",
            Self::ForceLimit => "loop config refused: force_limit_n must be finite, > 0 N and <= force_limit_max_n",
            Self::RampStep => "loop config refused: ramp_step_n must be finite and > 0 N per tick",
            Self::Passivity => "passivity guard refused: damping_n_s_per_mm and period_s must be finite and > 0",
        })
    }
}

impl core::error::Error for ConfigError {}

impl<const N: usize> LoopConfig<N> {
    /// Checks the configuration.
    ///
    /// # Errors
    /// The first [`ConfigError`] found: gains must be finite, `0 < force_limit_n <=
    /// force_limit_max_n` (both finite), `ramp_step_n` finite and > 0.
    pub fn validate(&self) -> Result<(), ConfigError> {
        if !self.channels.iter().all(|c| c.gains_per_n.iter().all(|g| g.is_finite())) {
            return Err(ConfigError::Gain);
        }
        check_limit(self.force_limit_n, self.force_limit_max_n)?;
        if !self.ramp_step_n.is_finite() || self.ramp_step_n <= 0.0 {
            return Err(ConfigError::RampStep);
        }
        Ok(())
    }
}

/// `Ok` when `0 < limit_n <= max_n` and both are finite.
///
/// # Errors
/// [`ConfigError::ForceLimit`] otherwise.
pub(crate) fn check_limit(limit_n: f32, max_n: f32) -> Result<(), ConfigError> {
    if limit_n.is_finite() && max_n.is_finite() && limit_n > 0.0 && limit_n <= max_n {
        Ok(())
    } else {
        Err(ConfigError::ForceLimit)
    }
}
