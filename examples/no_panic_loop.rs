//! Firmware example `no_panic_loop`: proves at link time that the control loop, the
//! telemetry queue and the host-link commands have no panic path, like `no_panic` does
//! for the evaluator (which stays the model-only image that `needle firmware size`
//! measures).
//!
//! Its `#[panic_handler]` calls `needle_haptics_panic_path_not_optimised_away`, defined
//! nowhere, so it links only if nothing reachable from `main` can panic: a
//! [`needle_haptics::control::ControlLoop`] tick and a [`LoopCore::step`] on a fault, a
//! telemetry push and pop, the frame reader, parser and replies on opaque bytes (every
//! input through `core::hint::black_box`), plus the model evaluation of `no_panic`.
//!
//! ```text
//! cargo build --release --example no_panic_loop --target thumbv6m-none-eabi
//! ```
//!
//! [`LoopCore::step`]: needle_haptics::control::LoopCore::step
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod panic_gate;

#[cfg(target_os = "none")]
mod firmware {
    use core::hint::black_box;
    use needle_haptics::{wrench, Evaluation, Pose};

    use core::convert::Infallible;
    use embedded_hal::digital::{ErrorType as PinError, OutputPin};
    use embedded_hal::pwm::{ErrorType as PwmError, SetDutyCycle};
    use needle_haptics::command::{respond, FrameReader};
    use needle_haptics::control::{Channel, ChannelMap, ControlLoop, LoopConfig, OverLimit, PoseFault, PoseSource};
    use needle_haptics::telemetry::Telemetry;

    /// Opaque poses and faults.
    struct Source;
    impl PoseSource for Source {
        fn read_pose(&mut self) -> Result<Pose, PoseFault> {
            black_box(Ok(Pose::new(3.0, -2.0, 5.0, -7.0, 4.5)))
        }
    }
    struct Pwm;
    impl PwmError for Pwm {
        type Error = Infallible;
    }
    impl SetDutyCycle for Pwm {
        fn max_duty_cycle(&self) -> u16 {
            black_box(1000)
        }
        fn set_duty_cycle(&mut self, d: u16) -> Result<(), Infallible> {
            black_box(d);
            Ok(())
        }
    }
    struct Pin;
    impl PinError for Pin {
        type Error = Infallible;
    }
    impl OutputPin for Pin {
        fn set_low(&mut self) -> Result<(), Infallible> {
            black_box(0);
            Ok(())
        }
        fn set_high(&mut self) -> Result<(), Infallible> {
            black_box(1);
            Ok(())
        }
    }

    /// A loop tick, a telemetry push and a host-link exchange, all on opaque data.
    fn control_loop() {
        let map = ChannelMap { gains_per_n: black_box([10.0, -5.0, 2.0]), direction_inverted: black_box(true) };
        let config = LoopConfig {
            channels: [map, map, map],
            force_limit_n: black_box(0.05),
            force_limit_max_n: black_box(0.1),
            over_limit: black_box(OverLimit::Saturate),
            ramp_step_n: black_box(0.01),
        };
        let channels = [Channel { pwm: Pwm, dir: Pin }, Channel { pwm: Pwm, dir: Pin }, Channel { pwm: Pwm, dir: Pin }];
        let Ok(mut l) = ControlLoop::new(config, Source, channels, Pin) else { return };
        let mut t: Telemetry<8> = Telemetry::new();
        let (mut tx, mut rx) = t.split();
        let mut reader = FrameReader::new();
        for _ in 0..black_box(3) {
            tx.push(l.tick());
            let step = l.core_mut().step(black_box(Err(PoseFault::Stale)));
            tx.push(step);
            for b in black_box(b"STATUS\nLIMIT 20\n".as_slice()) {
                if let Some(frame) = reader.push(black_box(*b)) {
                    black_box(respond(frame, l.core_mut(), rx.dropped()));
                }
            }
        }
        black_box(rx.pop());
    }

    #[cortex_m_rt::entry]
    fn main() -> ! {
        control_loop();
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
    eprintln!("`no_panic_loop` is firmware: cargo build --release --example no_panic_loop --target thumbv7em-none-eabihf");
}
