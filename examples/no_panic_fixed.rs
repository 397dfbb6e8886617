//! Firmware example `no_panic_fixed`: the fixed-point evaluator alone, with a panic
//! handler that cannot link (see `no_panic`): the firmware links only if nothing reachable
//! from `main` ([`needle_haptics::fixed::wrench`] and
//! [`needle_haptics::fixed::wrench_and_stiffness`] through opaque function pointers on an
//! opaque pose, so they are compiled for every input) can panic.
//!
//! It holds no floating-point code at all, so it also shows that the fixed-point path is
//! integer-only (host-tests/tests/firmware_no_panic.rs disassembles it: no soft-float
//! helper in the image on the M0 and M3, no FPU instruction in the evaluator on the M4F),
//! and `needle firmware size` measures the fixed-point model's flash on it.
//!
//! ```text
//! cargo build --release --example no_panic_fixed --target thumbv6m-none-eabi
//! ```
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod panic_gate;

#[cfg(target_os = "none")]
mod firmware {
    use core::hint::black_box;
    use needle_haptics::fixed::{self, Evaluation, Pose};

    #[cortex_m_rt::entry]
    fn main() -> ! {
        let eval: fn(&Pose) -> Evaluation = black_box(fixed::wrench);
        let one = Pose::ONE;
        let pose = black_box(Pose::new(3 * one, -2 * one, 5 * one, -7 * one, 9 * one / 2));
        let e = eval(&pose);
        black_box((e.status.bits(), e.status.is_error(), e.status.saturated(), e.wrench.to_array()));
        let eval_stiffness: fn(&Pose) -> fixed::StiffnessEvaluation = black_box(fixed::wrench_and_stiffness);
        let f = eval_stiffness(&pose);
        black_box((f.status.bits(), f.wrench.to_array(), f.stiffness.by_depth.to_array(), f.stiffness.by_x, f.stiffness.by_z));
        crate::panic_gate::exit_success()
    }
}

/// On the host this example does nothing: it is firmware.
#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("`no_panic_fixed` is firmware: cargo build --release --example no_panic_fixed --target thumbv6m-none-eabi");
}
