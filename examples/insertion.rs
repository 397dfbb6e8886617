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
//! Output lines: `needle-insertion t_ms=...` trace lines (format in
//! examples/common/trace.rs), then
//! `needle-insertion end ticks=<n> printed=<n> dropped=<n> max_fy_n=<d> max_cmd_y_n=<d>`.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod common;

#[cfg(target_os = "none")]
mod firmware {
    use crate::common::device::{RegPin, RegPwm, CONFIG};
    use crate::common::icount::Calibration;
    use crate::common::script::Insertion;
    use crate::common::trace;
    use crate::common::{exit, Out};
    use core::ptr::addr_of_mut;
    use core::sync::atomic::{AtomicBool, Ordering};
    use cortex_m::peripheral::syst::SystClkSource;
    use cortex_m_rt::exception;
    use needle_haptics::control::{Channel, ControlLoop};
    use needle_haptics::telemetry::{SampleConsumer, SampleProducer, Telemetry};

    /// Print every this many samples.
    const EVERY: u32 = 20;
    const QUEUE: usize = 64;

    /// The script (module docs): 1,200 ticks.
    const SCRIPT: Insertion = Insertion {
        t: 0,
        x_mm: 2.0,
        z_mm: -1.0,
        touch_ms: 100,
        move_ms: 500,
        hold_ms: 100,
        depth_mm: 6.0,
        theta_x_deg: 10.0,
        stale_ms: 650..670,
    };
    const TICKS: u32 = SCRIPT.ticks();

    type Loop = ControlLoop<Insertion, RegPwm, RegPin, RegPin, 3>;

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
        let Ok(l) = ControlLoop::new(CONFIG, SCRIPT, channels, RegPin(6)) else { exit(false) };
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
                    trace::print(&mut out, "needle-insertion", &s);
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
        trace::fixed(&mut out, max_fy, 5);
        out.str(" max_cmd_y_n=");
        trace::fixed(&mut out, max_cmd, 5);
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
