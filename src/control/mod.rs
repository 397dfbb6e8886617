//! The haptic control loop: pose in, model wrench, force limit and safety ramp, duty
//! cycles and direction pins out, on embedded-hal 1.0.
//!
//! - [`PoseSource`]: the board's pose (from encoders and kinematics), or why there is none;
//! - [`LoopConfig`]: the linear map from force to each channel's command, the device force
//!   limit, what happens above it ([`OverLimit`]), the ramp step of the safety ramp;
//! - [`Passivity`]: the optional guard that keeps the rendered stiffness passive;
//! - [`LoopCore`]: the control law of one tick, no hardware (the C API drives it);
//! - [`ControlLoop`]: the law wired to `SetDutyCycle` / `OutputPin` outputs;
//! - [`Sample`] and [`LoopFlags`]: what each tick did and why.
//!
//! ```
//! use core::convert::Infallible;
//! use embedded_hal::{digital::{ErrorType as PinErr, OutputPin}, pwm::{ErrorType as PwmErr, SetDutyCycle}};
//! use needle_haptics::control::*;
//! use needle_haptics::Pose;
//!
//! struct Encoders;
//! impl PoseSource for Encoders {
//!     fn read_pose(&mut self) -> Result<Pose, PoseFault> { Ok(Pose::new(0.0, 0.0, 0.0, 0.0, 4.0)) }
//! }
//! #[derive(Default)] struct Pwm(u16);
//! impl PwmErr for Pwm { type Error = Infallible; }
//! impl SetDutyCycle for Pwm {
//!     fn max_duty_cycle(&self) -> u16 { 1000 }
//!     fn set_duty_cycle(&mut self, d: u16) -> Result<(), Infallible> { self.0 = d; Ok(()) }
//! }
//! #[derive(Default)] struct Pin(bool);
//! impl PinErr for Pin { type Error = Infallible; }
//! impl OutputPin for Pin {
//!     fn set_low(&mut self) -> Result<(), Infallible> { self.0 = false; Ok(()) }
//!     fn set_high(&mut self) -> Result<(), Infallible> { self.0 = true; Ok(()) }
//! }
//!
//! # fn main() -> Result<(), ConfigError> {
//! // One motor pushing along y: full scale at 2 N.
//! let config = LoopConfig {
//!     channels: [ChannelMap { gains_per_n: [0.0, 0.5, 0.0], direction_inverted: false }],
//!     force_limit_n: 1.5,
//!     force_limit_max_n: 2.0,
//!     over_limit: OverLimit::Saturate,
//!     ramp_step_n: 0.01,
//! };
//! let mut l = ControlLoop::new(config, Encoders, [Channel { pwm: Pwm::default(), dir: Pin::default() }], Pin::default())?;
//! let s = l.tick();
//! assert_eq!(s.tick, 1);
//! assert!(!s.flags.contains(LoopFlags::RAMPING));
//! # Ok(())
//! # }
//! ```
mod config;
mod core;
mod flags;
mod hal_loop;
#[cfg(feature = "shaft-presliding")]
mod held_bristle;
mod passivity;
mod pose_source;
mod sample;

pub use self::core::{ChannelCommand, LoopCore};
pub use config::{ChannelMap, ConfigError, LoopConfig, OverLimit};
pub use flags::LoopFlags;
pub use hal_loop::{Channel, ControlLoop};
#[cfg(feature = "shaft-presliding")]
pub use held_bristle::HELD_SHARE;
pub use passivity::{Passivity, GUARD_FRACTION};
pub use pose_source::{PoseFault, PoseSource};
pub use sample::Sample;
