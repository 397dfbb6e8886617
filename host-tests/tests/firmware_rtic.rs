//! The RTIC 2 application (examples/rtic-lm3s6965) on QEMU's Stellaris LM3S6965
//! (Cortex-M3, `-icount shift=0`): the control loop in the Timer 0A interrupt at 1 kHz
//! of virtual time, telemetry drained by a lower-priority task.
//!
//! Checks: all 2,400 ticks run with 0 missed deadlines and 0 dropped samples; every
//! interval between two control runs is one period (to the SysTick resolution); the
//! worst tick is printed and is a small part of the period; every printed sample's fy
//! is the library's wrench at the printed pose bit for bit (the M3 evaluates like the
//! host: golden tests), the stale window ramps, the needle goes in to 6 mm and out.
//!
//! Nothing skips: a missing QEMU or rustup target fails with a message.
use needle_firmware_host::{self as firmware, board, qemu};
use std::time::Duration;

fn field<'a>(line: &'a str, key: &str) -> Option<&'a str> {
    line.split(' ').find_map(|w| w.strip_prefix(key)?.strip_prefix('='))
}

fn number(line: &str, key: &str) -> u64 {
    field(line, key).and_then(|v| v.parse().ok()).unwrap_or_else(|| panic!("no {key}=<n> in {line}"))
}

fn hex(v: &str) -> u32 {
    u32::from_str_radix(v.trim_start_matches("0x"), 16).unwrap_or_else(|e| panic!("{v}: {e}"))
}

#[test]
fn rtic_timer_interrupt_runs_the_loop_at_1_khz_without_missed_deadlines() {
    let set = firmware::fitted_set(&firmware::compiled_set()).unwrap_or_else(|e| panic!("{e:#}"));
    let elf = board::RTIC_LM3S6965.build(&set).unwrap_or_else(|e| panic!("{e:#}"));
    let run = qemu::run(&board::LM3S6965, &elf, true, Duration::from_secs(300)).unwrap_or_else(|e| panic!("{e:#}"));
    let out = &run.stdout;
    println!("{out}");
    assert!(run.status.success(), "the RTIC firmware exited with {}:\n{out}{}", run.status, run.stderr);

    let end = out.lines().find(|l| l.starts_with("needle-rtic end")).unwrap_or_else(|| panic!("no end line:\n{out}"));
    let ticks = number(end, "ticks");
    assert!(ticks >= 2000, "only {ticks} ticks: {end}");
    assert_eq!(number(end, "missed_deadlines"), 0, "{end}");
    assert_eq!(number(end, "dropped"), 0, "{end}");
    let (period, resolution) = (number(end, "period_instr"), number(end, "resolution_instr"));
    assert_eq!(period, 1_000_000, "1 kHz at 1 ns per instruction: {end}");
    for key in ["min_interval_instr", "max_interval_instr"] {
        let v = number(end, key);
        assert!(v.abs_diff(period) <= resolution, "{key} = {v}, not one period ({period} +- {resolution}): {end}");
    }
    let worst = number(end, "worst_tick_instr");
    assert!(worst > 0 && worst < period / 10, "worst tick {worst} instructions (a tick is one wrench, ~41k on the soft-float M3): {end}");
    println!(
        "rtic-lm3s6965: {ticks} ticks at 1 kHz, worst tick {worst} instructions ({:.1} % of the period), 0 missed",
        100.0 * worst as f64 / period as f64
    );

    let (mut rows, mut stale, mut max_depth, mut last_depth) = (0, 0, 0.0f32, f32::NAN);
    for l in out.lines().filter(|l| l.starts_with("needle-rtic t_ms=")) {
        let bits: Vec<u32> = field(l, "bits").expect("bits").split(',').map(hex).collect();
        assert_eq!(bits.len(), 6, "{l}");
        let flags = hex(field(l, "flags").expect("flags"));
        let f = |i: usize| f32::from_bits(bits[i]);
        let pose = needle_haptics::Pose::new(f(0), f(1), f(2), f(3), f(4));
        if flags & 0x0001 != 0 {
            stale += 1;
            assert_ne!(flags & 0x0020, 0, "stale without RAMPING: {l}");
        } else {
            let want = needle_haptics::wrench(&pose).wrench.fy_n;
            assert_eq!(bits[5], want.to_bits(), "firmware fy {} vs library {want}: {l}", f(5));
        }
        max_depth = max_depth.max(pose.depth_mm);
        last_depth = pose.depth_mm;
        rows += 1;
    }
    assert!(rows >= 24, "only {rows} trace lines");
    assert!(stale >= 3, "the stale window shows in the trace ({stale} lines)");
    assert_eq!(max_depth, 6.0);
    assert_eq!(last_depth, 0.0, "the needle comes back out");
}
