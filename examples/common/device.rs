//! A stand-in motor driver for the loop examples: PWM channels and pins that store
//! into memory-mapped-like words with volatile writes (what a real HAL's register write
//! costs), and the loop configuration the examples share.
use core::convert::Infallible;
use core::ptr::addr_of_mut;
use embedded_hal::digital::{ErrorType as PinError, OutputPin};
use embedded_hal::pwm::{ErrorType as PwmError, SetDutyCycle};
use needle_haptics::control::{ChannelMap, LoopConfig, OverLimit};

/// The "registers": duty of each channel, then direction pins, then enable.
static mut REGS: [u32; 8] = [0; 8];

fn write_reg(i: usize, v: u32) {
    if let Some(r) = unsafe { (*addr_of_mut!(REGS)).get_mut(i) } {
        // SAFETY: a valid, aligned word of a static; single-core, no concurrent access.
        unsafe { core::ptr::write_volatile(r, v) };
    }
}

/// The last value written to register `i`.
pub fn read_reg(i: usize) -> u32 {
    // SAFETY: as in write_reg.
    unsafe { (*addr_of_mut!(REGS)).get(i).map_or(0, |r| core::ptr::read_volatile(r)) }
}

/// A PWM channel writing its duty to register `index`; full scale 1000.
pub struct RegPwm(pub usize);

impl PwmError for RegPwm {
    type Error = Infallible;
}

impl SetDutyCycle for RegPwm {
    fn max_duty_cycle(&self) -> u16 {
        1000
    }
    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Infallible> {
        write_reg(self.0, u32::from(duty));
        Ok(())
    }
}

/// A pin writing 0/1 to register `index`.
pub struct RegPin(pub usize);

impl PinError for RegPin {
    type Error = Infallible;
}

impl OutputPin for RegPin {
    fn set_low(&mut self) -> Result<(), Infallible> {
        write_reg(self.0, 0);
        Ok(())
    }
    fn set_high(&mut self) -> Result<(), Infallible> {
        write_reg(self.0, 1);
        Ok(())
    }
}

/// Three channels (x, y, z motors) at full scale for 0.1 N, limit 0.06 N saturating.
pub const CONFIG: LoopConfig<3> = LoopConfig {
    channels: [
        ChannelMap { gains_per_n: [10.0, 0.0, 0.0], direction_inverted: false },
        ChannelMap { gains_per_n: [0.0, 10.0, 0.0], direction_inverted: false },
        ChannelMap { gains_per_n: [0.0, 0.0, 10.0], direction_inverted: true },
    ],
    force_limit_n: 0.06,
    force_limit_max_n: 0.1,
    over_limit: OverLimit::Saturate,
    ramp_step_n: 0.002,
};
