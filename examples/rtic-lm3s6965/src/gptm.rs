//! General-purpose timer 0 of the LM3S6965 (GPTM, datasheet DS-LM3S6965 chapter
//! "General-Purpose Timers"), timer A as one 32-bit down-counter. The device crate has
//! no register API, so this module writes the documented registers; it is the only
//! `unsafe` register access of the example.
use core::ptr::{read_volatile, write_volatile};

/// Run-mode clock gating control register 1 (System Control); bit 16 clocks Timer 0.
const SYSCTL_RCGC1: usize = 0x400f_e104;
const RCGC1_TIMER0: u32 = 1 << 16;
/// Timer 0 base address.
const BASE: usize = 0x4003_0000;
/// Configuration (0: one 32-bit timer).
const CFG: usize = 0x000;
/// Timer A mode (1: one-shot, 2: periodic).
const TAMR: usize = 0x004;
/// Control (bit 0 TAEN: timer A enabled).
const CTL: usize = 0x00c;
/// Interrupt mask (bit 0 TATOIM: time-out interrupt enabled).
const IMR: usize = 0x018;
/// Raw interrupt status (bit 0 TATORIS: timer A timed out).
const RIS: usize = 0x01c;
/// Interrupt clear (write 1 to bit 0 to clear TATORIS).
const ICR: usize = 0x024;
/// Timer A interval load (the period in timer clocks).
const TAILR: usize = 0x028;
const TIMEOUT: u32 = 1;

fn write(offset: usize, v: u32) {
    // SAFETY: an aligned, documented Timer 0 register; only this module touches Timer 0.
    unsafe { write_volatile((BASE + offset) as *mut u32, v) }
}

fn read(offset: usize) -> u32 {
    // SAFETY: as in `write`.
    unsafe { read_volatile((BASE + offset) as *const u32) }
}

/// Timer 0, timer A. Owning it is owning the peripheral: create it once, in `init`.
pub struct Timer0 {
    _private: (),
}

impl Timer0 {
    /// Clocks Timer 0 and stops it.
    ///
    /// # Safety
    /// Once per program: the value owns Timer 0.
    pub unsafe fn take() -> Self {
        // SAFETY: read-modify-write of the clock gating register in `init`, interrupts off.
        unsafe {
            let rcgc1 = read_volatile(SYSCTL_RCGC1 as *const u32);
            write_volatile(SYSCTL_RCGC1 as *mut u32, rcgc1 | RCGC1_TIMER0);
        }
        let t = Self { _private: () };
        t.stop();
        t
    }

    /// Starts timer A: `periodic` (reloads and times out every `load` clocks) or one-shot,
    /// its time-out interrupt `interrupt` enabled or masked.
    pub fn start(&self, load: u32, periodic: bool, interrupt: bool) {
        self.stop();
        write(CFG, 0);
        write(TAMR, if periodic { 2 } else { 1 });
        write(TAILR, load);
        write(ICR, TIMEOUT);
        write(IMR, if interrupt { TIMEOUT } else { 0 });
        write(CTL, 1);
    }

    /// Stops timer A and masks its interrupt.
    pub fn stop(&self) {
        write(CTL, 0);
        write(IMR, 0);
    }

    /// Whether timer A has timed out since the last [`Timer0::clear`].
    pub fn timed_out(&self) -> bool {
        read(RIS) & TIMEOUT != 0
    }

    /// Clears the time-out (the interrupt's acknowledge).
    pub fn clear(&self) {
        write(ICR, TIMEOUT);
    }
}
