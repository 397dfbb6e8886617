//! Firmware example `insertion`: the control loop at a simulated 1 kHz through a
//! scripted needle insertion, printing the force trace.
//!
//! SysTick interrupts every millisecond of QEMU's virtual time (`-icount shift=0`: 1 ns
//! per instruction; the SysTick reload is derived from the calibration, so it is 1 ms on
//! any board). The SysTick handler is the control loop: it reads the scripted
//! kinematics, ticks the [`ControlLoop`] (three motor channels, force limit 0.06 N,
//! saturating) and pushes the sample into the telemetry queue. `main`, at thread
//! priority, drains the queue and prints every 20th sample, so the loop never waits for
//! the (slow) output.
//!
//! The script, at x = 2 mm, z = -1 mm: touch for 100 ms; insert from 0 to 6 mm in
//! 500 ms while tilting theta_x from 0 to 10 degrees; hold 100 ms, with the encoders
//! stale from 650 to 669 ms (the loop ramps towards zero, then follows the model again);
//! withdraw to 0 mm and 0 degrees in 500 ms. 1,200 ticks.
//!
//! ```text
//! cargo run --release --example insertion --target thumbv7em-none-eabihf
//! ```
//!
//! Output lines: `needle-insertion t_ms=<n> depth_mm=<d> theta_x_deg=<d> fy_n=<d>
//! cmd_y_n=<d> duty=<x>,<y>,<z> en=<0|1> flags=0x<hhhh> bits=<x>,<z>,<tx>,<tz>,<depth>,<fy>`
//! (numbers rounded for reading, `bits` the exact f32 bits of the pose and fy), then
//! `needle-insertion end ticks=<n> printed=<n> dropped=<n> max_fy_n=<d> max_cmd_y_n=<d>`.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod common;

#[cfg(target_os = "none")]
mod firmware {
    use crate::common::device::{read_reg, RegPin, RegPwm, CONFIG};
    use crate::common::icount::Calibration;
    use crate::common::{exit, Out};
    use core::ptr::addr_of_mut;
    use core::sync::atomic::{AtomicBool, Ordering};
    use cortex_m::peripheral::syst::SystClkSource;
    use cortex_m_rt::exception;
    use needle_haptics::control::{Channel, ControlLoop, PoseFault, PoseSource, Sample};
    use needle_haptics::telemetry::{SampleConsumer, SampleProducer, Telemetry};
    use needle_haptics::Pose;

    /// Ticks of the script (ms).
    const TICKS: u32 = 1200;
    /// Print every this many samples.
    const EVERY: u32 = 20;
    const QUEUE: usize = 64;

    /// The scripted kinematics: the pose at tick `t` (ms), or stale.
    struct Kinematics {
        t: u32,
    }

    impl PoseSource for Kinematics {
        fn read_pose(&mut self) -> Result<Pose, PoseFault> {
            self.t += 1;
            let t = self.t;
            if (650..670).contains(&t) {
                return Err(PoseFault::Stale);
            }
            // Fraction of the insertion: 0 before 100 ms, 1 from 600 to 700 ms, 0 at 1200 ms.
            let s = if t < 100 {
                0.0
            } else if t < 600 {
                (t - 100) as f32 / 500.0
            } else if t < 700 {
                1.0
            } else {
                (TICKS.saturating_sub(t)) as f32 / 500.0
            };
            Ok(Pose::new(2.0, -1.0, 10.0 * s, 0.0, 6.0 * s))
        }
    }

    type Loop = ControlLoop<Kinematics, RegPwm, RegPin, RegPin, 3>;

    static mut LOOP: Option<(Loop, SampleProducer<'static, QUEUE>)> = None;
    static mut TELEMETRY: Telemetry<QUEUE> = Telemetry::new();
    static DONE: AtomicBool = AtomicBool::new(false);

    #[exception]
    fn SysTick() {
        // SAFETY: main initialised LOOP before enabling this interrupt and never touches
        // it again; this handler is its only user.
        let Some((l, tx)) = (unsafe { (*addr_of_mut!(LOOP)).as_mut() }) else { return };
        let s = l.tick();
        tx.push(s);
        if s.tick >= TICKS {
            // SAFETY: stops this interrupt; nothing else uses SysTick any more.
            unsafe { (*cortex_m::peripheral::SYST::PTR).csr.modify(|v| v & !0b10) };
            DONE.store(true, Ordering::Release);
        }
    }

    /// Appends `v` rounded to `decimals` digits (|v| < 2^31 / 10^decimals).
    fn fixed(out: &mut Out, v: f32, decimals: u32) {
        let scale = 10u32.pow(decimals) as f32;
        let n = (if v < 0.0 { -v } else { v } * scale + 0.5) as u64;
        if v < 0.0 && n != 0 {
            out.str("-");
        }
        let p = 10u64.pow(decimals);
        out.dec(n / p);
        out.str(".");
        let frac = n % p;
        let mut d = p / 10;
        while d > frac.max(1) && d > 1 {
            out.str("0");
            d /= 10;
        }
        out.dec(frac);
    }

    fn print(out: &mut Out, s: &Sample) {
        out.str("needle-insertion t_ms=");
        out.dec(u64::from(s.tick));
        out.str(" depth_mm=");
        fixed(out, s.pose.depth_mm, 3);
        out.str(" theta_x_deg=");
        fixed(out, s.pose.theta_x_deg, 2);
        out.str(" fy_n=");
        fixed(out, s.wrench.fy_n, 5);
        out.str(" cmd_y_n=");
        fixed(out, s.force_cmd_n[1], 5);
        out.str(" duty=");
        out.dec(u64::from(read_reg(0)));
        out.str(",");
        out.dec(u64::from(read_reg(1)));
        out.str(",");
        out.dec(u64::from(read_reg(2)));
        out.str(" en=");
        out.dec(u64::from(read_reg(6)));
        out.str(" flags=");
        out.hex(u32::from(s.flags.bits()), 4);
        out.str(" bits=");
        let p = s.pose;
        for v in [p.x_mm, p.z_mm, p.theta_x_deg, p.theta_z_deg, p.depth_mm] {
            out.hex(v.to_bits(), 8);
            out.str(",");
        }
        out.hex(s.wrench.fy_n.to_bits(), 8);
        out.nl();
    }

    #[cortex_m_rt::entry]
    fn main() -> ! {
        let mut out = Out::new();
        let Some(p) = cortex_m::Peripherals::take() else { exit(false) };
        let mut syst = p.SYST;
        let cal = Calibration::start(&mut syst);
        if !cal.deterministic || cal.ticks == 0 {
            out.str("needle-insertion error: not under QEMU -icount shift=0\n");
            out.flush();
            exit(false)
        }
        // SysTick ticks per millisecond of virtual time (1 ns per instruction).
        let per_ms = (1_000_000 * cal.ticks / cal.instructions) as u32;
        // SAFETY: TELEMETRY is split once, here, before the interrupt starts.
        let (tx, mut rx): (SampleProducer<'static, QUEUE>, SampleConsumer<'static, QUEUE>) = unsafe { (*addr_of_mut!(TELEMETRY)).split() };
        let channels = [0, 1, 2].map(|i| Channel { pwm: RegPwm(i), dir: RegPin(3 + i) });
        let Ok(l) = ControlLoop::new(CONFIG, Kinematics { t: 0 }, channels, RegPin(6)) else { exit(false) };
        // SAFETY: the interrupt is not enabled yet.
        unsafe { *addr_of_mut!(LOOP) = Some((l, tx)) };
        out.str("needle-insertion period_systick_ticks=");
        out.dec(u64::from(per_ms));
        out.str(" ticks=");
        out.dec(u64::from(TICKS));
        out.str(" limit_n=0.06 over_limit=saturate\n");
        syst.set_clock_source(SystClkSource::Core);
        syst.set_reload(per_ms - 1);
        syst.clear_current();
        syst.enable_interrupt();
        syst.enable_counter();

        let (mut printed, mut received, mut max_fy, mut max_cmd) = (0u64, 0u32, 0.0f32, 0.0f32);
        loop {
            let done = DONE.load(Ordering::Acquire);
            while let Some(s) = rx.pop() {
                received += 1;
                max_fy = max_fy.max(s.wrench.fy_n);
                max_cmd = max_cmd.max(s.force_cmd_n[1]);
                if s.tick % EVERY == 0 || (650..=672).contains(&s.tick) && s.tick % 4 == 0 {
                    print(&mut out, &s);
                    printed += 1;
                }
            }
            if done {
                break;
            }
            cortex_m::asm::wfi();
        }
        out.str("needle-insertion end ticks=");
        out.dec(u64::from(received));
        out.str(" printed=");
        out.dec(printed);
        out.str(" dropped=");
        out.dec(u64::from(rx.dropped()));
        out.str(" max_fy_n=");
        fixed(&mut out, max_fy, 5);
        out.str(" max_cmd_y_n=");
        fixed(&mut out, max_cmd, 5);
        out.nl();
        out.flush();
        exit(received == TICKS && rx.dropped() == 0)
    }
}

/// On the host this example does nothing: it is firmware.
#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("`insertion` is firmware: cargo run --release --example insertion --target thumbv7em-none-eabihf");
}
