//! Virtual time from SysTick: the free-running 24-bit counter (started by the
//! calibration) extended to 64 bits, and its conversion to instructions.
use crate::common::icount::{elapsed, Calibration};
use cortex_m::peripheral::SYST;

/// SysTick ticks since the clock was made. Read it at least once per 2^24 SysTick ticks
/// (the control task reads it every period).
pub struct Clock {
    last: u32,
    ticks: u64,
    /// Instructions of the calibration and the SysTick ticks they took.
    instructions: u64,
    per_ticks: u64,
}

impl Clock {
    /// A clock reading from now, converting with `cal`.
    pub fn new(cal: &Calibration) -> Self {
        Self { last: SYST::get_current(), ticks: 0, instructions: cal.instructions, per_ticks: cal.ticks.max(1) }
    }

    /// SysTick ticks since [`Clock::new`].
    pub fn now(&mut self) -> u64 {
        let current = SYST::get_current();
        self.ticks += u64::from(elapsed(self.last, current));
        self.last = current;
        self.ticks
    }

    /// `ticks` SysTick ticks in instructions (1 ns of virtual time each), rounded.
    pub fn instructions(&self, ticks: u64) -> u64 {
        (ticks * self.instructions + self.per_ticks / 2) / self.per_ticks
    }
}
