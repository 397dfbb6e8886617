//! Firmware example `no_panic_insertion`: the link-time proof that the insertion model
//! cannot panic. Its panic handler calls an undefined symbol (`panic_gate`), so the
//! firmware links only if the optimiser removed every panic path from what it calls:
//! `Insertion::new`, `set_scales`, `step` and `step_with_stiffness` through every
//! compiled-in stack (deflection, puncture, cutting, friction, the track), `reset`, and a
//! `LoopCore` rendering the insertion with the passivity guard. Run under QEMU by
//! host-tests/tests/firmware_no_panic.rs, which also measures this image's flash: the
//! model, the depth extension, the insertion and the stacks (the goal: <= 24 KiB).
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod panic_gate;

#[cfg(target_os = "none")]
mod firmware {
    use core::hint::black_box;
    use needle_haptics::control::{ChannelMap, LoopConfig, LoopCore, OverLimit, Passivity};
    use needle_haptics::insertion::{stacks, Insertion, InsertionConfig};
    use needle_haptics::Pose;

    #[cortex_m_rt::entry]
    fn main() -> ! {
        for stack in black_box(&stacks::ALL) {
            let Ok(mut ins) = Insertion::new(black_box(stack), black_box(InsertionConfig::DEFAULT_1KHZ)) else { continue };
            let scales = [1.0f32; 8];
            let n = black_box(stack.layers.len()).min(scales.len());
            let _ = ins.set_scales(black_box(scales.get(..n).unwrap_or(&[])));
            let mut d = black_box(-1.0f32);
            while d < black_box(40.0) {
                let e = ins.step(&black_box(Pose::new(1.0, -0.5, 3.0, -2.0, d)));
                black_box((e.wrench, e.status.bits(), e.phase.code(), e.punctures));
                d += black_box(0.05);
            }
            ins.reset();
            black_box(&ins);
            let config = LoopConfig {
                channels: [ChannelMap { gains_per_n: [0.0, 0.5, 0.0], direction_inverted: false }],
                force_limit_n: 1.5,
                force_limit_max_n: 2.0,
                over_limit: OverLimit::Saturate,
                ramp_step_n: 0.01,
            };
            let Ok(mut core) = LoopCore::new(black_box(config)) else { continue };
            let _ = core.set_passivity(black_box(Some(Passivity { damping_n_s_per_mm: 0.001, period_s: 0.001 })));
            core.set_insertion(Some(ins));
            let mut d = black_box(-1.0f32);
            while d < black_box(40.0) {
                let (e, k) = ins.step_with_stiffness(&black_box(Pose::new(1.0, -0.5, 3.0, -2.0, d)));
                black_box((e.wrench, k.stiffness_n_per_mm, k.dissipative_n));
                black_box(core.step(black_box(Ok(Pose::new(1.0, -0.5, 3.0, -2.0, d)))));
                black_box(core.insertion_evaluation());
                d += black_box(0.05);
            }
        }
        crate::panic_gate::exit_success()
    }
}

/// On the host this example does nothing: it is firmware.
#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("`no_panic_insertion` is firmware: cargo build --release --example no_panic_insertion --target thumbv7em-none-eabihf");
}
