//! The link-time panic gate of the `no_panic*` firmware examples (bare metal only).
//!
//! Its `#[panic_handler]` calls `needle_haptics_panic_path_not_optimised_away`, an
//! `extern "C"` function that is defined nowhere. A firmware that holds this module
//! therefore links only if the optimiser removed every call to the panic handler, i.e. if
//! nothing reachable from its `main` can panic. A link error naming that symbol means a
//! panic path (an index, an unwrap, an overflow check, a division) is left: find it with
//! `arm-none-eabi-objdump -d` on a build whose handler is defined.

use core::panic::PanicInfo;
use cortex_m_semihosting::debug;

extern "C" {
    /// Defined nowhere: a reference left to it is a link error.
    fn needle_haptics_panic_path_not_optimised_away() -> !;
}

#[panic_handler]
fn panic(_info: &PanicInfo) -> ! {
    // SAFETY: never runs; if a call to the handler survives optimisation, the firmware
    // does not link, which is the point of the gate.
    unsafe { needle_haptics_panic_path_not_optimised_away() }
}

/// Ends the QEMU run with exit status 0 (semihosting), and never returns.
pub fn exit_success() -> ! {
    debug::exit(debug::EXIT_SUCCESS);
    loop {
        cortex_m::asm::bkpt();
    }
}
