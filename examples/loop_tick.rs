//! Firmware example `loop_tick`: executed instructions of one control-loop tick
//! ([`ControlLoop::tick`]: read the pose, evaluate the model, limit, map to three PWM
//! channels, write three direction pins, three duties and the enable pin), of the model
//! evaluation alone, of one telemetry push, and of answering one host-link command.
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
    use needle_haptics::control::{Channel, ControlLoop, PoseFault, PoseSource, Sample};
    use needle_haptics::telemetry::Telemetry;
    use needle_haptics::{wrench, Pose};

    const CALLS: u32 = 256;

    /// The pose the encoders "read": the typical pose of `bench`, through black_box.
    struct Encoders(Pose);

    impl PoseSource for Encoders {
        fn read_pose(&mut self) -> Result<Pose, PoseFault> {
            Ok(black_box(self.0))
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
        out.dec(tenths / 10);
        out.str(".");
        out.dec(tenths % 10);
        out.nl();
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
        let Ok(mut l) = ControlLoop::new(CONFIG, Encoders(pose), channels, RegPin(6)) else { exit(false) };

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
