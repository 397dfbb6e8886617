//! Firmware example `loop_tick`: executed instructions of one control-loop tick
//! ([`ControlLoop::tick`]: read the pose, evaluate the model, limit, map to three PWM
//! channels, write three direction pins, three duties and the enable pin), of the model
//! evaluation alone, of one telemetry push, and of answering one host-link command.
//!
//! Then the tick rendering a whole insertion ([`LoopCore::set_insertion`]) through each
//! shipped tissue stack, the needle advancing 3 µm per tick (3 mm/s) along the tilted
//! pose: `insertion-<stack>-surface` deflecting the surface (the FE surrogate),
//! `insertion-<stack>-deep` 2 mm below the last boundary (friction over every layer
//! passed, the track's hold, cutting), each without and with the passivity guard
//! (`+guard`: the deflected boundary's stiffness from the surrogate's depth rate).
//!
//! Same method as `bench` (QEMU `-icount shift=0`, SysTick calibrated by a 2-instruction
//! loop, `CALLS` calls minus the same loop without the call). The outputs are volatile
//! word stores, like a HAL's register writes.
//!
//! ```text
//! cargo run --release --example loop_tick --target thumbv7em-none-eabihf
//! ```
//!
//! Output: `needle-loop-tick target=... deterministic=yes|no`, then one line per measure
//! `needle-loop-tick what=<name> instructions=<n.n>`, then `needle-loop-tick end`.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod common;

#[cfg(target_os = "none")]
mod firmware {
    use crate::common::device::{RegPin, RegPwm, CONFIG};
    use crate::common::icount::{elapsed, Calibration};
    use crate::common::{exit, target_name, Out};
    use core::hint::black_box;
    use cortex_m::peripheral::SYST;
    use needle_haptics::command::{parse, respond};
    use needle_haptics::control::{Channel, ControlLoop, Passivity, PoseFault, PoseSource, Sample};
    use needle_haptics::insertion::{stacks, Insertion, InsertionConfig};
    use needle_haptics::telemetry::Telemetry;
    use needle_haptics::{wrench, Pose};

    const CALLS: u32 = 256;

    /// The pose the encoders "read" (the typical pose of `bench`, through black_box),
    /// advancing its depth by the second field (mm) after each read.
    struct Encoders(Pose, f32);

    impl PoseSource for Encoders {
        fn read_pose(&mut self) -> Result<Pose, PoseFault> {
            let p = black_box(self.0);
            self.0.depth_mm += self.1;
            Ok(p)
        }
    }

    type Loop = ControlLoop<Encoders, RegPwm, RegPin, RegPin, 3>;

    #[inline(never)]
    fn time_ticks(l: &mut Loop, calls: u32) -> u32 {
        let start = SYST::get_current();
        for _ in 0..calls {
            black_box(l.tick());
        }
        elapsed(start, SYST::get_current())
    }

    #[inline(never)]
    fn time_empty(l: &mut Loop, calls: u32) -> u32 {
        let start = SYST::get_current();
        for _ in 0..calls {
            black_box(black_box(&mut *l));
        }
        elapsed(start, SYST::get_current())
    }

    #[inline(never)]
    fn time_wrench(pose: &Pose, calls: u32) -> u32 {
        let start = SYST::get_current();
        for _ in 0..calls {
            black_box(wrench(black_box(pose)));
        }
        elapsed(start, SYST::get_current())
    }

    #[inline(never)]
    fn time_empty_pose(pose: &Pose, calls: u32) -> u32 {
        let start = SYST::get_current();
        for _ in 0..calls {
            black_box(black_box(pose));
        }
        elapsed(start, SYST::get_current())
    }

    fn line(out: &mut Out, cal: &Calibration, what: &str, tenths: u64) {
        let _ = cal;
        out.str("needle-loop-tick what=");
        out.str(what);
        out.str(" instructions=");
        out.tenths(tenths);
        out.nl();
    }

    /// The insertion measures (module docs): one loop per stack and case, the needle
    /// first advanced at 3 mm/s to the start depth, then `CALLS` timed ticks advancing on.
    fn insertion_ticks(out: &mut Out, cal: &Calibration, pose: Pose) {
        const STEP_MM: f32 = 0.003;
        let guard = Passivity { damping_n_s_per_mm: 0.001, period_s: 0.001 };
        for stack in &stacks::ALL {
            let total: f32 = stack.layers.iter().map(|l| l.thickness_mm).sum();
            for (case, depth) in [("surface", 4.5f32), ("deep", total + 2.0)] {
                for guarded in [false, true] {
                    let start = Pose { depth_mm: -0.5, ..pose };
                    let channels = [0, 1, 2].map(|i| Channel { pwm: RegPwm(i), dir: RegPin(3 + i) });
                    let Ok(mut l) = ControlLoop::new(CONFIG, Encoders(start, STEP_MM), channels, RegPin(6)) else { exit(false) };
                    let Ok(ins) = Insertion::new(stack, InsertionConfig::DEFAULT_1KHZ) else { exit(false) };
                    l.core_mut().set_insertion(Some(ins));
                    if guarded && l.core_mut().set_passivity(Some(guard)).is_err() {
                        exit(false)
                    }
                    let ticks = ((depth + 0.5) / STEP_MM) as u32;
                    for _ in 0..ticks {
                        l.tick();
                    }
                    let with = time_ticks(&mut l, black_box(CALLS));
                    let without = time_empty(&mut l, black_box(CALLS));
                    let mut name = [0u8; 40];
                    let n = label(&mut name, &["insertion-", stack.name, "-", case, if guarded { "+guard" } else { "" }]);
                    let what = name.get(..n).and_then(|b| core::str::from_utf8(b).ok()).unwrap_or("insertion");
                    line(out, cal, what, cal.tenths_per_call(with, without, CALLS));
                    let phase = l.core().insertion_evaluation().map_or(0, |e| e.phase.code());
                    out.str("needle-loop-tick insertion_phase=");
                    out.hex(u32::from(phase), 4);
                    out.str(" tick_flags=");
                    out.hex(u32::from(l.core().last().flags.bits()), 4);
                    // the Prony terms of the deflected boundary's layer (0: no filter ran)
                    let deflected = if phase & 0xff00 == 0x0100 { stack.layers.get(usize::from(phase & 0xff)) } else { None };
                    out.str(" qlv_terms=");
                    out.dec(deflected.map_or(0, |layer| layer.prony.len()) as u64);
                    out.nl();
                }
            }
        }
    }

    /// The parts concatenated into `buf` (truncated to fit), the length.
    fn label(buf: &mut [u8; 40], parts: &[&str]) -> usize {
        let mut n = 0;
        for b in parts.iter().flat_map(|p| p.bytes()) {
            if let Some(slot) = buf.get_mut(n) {
                *slot = b;
                n += 1;
            }
        }
        n
    }

    #[cortex_m_rt::entry]
    fn main() -> ! {
        let mut out = Out::new();
        let Some(p) = cortex_m::Peripherals::take() else { exit(false) };
        let mut syst = p.SYST;
        let cal = Calibration::start(&mut syst);
        out.str("needle-loop-tick target=");
        out.str(target_name());
        out.str(" calls=");
        out.dec(u64::from(CALLS));
        out.str(" deterministic=");
        out.str(if cal.deterministic { "yes" } else { "no" });
        out.nl();
        if cal.ticks == 0 {
            out.str("needle-loop-tick error: SysTick does not count\n");
            out.flush();
            exit(false)
        }
        let pose = Pose::new(3.0, -2.0, 5.0, -7.0, 4.5);
        let channels = [0, 1, 2].map(|i| Channel { pwm: RegPwm(i), dir: RegPin(3 + i) });
        let Ok(mut l) = ControlLoop::new(CONFIG, Encoders(pose, 0.0), channels, RegPin(6)) else { exit(false) };

        let with = time_ticks(&mut l, black_box(CALLS));
        let without = time_empty(&mut l, black_box(CALLS));
        line(&mut out, &cal, "tick", cal.tenths_per_call(with, without, CALLS));
        let s = l.tick();
        out.str("needle-loop-tick tick_flags=");
        out.hex(u32::from(s.flags.bits()), 4);
        out.str(" model_status=");
        out.hex(u32::from(s.model.bits()), 2);
        out.nl();

        let with = time_wrench(&pose, black_box(CALLS));
        let without = time_empty_pose(&pose, black_box(CALLS));
        line(&mut out, &cal, "wrench", cal.tenths_per_call(with, without, CALLS));

        // One telemetry push into a queue that is drained after each (never full).
        let mut t: Telemetry<4> = Telemetry::new();
        let (mut tx, mut rx) = t.split();
        let start = SYST::get_current();
        for _ in 0..CALLS {
            black_box(tx.push(black_box(s)));
            black_box(rx.pop());
        }
        let push_pop = elapsed(start, SYST::get_current());
        let start = SYST::get_current();
        for _ in 0..CALLS {
            black_box(black_box(s));
            black_box(rx.pop());
        }
        let pop = elapsed(start, SYST::get_current());
        line(&mut out, &cal, "telemetry_push", cal.tenths_per_call(push_pop, pop, CALLS));

        // One STATUS command: parse and reply.
        let start = SYST::get_current();
        for _ in 0..CALLS {
            black_box(respond(parse(black_box(b"STATUS")), l.core_mut(), 0));
        }
        let cmd = elapsed(start, SYST::get_current());
        let start = SYST::get_current();
        for _ in 0..CALLS {
            black_box(black_box(b"STATUS"));
        }
        let none = elapsed(start, SYST::get_current());
        line(&mut out, &cal, "command_status", cal.tenths_per_call(cmd, none, CALLS));
        let _: Sample = s;
        insertion_ticks(&mut out, &cal, pose);
        out.str("needle-loop-tick end\n");
        out.flush();
        exit(true)
    }
}

/// On the host this example does nothing: it is firmware.
#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("`loop_tick` is firmware: cargo run --release --example loop_tick --target thumbv7em-none-eabihf");
}
