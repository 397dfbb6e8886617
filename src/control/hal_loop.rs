//! [`ControlLoop`]: [`LoopCore`] wired to a [`PoseSource`] and embedded-hal 1.0 outputs.
use super::{ConfigError, LoopConfig, LoopCore, LoopFlags, PoseSource, Sample};
use embedded_hal::digital::{OutputPin, PinState};
use embedded_hal::pwm::SetDutyCycle;

/// One motor channel: a PWM output for the magnitude and a pin for the direction.
///
/// Boards whose channels are different types can use `&mut dyn SetDutyCycle<Error = E>`
/// and `&mut dyn OutputPin<Error = E>` (embedded-hal implements both traits for `&mut T`).
#[derive(Debug)]
pub struct Channel<PWM, DIR> {
    /// The motor driver's PWM input.
    pub pwm: PWM,
    /// The motor driver's direction input.
    pub dir: DIR,
}

/// A haptic control loop over `N` motor channels.
///
/// Each [`tick`](Self::tick) reads the pose from `P`, runs [`LoopCore::step`], and writes,
/// channel by channel in order, the direction pin then the duty cycle, then the enable
/// pin (high unless the loop is `DISABLED`). Every output is written every tick. A
/// failed write sets `OUTPUT_ERROR` in the tick's flags and the remaining outputs are
/// still written. No allocation, no panic, no blocking beyond what the HAL's writes do.
#[derive(Debug)]
pub struct ControlLoop<P, PWM, DIR, EN, const N: usize> {
    core: LoopCore<N>,
    source: P,
    channels: [Channel<PWM, DIR>; N],
    max_duty: [u16; N],
    enable: EN,
}

impl<P, PWM, DIR, EN, const N: usize> ControlLoop<P, PWM, DIR, EN, N>
where
    P: PoseSource,
    PWM: SetDutyCycle,
    DIR: OutputPin,
    EN: OutputPin,
{
    /// A loop at rest over these devices. Reads each PWM's `max_duty_cycle()` once;
    /// writes nothing (the first tick sets every output).
    ///
    /// # Errors
    /// The configuration is invalid ([`LoopConfig::validate`]).
    pub fn new(config: LoopConfig<N>, source: P, channels: [Channel<PWM, DIR>; N], enable: EN) -> Result<Self, ConfigError> {
        let core = LoopCore::new(config)?;
        let max_duty = channels.each_ref().map(|c| c.pwm.max_duty_cycle());
        Ok(Self { core, source, channels, max_duty, enable })
    }

    /// One tick: read the pose, evaluate, map, write every output; the tick's record.
    pub fn tick(&mut self) -> Sample {
        let reading = self.source.read_pose();
        self.core.step(reading);
        let mut failed = false;
        let commands = *self.core.commands();
        for ((ch, cmd), max) in self.channels.iter_mut().zip(commands.iter()).zip(self.max_duty.iter()) {
            failed |= ch.dir.set_state(PinState::from(cmd.direction_high)).is_err();
            failed |= ch.pwm.set_duty_cycle(cmd.duty(*max)).is_err();
        }
        failed |= self.enable.set_state(PinState::from(self.core.enabled())).is_err();
        if failed {
            self.core.add_flags(LoopFlags::OUTPUT_ERROR);
        }
        *self.core.last()
    }

    /// The control law, its configuration and its last sample.
    #[inline]
    #[must_use]
    pub const fn core(&self) -> &LoopCore<N> {
        &self.core
    }

    /// The control law, to change its force limit or over-limit mode (the host link's
    /// commands do this through [`crate::command`]).
    #[inline]
    pub fn core_mut(&mut self) -> &mut LoopCore<N> {
        &mut self.core
    }

    /// Each channel's full-scale duty, as read at construction.
    #[inline]
    #[must_use]
    pub const fn max_duty(&self) -> &[u16; N] {
        &self.max_duty
    }

    /// The devices back, to tear the loop down (outputs are left as last written).
    pub fn release(self) -> (P, [Channel<PWM, DIR>; N], EN) {
        (self.source, self.channels, self.enable)
    }
}
