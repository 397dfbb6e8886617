//! needle-haptics on a NUCLEO-F401RE (STM32F401RE, Cortex-M4F at 84 MHz): an RTIC 2
//! application that renders the model's reaction force on a one-axis insertion rig.
//!
//! Wiring (Arduino header names in brackets):
//! - motor drivers, PWM at 20 kHz on TIM3: CH1 PA6 [D12] x, CH2 PA7 [D11] y, CH3 PB0
//!   [A3] z; direction pins PA8 [D7], PA9 [D8], PA10 [D2]; driver enable PB5 [D4];
//! - depth: a quadrature encoder on TIM2, A on PA0 [A0], B on PA1 [A1] (homed at
//!   start-up: the needle tip must touch the tissue surface at reset);
//! - control tick: the TIM5 update interrupt at 1 kHz, an RTIC hardware task at
//!   priority 2 running [`ControlLoop::tick`] and pushing the sample to telemetry;
//! - telemetry: an async task at priority 1 logs every 100th sample with defmt (RTT)
//!   and, once a second, the worst tick in core cycles (DWT) and the overruns (ticks
//!   that ended after the next update event).
//!
//! Build: `cargo build --release`; flash and watch the log with a probe attached:
//! `cargo run --release` (probe-rs, .cargo/config.toml). The constants below are the
//! rig's: set them from your motors, drivers and encoder before powering the motors.
#![no_std]
#![no_main]

mod encoder_depth;

use defmt_rtt as _;
use panic_probe as _;

use needle_haptics::control::{ChannelMap, LoopConfig, OverLimit};
use needle_haptics::Pose;

/// The rig's entry point and tilts (the needle's axis is fixed).
const ENTRY: Pose = Pose::new(0.0, 0.0, 0.0, 0.0, 0.0);
/// Depth encoder resolution: counts per mm of insertion, quadrature counted.
const COUNTS_PER_MM: f32 = 400.0;
/// Largest count change in one 1 ms tick that is a real motion (here 0.5 m/s).
const MAX_STEP_COUNTS: u32 = 200;
/// Force to duty: each channel's duty fraction per newton of (fx, fy, fz); full scale
/// 0.1 N on every axis. The force limit and ramp of the safety stop.
const CONFIG: LoopConfig<3> = LoopConfig {
    channels: [
        ChannelMap { gains_per_n: [10.0, 0.0, 0.0], direction_inverted: false },
        ChannelMap { gains_per_n: [0.0, 10.0, 0.0], direction_inverted: false },
        ChannelMap { gains_per_n: [0.0, 0.0, 10.0], direction_inverted: false },
    ],
    force_limit_n: 0.08,
    force_limit_max_n: 0.1,
    over_limit: OverLimit::Saturate,
    ramp_step_n: 0.002,
};
/// The device's physical damping along the needle, N*s/mm, measured on the rig; with
/// it the passivity guard limits the rendered stiffness (`control::Passivity`). None:
/// no guard.
const DAMPING_N_S_PER_MM: Option<f32> = None;
/// Log every this many samples.
const EVERY: u32 = 100;
/// Telemetry queue capacity (samples).
const QUEUE: usize = 32;

#[rtic::app(device = stm32f4xx_hal::pac, dispatchers = [USART1])]
mod app {
    use super::*;
    use crate::encoder_depth::EncoderDepth;
    use cortex_m::peripheral::DWT;
    use needle_haptics::control::{Channel, ControlLoop, Passivity};
    use needle_haptics::telemetry::{SampleConsumer, SampleProducer, Telemetry};
    use stm32f4xx_hal::gpio::{AnyPin, Output, PushPull, PB5};
    use stm32f4xx_hal::pac::{TIM3, TIM5};
    use stm32f4xx_hal::prelude::*;
    use stm32f4xx_hal::qei::Qei;
    use stm32f4xx_hal::rcc::Config;
    use stm32f4xx_hal::timer::{CounterHz, ErasedChannel, Event, Flag, PwmHzManager};

    type Loop = ControlLoop<EncoderDepth, ErasedChannel<TIM3>, AnyPin<Output<PushPull>>, PB5<Output<PushPull>>, 3>;

    /// Timing of the control task since the last report.
    #[derive(Clone, Copy, Default)]
    pub struct Timing {
        pub worst_cycles: u32,
        pub overruns: u32,
    }

    #[shared]
    struct Shared {
        timing: Timing,
    }

    #[local]
    struct Local {
        control: Loop,
        tx: SampleProducer<'static, QUEUE>,
        rx: SampleConsumer<'static, QUEUE>,
        timer: CounterHz<TIM5>,
        pwm: PwmHzManager<TIM3>,
    }

    #[init(local = [telemetry: Telemetry<QUEUE> = Telemetry::new()])]
    fn init(cx: init::Context) -> (Shared, Local) {
        let mut core = cx.core;
        let dp = cx.device;
        // NUCLEO: 8 MHz from the ST-LINK's MCO into OSC_IN (HSE bypass), core at 84 MHz.
        let mut rcc = dp.RCC.freeze(Config::hse(8.MHz()).bypass_hse_oscillator().sysclk(84.MHz()));
        core.DCB.enable_trace();
        core.DWT.enable_cycle_counter();
        let gpioa = dp.GPIOA.split(&mut rcc);
        let gpiob = dp.GPIOB.split(&mut rcc);

        let (pwm, (c1, c2, c3, ..)) = dp.TIM3.pwm_hz(20.kHz(), &mut rcc);
        let mut pwm_x = c1.with(gpioa.pa6).erase();
        let mut pwm_y = c2.with(gpioa.pa7).erase();
        let mut pwm_z = c3.with(gpiob.pb0).erase();
        for c in [&mut pwm_x, &mut pwm_y, &mut pwm_z] {
            c.set_duty(0);
            c.enable();
        }
        let channels = [
            Channel { pwm: pwm_x, dir: gpioa.pa8.into_push_pull_output().erase() },
            Channel { pwm: pwm_y, dir: gpioa.pa9.into_push_pull_output().erase() },
            Channel { pwm: pwm_z, dir: gpioa.pa10.into_push_pull_output().erase() },
        ];
        let enable = gpiob.pb5.into_push_pull_output();
        let qei = Qei::new(dp.TIM2, (gpioa.pa0, gpioa.pa1), &mut rcc);
        let depth = EncoderDepth::homed_here(qei, ENTRY, COUNTS_PER_MM, MAX_STEP_COUNTS);

        let mut control = match ControlLoop::new(CONFIG, depth, channels, enable) {
            Ok(l) => l,
            Err(e) => halt(defmt::Debug2Format(&e)),
        };
        let passivity = DAMPING_N_S_PER_MM.map(|b| Passivity { damping_n_s_per_mm: b, period_s: 0.001 });
        if let Err(e) = control.core_mut().set_passivity(passivity) {
            halt(defmt::Debug2Format(&e));
        }

        let mut timer = dp.TIM5.counter_hz(&mut rcc);
        if timer.start(1.kHz()).is_err() {
            halt("TIM5 cannot tick at 1 kHz from this clock tree");
        }
        timer.listen(Event::Update);
        let (tx, rx) = cx.local.telemetry.split();
        defmt::info!(
            "needle-nucleo: set {=str} (fitted {=bool}), loop at 1 kHz on TIM5, core {=u32} Hz",
            needle_haptics::model_info::SET,
            needle_haptics::model_info::FITTED,
            rcc.clocks.sysclk().raw()
        );
        (Shared { timing: Timing::default() }, Local { control, tx, rx, timer, pwm })
    }

    /// Logs why the loop cannot start and stops, motors never enabled.
    fn halt(why: impl defmt::Format) -> ! {
        defmt::error!("needle-nucleo: cannot start: {}", why);
        loop {
            cortex_m::asm::wfi();
        }
    }

    #[idle]
    fn idle(_: idle::Context) -> ! {
        loop {
            cortex_m::asm::wfi();
        }
    }

    /// The 1 kHz control tick.
    #[task(binds = TIM5, priority = 2, shared = [timing], local = [control, tx, timer])]
    fn control(mut cx: control::Context) {
        let start = DWT::cycle_count();
        cx.local.timer.clear_flags(Flag::Update);
        let s = cx.local.control.tick();
        cx.local.tx.push(s);
        let cycles = DWT::cycle_count().wrapping_sub(start);
        let overran = cx.local.timer.flags().contains(Flag::Update);
        cx.shared.timing.lock(|t| {
            t.worst_cycles = t.worst_cycles.max(cycles);
            t.overruns += u32::from(overran);
        });
        let _ = telemetry::spawn();
    }

    /// Logs samples and, once a second, the control task's timing.
    #[task(priority = 1, shared = [timing], local = [rx, pwm])]
    async fn telemetry(mut cx: telemetry::Context) {
        while let Some(s) = cx.local.rx.pop() {
            if s.tick % EVERY == 0 {
                defmt::info!("{}", s);
            }
            if s.tick % 1000 == 0 {
                let t = cx.shared.timing.lock(core::mem::take);
                defmt::info!(
                    "needle-nucleo: worst tick {=u32} cycles, {=u32} overruns, {=u32} samples dropped",
                    t.worst_cycles,
                    t.overruns,
                    cx.local.rx.dropped()
                );
            }
        }
    }
}
