//! Firmware example `no_panic_fixed_insertion`: the link-time proof that the fixed-point
//! insertion model cannot panic and uses no floating point. Its panic handler calls an
//! undefined symbol (`panic_gate`), so the firmware links only if the optimiser removed
//! every panic path from what it calls: `fixed::insertion::Insertion::new`,
//! `set_scales`, `step` through every compiled-in stack (deflection, puncture, cutting,
//! friction, the track) and `reset`. host-tests/tests/firmware_no_panic.rs runs it under
//! QEMU, checks that the image links no soft-float helper and has no FPU instruction,
//! and measures its flash (the model, the depth extension, the insertion and the
//! stacks, in integers).
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod panic_gate;

#[cfg(target_os = "none")]
mod firmware {
    use core::hint::black_box;
    use needle_haptics::fixed::insertion::{stacks, Insertion, InsertionConfig};
    use needle_haptics::fixed::Pose;

    #[cortex_m_rt::entry]
    fn main() -> ! {
        let one = Pose::ONE;
        for stack in black_box(&stacks::ALL) {
            let Ok(mut ins) = Insertion::new(black_box(stack), black_box(InsertionConfig::DEFAULT_1KHZ)) else { continue };
            let scales = [one; 8];
            let n = black_box(stack.count).min(scales.len());
            let _ = ins.set_scales(black_box(scales.get(..n).unwrap_or(&[])));
            let mut d = black_box(-one);
            while d < black_box(40 * one) {
                let e = ins.step(&black_box(Pose::new(one, -one / 2, 3 * one, -2 * one, d)));
                black_box((e.wrench, e.status.bits(), e.phase.code(), e.punctures, e.velocity_mm_per_s_q16));
                d += black_box(one / 20);
            }
            ins.reset();
            black_box(&ins);
        }
        crate::panic_gate::exit_success()
    }
}

/// On the host this example does nothing: it is firmware.
#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!(
        "`no_panic_fixed_insertion` is firmware: cargo build --release --example no_panic_fixed_insertion --target thumbv6m-none-eabi"
    );
}
