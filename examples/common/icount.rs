//! Instruction counting under QEMU `-icount shift=0` (see examples/bench.rs for the
//! method): SysTick free-running from the core clock, calibrated with an assembly loop of
//! exactly 2 instructions per iteration.
use core::arch::asm;
use core::hint::black_box;
use cortex_m::peripheral::{syst::SystClkSource, SYST};

/// Iterations of the two calibration loops.
const CAL_SHORT: u32 = 10_000;
const CAL_LONG: u32 = 1_010_000;

/// SysTick ticks between two readings (it counts down from 0xff_ffff and wraps).
pub fn elapsed(start: u32, end: u32) -> u32 {
    start.wrapping_sub(end) & 0x00ff_ffff
}

/// Ticks taken by `n` (>= 1) iterations of a 2-instruction loop.
#[inline(never)]
fn spin(n: u32) -> u32 {
    let start = SYST::get_current();
    // SAFETY: a register-only countdown loop; n >= 1 (callers pass constants).
    unsafe {
        asm!("2:", "subs {n}, #1", "bne 2b", n = inout(reg) n => _, options(nomem, nostack));
    }
    elapsed(start, SYST::get_current())
}

/// Instructions per SysTick tick, measured.
pub struct Calibration {
    /// Instructions of the calibration difference.
    pub instructions: u64,
    /// SysTick ticks they took.
    pub ticks: u64,
    /// Two equal loops took equal ticks (the run is under `-icount`).
    pub deterministic: bool,
}

impl Calibration {
    /// Starts SysTick free-running from the core clock and calibrates it.
    pub fn start(syst: &mut SYST) -> Self {
        syst.set_clock_source(SystClkSource::Core);
        syst.set_reload(0x00ff_ffff);
        syst.clear_current();
        syst.enable_counter();
        let long_a = spin(black_box(CAL_LONG));
        let long_b = spin(black_box(CAL_LONG));
        let short = spin(black_box(CAL_SHORT));
        Self {
            instructions: u64::from(2 * (CAL_LONG - CAL_SHORT)),
            ticks: u64::from(long_a.saturating_sub(short)),
            deterministic: long_a == long_b,
        }
    }

    /// Instructions per call in tenths, rounded, from the ticks of `calls` calls
    /// (`with`) and of the same loop without the call (`without`).
    pub fn tenths_per_call(&self, with: u32, without: u32, calls: u32) -> u64 {
        let num = u64::from(with.saturating_sub(without)) * self.instructions * 10;
        let den = (self.ticks * u64::from(calls)).max(1);
        (num + den / 2) / den
    }
}
