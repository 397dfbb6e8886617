//! Firmware example `no_panic`: proves at link time that the evaluator has no panic path.
//!
//! Its `#[panic_handler]` calls `needle_haptics_panic_path_not_optimised_away`, an
//! `extern "C"` function that is defined nowhere. The firmware therefore links only if
//! the optimiser removed every call to the panic handler, i.e. if nothing reachable from
//! `main` (the evaluator [`needle_haptics::wrench`] called through an opaque function
//! pointer on an opaque pose, so it is compiled for every input, plus the small
//! [`needle_haptics::Wrench`] / [`needle_haptics::Status`] helpers) can panic. Build it
//! in release (the crate's release profile: opt-level 3, LTO):
//!
//! ```text
//! cargo build --release --example no_panic --target thumbv6m-none-eabi
//! ```
//!
//! A link error naming that symbol means a panic path (an index, an unwrap, an overflow
//! check, a division) is left in the evaluator: find it with
//! `arm-none-eabi-objdump -d` on a build whose handler is defined.
//!
//! It is also the smallest firmware that contains the model (no formatting code, no
//! static data of its own), so `needle firmware size` measures the model's flash and RAM
//! on it. Run under QEMU, it evaluates one pose and exits with status 0.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod panic_gate;

#[cfg(target_os = "none")]
mod firmware {
    use core::hint::black_box;
    use needle_haptics::{wrench, Evaluation, Pose};

    #[cortex_m_rt::entry]
    fn main() -> ! {
        let eval: fn(&Pose) -> Evaluation = black_box(wrench);
        let pose = black_box(Pose::new(3.0, -2.0, 5.0, -7.0, 4.5));
        let e = eval(&pose);
        let about_tip = e.wrench.about(black_box([0.0, -60.0, 0.0]));
        black_box((e.status.bits(), e.status.is_error(), e.status.saturated(), about_tip));
        crate::panic_gate::exit_success()
    }
}

/// On the host this example does nothing: it is firmware.
#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("`no_panic` is firmware: cargo build --release --example no_panic --target thumbv7em-none-eabihf");
}
