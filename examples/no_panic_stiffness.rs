//! Firmware example `no_panic_stiffness`: proves at link time that
//! [`needle_haptics::wrench_and_stiffness`] has no panic path, like `no_panic` does for
//! the wrench (same undefined-symbol panic handler, `examples/panic_gate`). Run under
//! QEMU, it evaluates one pose and exits with status 0.
//!
//! ```text
//! cargo build --release --example no_panic_stiffness --target thumbv6m-none-eabi
//! ```
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod panic_gate;

#[cfg(target_os = "none")]
mod firmware {
    use core::hint::black_box;
    use needle_haptics::{wrench_and_stiffness, Pose, StiffnessEvaluation};

    #[cortex_m_rt::entry]
    fn main() -> ! {
        let eval: fn(&Pose) -> StiffnessEvaluation = black_box(wrench_and_stiffness);
        let pose = black_box(Pose::new(3.0, -2.0, 5.0, -7.0, 4.5));
        let e = eval(&pose);
        black_box((e.status.bits(), e.wrench.to_array(), e.stiffness.by_depth.to_array(), e.stiffness.by_x, e.stiffness.by_z));
        crate::panic_gate::exit_success()
    }
}

/// On the host this example does nothing: it is firmware.
#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("`no_panic_stiffness` is firmware: cargo build --release --example no_panic_stiffness --target thumbv7em-none-eabihf");
}
