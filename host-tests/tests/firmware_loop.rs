//! The control loop on the emulated Cortex-M4F (QEMU, `-icount shift=0`):
//!
//! - `loop_tick`: executed instructions of one loop tick, against the goal of 5 % of a
//!   1 kHz period on a 64 MHz core (3,200 instructions);
//! - `insertion`: the loop at 1 kHz of virtual time in the SysTick handler through the
//!   scripted insertion; every printed sample's fy must be the library's wrench of the
//!   printed pose bit for bit, the depth must reach 6 mm and come back, the stale window
//!   must ramp, the command must stay within the 0.06 N limit, and no sample is dropped.
//!
//! Nothing skips: a missing QEMU or rustup target fails with a message.
use needle_firmware_host::build::Features;
use needle_firmware_host::{self as firmware, build, qemu};
use std::time::Duration;

fn field<'a>(line: &'a str, key: &str) -> Option<&'a str> {
    line.split(' ').find_map(|w| w.strip_prefix(key)?.strip_prefix('='))
}

fn run_example(name: &str) -> String {
    run_example_with(name, Features::Viscoelastic)
}

fn run_example_with(name: &str, features: Features) -> String {
    let core = firmware::core("m4f").unwrap_or_else(|e| panic!("{e:#}"));
    let set = firmware::fitted_set(&firmware::compiled_set()).unwrap_or_else(|e| panic!("{e:#}"));
    let elf = build::build_examples_with(&core, &[name], &set, features).unwrap_or_else(|e| panic!("{e:#}")).remove(0);
    let run = qemu::run(&core, &elf, true, Duration::from_secs(300)).unwrap_or_else(|e| panic!("{e:#}"));
    assert!(run.status.success(), "{name} exited with {}:\n{}{}", run.status, run.stdout, run.stderr);
    run.stdout
}

#[test]
fn loop_tick_instructions_on_cortex_m4f() {
    let out = run_example("loop_tick");
    println!("{out}");
    let head = out.lines().next().unwrap_or_default();
    assert_eq!(field(head, "deterministic"), Some("yes"), "not under -icount: {head}");
    let figure = |what: &str| -> f64 {
        out.lines()
            .find(|l| field(l, "what") == Some(what))
            .and_then(|l| field(l, "instructions"))
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("no {what} figure in:\n{out}"))
    };
    let (tick, wrench) = (figure("tick"), figure("wrench"));
    assert!(tick > wrench, "a tick ({tick}) includes a wrench ({wrench})");
    assert!(tick < 3200.0, "one loop tick takes {tick} instructions on the M4F (goal < 3,200)");
    assert!(figure("telemetry_push") > 0.0 && figure("command_status") > 0.0);
    assert!(out.lines().any(|l| l == "needle-loop-tick tick_flags=0x0000 model_status=0x00"), "{out}");
    // The loop rendering the whole insertion (issue 41's budget: <= 1,600 instructions
    // per tick on the M4F): every shipped stack, deflecting the surface and deep inside,
    // without and with the passivity guard; the phase each case reached.
    let insertion: Vec<(&str, f64)> = out
        .lines()
        .filter_map(|l| {
            let what = field(l, "what")?;
            Some((what, field(l, "instructions")?.parse().ok()?)).filter(|_| what.starts_with("insertion-"))
        })
        .collect();
    assert_eq!(insertion.len(), 4 * compiled_stacks(Features::Viscoelastic), "{out}");
    let phases: Vec<&str> = out.lines().filter_map(|l| field(l, "insertion_phase")).collect();
    assert_eq!(phases.len(), insertion.len(), "{out}");
    let terms: Vec<usize> = out.lines().filter_map(|l| field(l, "qlv_terms")?.parse().ok()).collect();
    assert_eq!(terms.len(), insertion.len(), "{out}");
    assert!(terms.iter().any(|&t| t > 0), "no case deflects a boundary with Prony terms (the epidural skin has one):\n{out}");
    for ((what, n), &t) in insertion.iter().zip(&terms) {
        // Issue 41's 1,600 is the elastic insertion's budget; a tick whose deflected layer
        // has Prony terms also runs the viscoelastic filter (the insertion's and the
        // guard's), which has its own budget of 120 instructions per tick (issue 39), so
        // such a tick is held to the sum of the two goals.
        let goal = if t == 0 { 1600.0 } else { 1600.0 + 120.0 };
        assert!(*n <= goal, "{what}: {n} instructions per loop tick with {t} Prony term(s) on the deflected layer (goal <= {goal})");
    }
    for ((what, _), phase) in insertion.iter().zip(&phases) {
        let want = if what.contains("-surface") { "0x0100" } else { "0x02" };
        assert!(phase.starts_with(want), "{what}: phase {phase}, want {want}..");
    }
}

/// How many of the host's stacks (every feature) a firmware build with `features` compiles in.
fn compiled_stacks(features: Features) -> usize {
    needle_haptics::insertion::stacks::ALL.iter().filter(|s| features.compiles(s)).count()
}

/// One `insertion-*` case of the `loop_tick` output: its name, instructions per loop tick,
/// the Prony terms on the deflected layer and the phase reached.
fn insertion_cases(out: &str) -> Vec<(String, f64, usize, String)> {
    let mut cases = Vec::new();
    let lines: Vec<&str> = out.lines().collect();
    for (i, l) in lines.iter().enumerate() {
        let Some(what) = field(l, "what").filter(|w| w.starts_with("insertion-")) else { continue };
        let n: f64 = field(l, "instructions").and_then(|v| v.parse().ok()).unwrap_or_else(|| panic!("no instructions: {l}"));
        let next = lines.get(i + 1).copied().unwrap_or_default();
        let terms = field(next, "qlv_terms").and_then(|v| v.parse().ok()).unwrap_or_else(|| panic!("no qlv_terms after {l}: {next}"));
        let phase = field(next, "insertion_phase").unwrap_or_else(|| panic!("no phase after {l}: {next}"));
        cases.push((what.to_string(), n, terms, phase.to_string()));
    }
    cases
}

/// Issue 64's cost goal with the `tissue-shape` feature: the loop rendering the whole
/// insertion, every stack of the build (the shaped one too) at the surface and deep, with
/// and without the guard, within issue 41's 1,600 instructions per elastic tick; a tick
/// whose deflected layer has Prony terms within the sum with the filter's 120 (issue 39),
/// as in the build without the feature. Every case meets it (the rig skin's guarded
/// surface tick 1,685.2 -> 1,587.0 once the square roots of the guard's stiffness and of
/// the force limit were the FPU's instruction, `needle_fpu`).
#[test]
fn loop_tick_instructions_with_tissue_shape_on_cortex_m4f() {
    let out = run_example_with("loop_tick", Features::Shape);
    println!("{out}");
    let cases = insertion_cases(&out);
    assert_eq!(cases.len(), 4 * compiled_stacks(Features::Shape), "{out}");
    assert!(compiled_stacks(Features::Shape) > compiled_stacks(Features::Viscoelastic), "no shaped stack in the build:\n{out}");
    let mut missed = Vec::new();
    for (what, n, terms, phase) in &cases {
        let want = if what.contains("-surface") { "0x0100" } else { "0x02" };
        assert!(phase.starts_with(want), "{what}: phase {phase}, want {want}..");
        let goal = if *terms == 0 { 1600.0 } else { 1600.0 + 120.0 };
        if *n > goal {
            missed
                .push(format!("{what}: {n} instructions per loop tick with {terms} Prony term(s) on the deflected layer (goal <= {goal})"));
        }
    }
    assert!(missed.is_empty(), "with tissue-shape:\n{}", missed.join("\n"));
}

#[test]
fn insertion_trace_at_1_khz_follows_the_model() {
    let out = run_example("insertion");
    println!("{out}");
    let end = out.lines().find(|l| l.starts_with("needle-insertion end")).unwrap_or_else(|| panic!("no end line:\n{out}"));
    assert_eq!(field(end, "ticks"), Some("1200"), "{end}");
    assert_eq!(field(end, "dropped"), Some("0"), "{end}");
    let max_cmd: f32 = field(end, "max_cmd_y_n").and_then(|v| v.parse().ok()).expect("max_cmd_y_n");
    assert!(max_cmd <= 0.0600 + 1e-5, "command above the 0.06 N limit: {max_cmd}");
    let (mut rows, mut max_depth, mut stale, mut saturated) = (0, 0.0f32, 0, 0);
    let mut last_depth_end = f32::NAN;
    for l in out.lines().filter(|l| l.starts_with("needle-insertion t_ms=")) {
        let bits: Vec<u32> =
            field(l, "bits").expect("bits").split(',').map(|b| u32::from_str_radix(b.trim_start_matches("0x"), 16).expect("hex")).collect();
        assert_eq!(bits.len(), 6, "{l}");
        let flags = u16::from_str_radix(field(l, "flags").expect("flags").trim_start_matches("0x"), 16).expect("flags");
        let pose = needle_haptics::Pose::new(
            f32::from_bits(bits[0]),
            f32::from_bits(bits[1]),
            f32::from_bits(bits[2]),
            f32::from_bits(bits[3]),
            f32::from_bits(bits[4]),
        );
        let fy = f32::from_bits(bits[5]);
        if flags & 0x0001 != 0 {
            stale += 1;
            assert_ne!(flags & 0x0020, 0, "stale without RAMPING: {l}");
            assert_eq!(fy, 0.0, "not evaluated on a stale pose: {l}");
        } else {
            let want = needle_haptics::wrench(&pose).wrench.fy_n;
            assert_eq!(fy.to_bits(), want.to_bits(), "firmware fy {fy} vs library {want}: {l}");
        }
        saturated += usize::from(flags & 0x0010 != 0);
        max_depth = max_depth.max(pose.depth_mm);
        last_depth_end = pose.depth_mm;
        rows += 1;
    }
    assert!(rows >= 60, "only {rows} trace lines");
    assert_eq!(max_depth, 6.0);
    assert_eq!(last_depth_end, 0.0, "the needle comes back out");
    assert!(stale >= 3, "the stale window shows in the trace ({stale} lines)");
    assert!(saturated >= 3, "deep poses saturate at the limit ({saturated} lines)");
}
