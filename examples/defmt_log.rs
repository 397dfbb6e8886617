//! Firmware example `defmt_log` (feature `defmt`): the control loop logging through
//! defmt. The global logger is `defmt-semihosting`: raw defmt frames on QEMU's stdout,
//! decoded on the host with the ELF's string table, e.g.
//!
//! ```text
//! cargo build --release --example defmt_log --features defmt --target thumbv7em-none-eabihf
//! qemu-system-arm -cpu cortex-m4 -machine mps2-an386 -nographic -semihosting-config enable=on,target=native \
//!   -kernel target/thumbv7em-none-eabihf/release/examples/defmt_log | defmt-print -e target/thumbv7em-none-eabihf/release/examples/defmt_log
//! ```
//!
//! It logs the model's identity, five ticks of an insertion (each [`Sample`] with its
//! pose, wrench, [`Status`](needle_haptics::Status) and [`LoopFlags`]), a stale tick,
//! a refused host-link frame, and `defmt-log end`.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod common;

#[cfg(target_os = "none")]
mod firmware {
    use crate::common::device::{RegPin, RegPwm, CONFIG};
    use crate::common::exit;
    use defmt_semihosting as _;
    use needle_haptics::command::{parse, Command};
    use needle_haptics::control::{Channel, ControlLoop, LoopFlags, PoseFault, PoseSource, Sample};
    use needle_haptics::{model_info, Pose};

    struct Insertion(u8);

    impl PoseSource for Insertion {
        fn read_pose(&mut self) -> Result<Pose, PoseFault> {
            self.0 += 1;
            if self.0 > 5 {
                return Err(PoseFault::Stale);
            }
            Ok(Pose::new(2.0, -1.0, 2.0 * f32::from(self.0), 0.0, 1.2 * f32::from(self.0)))
        }
    }

    #[cortex_m_rt::entry]
    fn main() -> ! {
        defmt::println!("defmt-log set={=str} fitted={=bool}", model_info::SET, model_info::FITTED);
        let channels = [0, 1, 2].map(|i| Channel { pwm: RegPwm(i), dir: RegPin(3 + i) });
        let Ok(mut l) = ControlLoop::new(CONFIG, Insertion(0), channels, RegPin(6)) else { exit(false) };
        for _ in 0..6 {
            let s: Sample = l.tick();
            defmt::println!("defmt-log sample {}", s);
            if s.flags.contains(LoopFlags::POSE_STALE) {
                defmt::println!("defmt-log stale pose: flags {}", s.flags);
            }
        }
        let frame = parse(b"LIMIT -5");
        defmt::println!("defmt-log frame {}", frame);
        let ok: Result<Command, _> = parse(b"MODE RAMP");
        defmt::println!("defmt-log frame {}", ok);
        defmt::println!("defmt-log end");
        exit(true)
    }
}

/// On the host this example does nothing: it is firmware.
#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("`defmt_log` is firmware: cargo run --release --example defmt_log --features defmt --target thumbv7em-none-eabihf");
}
