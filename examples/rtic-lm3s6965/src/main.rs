//! RTIC 2 on QEMU's `lm3s6965evb` (Cortex-M3): the needle-haptics control loop at 1 kHz.
//!
//! - `control` (priority 2) is bound to the Timer 0A interrupt, a hardware timer in
//!   periodic mode at 1 ms of virtual time. Each run ticks the [`ControlLoop`] (three
//!   motor channels, force limit 0.06 N, saturating), pushes the [`Sample`] into the
//!   telemetry queue, measures itself and spawns `telemetry`.
//! - `telemetry` (priority 1, async) drains the queue and prints every 100th sample; the
//!   control task preempts it whenever the timer fires.
//! - The script (examples/common/script.rs) at x = 2 mm, z = -1 mm: touch 100 ms, insert
//!   to 6 mm while tilting theta_x to 10 degrees in 1,000 ms, hold 300 ms with the
//!   encoders stale from 1,150 to 1,169 ms, withdraw in 1,000 ms: 2,400 ticks.
//!
//! Timing, under `qemu-system-arm -icount shift=0` (1 ns per instruction): SysTick runs
//! free from the core clock and is calibrated against an instruction loop; the timer's
//! clock is measured against SysTick (a one-shot interval) and its load set for 1 ms.
//! A *missed deadline* is a control run that ends after the next timer time-out
//! (the time-out flag is set again when it returns) or a period without a run (two runs
//! more than 1.5 periods apart). The worst tick is the longest run of the control task's
//! body, in instructions (resolution: the SysTick tick, printed).
//!
//! Output: a header `needle-rtic board=... timer_load=<clocks per period> ...`, trace
//! lines `needle-rtic t_ms=...` (format in examples/common/trace.rs), then `needle-rtic
//! end ticks=<n> period_instr=<n> resolution_instr=<n> worst_tick_instr=<n> at_t_ms=<n>
//! min_interval_instr=<n> max_interval_instr=<n> overran=<n> skipped=<n>
//! missed_deadlines=<n> dropped=<n>` (interval: from one control run's start to the
//! next); exit status 0 when every tick ran, none was missed and no sample was dropped.
#![no_std]
#![no_main]

#[path = "../../common/mod.rs"]
mod common;

mod clock;
mod gptm;

use common::device::{RegPin, RegPwm};
use common::script::Insertion;
use needle_haptics::control::ControlLoop;

/// The script (module docs).
const SCRIPT: Insertion = Insertion {
    t: 0,
    x_mm: 2.0,
    z_mm: -1.0,
    touch_ms: 100,
    move_ms: 1000,
    hold_ms: 300,
    depth_mm: 6.0,
    theta_x_deg: 10.0,
    stale_ms: 1150..1170,
};
const TICKS: u32 = SCRIPT.ticks();
/// Print every this many samples.
const EVERY: u32 = 100;
/// Telemetry queue capacity (samples).
const QUEUE: usize = 32;
/// The control period (ns of virtual time).
const PERIOD_NS: u64 = 1_000_000;
/// Timer clocks of the one-shot interval that measures the timer's clock.
const MEASURE_CLOCKS: u32 = 200_000;

type Loop = ControlLoop<Insertion, RegPwm, RegPin, RegPin, 3>;

/// What the control task measured, shared with `telemetry` for the summary.
#[derive(Clone, Copy, Default)]
pub struct Timing {
    /// The last tick run (the loop's tick count).
    pub ticks: u32,
    /// The longest control run, instructions, and its tick.
    pub worst_tick_instr: u64,
    pub worst_tick_at: u32,
    /// Shortest and longest interval between two control runs' starts, instructions.
    pub min_interval_instr: u64,
    pub max_interval_instr: u64,
    /// Runs that ended after the next time-out.
    pub overran: u32,
    /// Periods without a run.
    pub skipped: u32,
    /// The last tick has run.
    pub done: bool,
}

impl Timing {
    /// Adds one control run of `tick_instr` instructions at `tick`, started `interval_instr`
    /// after the previous one (`None` for the first run).
    fn add(&mut self, tick: u32, tick_instr: u64, interval_instr: Option<u64>, overran: bool, skipped: u32) {
        self.ticks = tick;
        if tick_instr > self.worst_tick_instr {
            self.worst_tick_instr = tick_instr;
            self.worst_tick_at = tick;
        }
        if let Some(i) = interval_instr {
            self.max_interval_instr = self.max_interval_instr.max(i);
            self.min_interval_instr = if self.min_interval_instr == 0 { i } else { self.min_interval_instr.min(i) };
        }
        self.overran += u32::from(overran);
        self.skipped += skipped;
    }

    /// Missed deadlines: overruns plus periods without a run.
    pub fn missed(&self) -> u32 {
        self.overran + self.skipped
    }
}

#[rtic::app(device = lm3s6965, dispatchers = [SSI0])]
mod app {
    use super::*;
    use crate::clock::Clock;
    use crate::common::icount::Calibration;
    use crate::common::trace;
    use crate::common::{exit, Out};
    use crate::gptm::Timer0;
    use needle_haptics::control::Channel;
    use needle_haptics::telemetry::{SampleConsumer, SampleProducer, Telemetry};

    #[shared]
    struct Shared {
        timing: Timing,
    }

    #[local]
    struct Local {
        control: Loop,
        tx: SampleProducer<'static, QUEUE>,
        rx: SampleConsumer<'static, QUEUE>,
        timer: Timer0,
        clock: Clock,
        period_ticks: u64,
        last_entry: Option<u64>,
        out: Out,
        resolution_instr: u64,
    }

    #[init(local = [telemetry: Telemetry<QUEUE> = Telemetry::new()])]
    fn init(cx: init::Context) -> (Shared, Local) {
        let mut out = Out::new();
        let mut syst = cx.core.SYST;
        let cal = Calibration::start(&mut syst);
        if !cal.deterministic || cal.ticks == 0 {
            out.str("needle-rtic error: not under QEMU -icount shift=0\n");
            out.flush();
            exit(false)
        }
        let mut clock = Clock::new(&cal);
        // SAFETY: the only Timer0, taken once in init.
        let timer = unsafe { Timer0::take() };
        // The timer's clock, measured: one one-shot interval against SysTick.
        let t0 = clock.now();
        timer.start(MEASURE_CLOCKS, false, false);
        while !timer.timed_out() {}
        let measured = clock.now() - t0;
        let interval_ns = clock.instructions(measured);
        timer.stop();
        timer.clear();
        // Timer clocks per period: MEASURE_CLOCKS took interval_ns.
        let load = (u64::from(MEASURE_CLOCKS) * PERIOD_NS + interval_ns / 2) / interval_ns.max(1);
        let period_ticks = PERIOD_NS * cal.ticks / cal.instructions.max(1);
        let Ok(load) = u32::try_from(load) else { exit(false) };
        if load < 2 || period_ticks == 0 {
            out.str("needle-rtic error: timer clock out of range\n");
            out.flush();
            exit(false)
        }

        let channels = [0, 1, 2].map(|i| Channel { pwm: RegPwm(i), dir: RegPin(3 + i) });
        let Ok(control) = ControlLoop::new(common::device::CONFIG, SCRIPT, channels, RegPin(6)) else { exit(false) };
        let (tx, rx) = cx.local.telemetry.split();
        out.str("needle-rtic board=lm3s6965evb core=cortex-m3 ticks=");
        out.dec(u64::from(TICKS));
        out.str(" timer_clock_ns_x1000=");
        out.dec(interval_ns * 1000 / u64::from(MEASURE_CLOCKS));
        out.str(" timer_load=");
        out.dec(u64::from(load));
        out.str(" systick_ticks_per_period=");
        out.dec(period_ticks);
        out.nl();
        out.flush();
        timer.start(load - 1, true, true);
        (
            Shared { timing: Timing::default() },
            Local { control, tx, rx, timer, period_ticks, last_entry: None, out, resolution_instr: clock.instructions(1), clock },
        )
    }

    /// Spins. On a board this would be `wfi`; under QEMU 7.2 a sleeping core lets
    /// virtual time run with host time (`-icount` `sleep=on`: timer intervals measured
    /// 0.64 to 1.35 ms; `sleep=off`: every other time-out lost), so the example keeps
    /// the core busy and virtual time stays one nanosecond per instruction.
    #[idle]
    fn idle(_: idle::Context) -> ! {
        loop {
            cortex_m::asm::nop();
        }
    }

    /// The 1 kHz control tick (module docs).
    #[task(binds = TIMER_0A, priority = 2, shared = [timing], local = [control, tx, timer, clock, period_ticks, last_entry])]
    fn control(mut cx: control::Context) {
        let local = cx.local;
        local.timer.clear();
        let entry = local.clock.now();
        let s = local.control.tick();
        local.tx.push(s);
        let exit_at = local.clock.now();
        let overran = local.timer.timed_out();
        let interval = local.last_entry.map(|last| entry - last);
        *local.last_entry = Some(entry);
        let period = *local.period_ticks;
        // Periods without a run between this run and the previous one.
        let skipped = interval.map_or(0, |i| (i + period / 2) / period).saturating_sub(1);
        let done = s.tick >= TICKS;
        if done {
            local.timer.stop();
        }
        let tick_instr = local.clock.instructions(exit_at - entry);
        let interval_instr = interval.map(|i| local.clock.instructions(i));
        let skipped = u32::try_from(skipped).unwrap_or(u32::MAX);
        cx.shared.timing.lock(|t| {
            t.add(s.tick, tick_instr, interval_instr, overran, skipped);
            t.done = done;
        });
        let _ = telemetry::spawn();
    }

    /// Drains the telemetry queue, prints, and ends the run after the last tick.
    #[task(priority = 1, shared = [timing], local = [rx, out, resolution_instr])]
    async fn telemetry(mut cx: telemetry::Context) {
        let local = cx.local;
        while let Some(s) = local.rx.pop() {
            if s.tick % EVERY == 0 || (1150..=1172).contains(&s.tick) && s.tick % 4 == 0 {
                trace::print(local.out, "needle-rtic", &s);
            }
        }
        let timing = cx.shared.timing.lock(|t| *t);
        if !timing.done {
            return;
        }
        let dropped = local.rx.dropped();
        let out = local.out;
        out.str("needle-rtic end ticks=");
        out.dec(u64::from(timing.ticks));
        for (key, v) in [
            ("period_instr", PERIOD_NS),
            ("resolution_instr", *local.resolution_instr),
            ("worst_tick_instr", timing.worst_tick_instr),
            ("at_t_ms", u64::from(timing.worst_tick_at)),
            ("min_interval_instr", timing.min_interval_instr),
            ("max_interval_instr", timing.max_interval_instr),
            ("overran", u64::from(timing.overran)),
            ("skipped", u64::from(timing.skipped)),
            ("missed_deadlines", u64::from(timing.missed())),
            ("dropped", u64::from(dropped)),
        ] {
            out.str(" ");
            out.str(key);
            out.str("=");
            out.dec(v);
        }
        out.nl();
        out.flush();
        exit(timing.ticks == TICKS && timing.missed() == 0 && dropped == 0)
    }
}
