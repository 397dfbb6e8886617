//! The insertion model through the C API from C: `c/capi_insertion.c`, compiled with the
//! host's gcc against this build's `libneedle_capi.a` and `needle.h`, steps the golden
//! insertion paths (examples/common/insertion_paths.rs) through every compiled-in stack
//! with `needle_insertion_*`, and a C loop rendering each with `needle_loop_set_insertion`;
//! every path's digest must equal the Rust library's own run, bit for bit; and
//! `c/capi_fixed_insertion.c` the same with the fixed-point insertion
//! (`needle_fixed_insertion_*`, the paths' Q16.16 poses).
//!
//! Nothing skips: a missing gcc fails with a message (.ci/test installs it).
#[path = "../../../examples/common/insertion_paths.rs"]
mod paths;

mod common;

use common::{manifest_dir, run, scratch, staticlib};
use needle_haptics::control::{ChannelMap, LoopConfig, LoopCore, OverLimit};
use needle_haptics::insertion::{stacks, Insertion, InsertionConfig};
use needle_haptics::Pose;
use paths::{depth_scale, for_each_path_tick, for_each_path_tick_q16, Digest, PATH_COUNT};
use std::fmt::Write as _;
use std::process::Command;

/// The C program's loop configuration (capi_insertion.c, `start`): channel i pushes
/// along axis i at 0.01 per N, a 100 N limit that never binds.
fn loop_core() -> LoopCore<3> {
    let ch = |i: usize| {
        let mut gains_per_n = [0.0; 3];
        gains_per_n[i] = 0.01;
        ChannelMap { gains_per_n, direction_inverted: false }
    };
    let config = LoopConfig {
        channels: [ch(0), ch(1), ch(2)],
        force_limit_n: 100.0,
        force_limit_max_n: 100.0,
        over_limit: OverLimit::Saturate,
        ramp_step_n: 0.01,
    };
    LoopCore::new(config).expect("config")
}

/// The ticks file for the C program, and the lines it must print.
fn ticks_and_expected() -> (String, Vec<String>) {
    let (mut ticks, mut want) = (String::new(), Vec::new());
    for stack in &stacks::ALL {
        for i in 0..PATH_COUNT {
            let mut ins = Insertion::new(stack, InsertionConfig::DEFAULT_1KHZ).expect("shipped stack");
            let mut l = loop_core();
            l.set_insertion(Some(ins));
            let (mut digest, mut loop_digest) = (Digest::new(), Digest::new());
            let (mut n, mut punctures) = (0u64, 0u64);
            for_each_path_tick(i, depth_scale(stack), |_, p| {
                let _ = writeln!(
                    ticks,
                    "{} {i} {:x} {:x} {:x} {:x} {:x}",
                    stack.name,
                    p[0].to_bits(),
                    p[1].to_bits(),
                    p[2].to_bits(),
                    p[3].to_bits(),
                    p[4].to_bits()
                );
                let pose = Pose { x_mm: p[0], z_mm: p[1], theta_x_deg: p[2], theta_z_deg: p[3], depth_mm: p[4] };
                let e = ins.step(&pose);
                digest.tick(e.wrench.to_array(), e.status.bits(), e.phase.code(), e.punctures, e.flags.bits());
                n += 1;
                punctures += u64::from(e.punctures);
                let s = l.step(Ok(pose));
                for c in s.force_cmd_n {
                    loop_digest.word(c.to_bits());
                }
                loop_digest.word(u32::from(s.flags.bits()));
                loop_digest.word(u32::from(s.model.bits()));
            });
            let hex = |d: Digest| format!("digest_hi={:#010x} digest_lo={:#010x}", (d.0 >> 32) as u32, d.0 as u32);
            want.push(format!("stack={} path={i} ticks={n} punctures={punctures} {}", stack.name, hex(digest)));
            want.push(format!("loop stack={} path={i} {}", stack.name, hex(loop_digest)));
        }
    }
    (ticks, want)
}

#[test]
fn c_program_steps_the_golden_insertion_paths_bit_for_bit() {
    assert!(!stacks::ALL.is_empty(), "the default set ships tissue stacks");
    let dir = scratch("insertion");
    let lib = staticlib(None);
    let exe = dir.join("capi_insertion");
    run(
        Command::new("gcc")
            .args(["-std=c11", "-O2", "-Wall", "-Wextra", "-Werror", "-ffp-contract=off", "-I"])
            .arg(&dir)
            .arg(manifest_dir().join("c").join("capi_insertion.c"))
            .arg(&lib)
            .args(["-lm", "-lpthread", "-ldl", "-o"])
            .arg(&exe),
        "gcc capi_insertion.c",
    );
    let (ticks, want) = ticks_and_expected();
    let file = dir.join("ticks.txt");
    std::fs::write(&file, &ticks).expect("write ticks.txt");
    let out = run(Command::new(&exe).arg(&file), "capi_insertion");
    let got: Vec<&str> = out.lines().filter(|l| l.starts_with("stack=") || l.starts_with("loop stack=")).collect();
    assert_eq!(got.len(), want.len(), "{out}");
    for (g, w) in got.iter().zip(&want) {
        assert_eq!(g, w, "the C program's run differs from the library's");
    }
    let total = ticks.lines().count();
    let end = out.lines().find(|l| l.starts_with("capi-insertion ")).unwrap_or_else(|| panic!("no summary:\n{out}"));
    assert_eq!(end, format!("capi-insertion ticks_read={total} failures=0 refusals=ok"));
    println!("{} paths ({total} ticks) through the C API match the library, insertion and loop", want.len() / 2);
}

/// The Q16.16 ticks file for `capi_fixed_insertion`, and the lines it must print.
fn fixed_ticks_and_expected() -> (String, Vec<String>) {
    use needle_haptics::fixed::insertion::{stacks as fixed_stacks, Insertion as FixedInsertion, InsertionConfig as FixedConfig};
    let (mut ticks, mut want) = (String::new(), Vec::new());
    for (stack, scale_of) in fixed_stacks::ALL.iter().zip(&stacks::ALL) {
        for i in 0..PATH_COUNT {
            let mut ins = FixedInsertion::new(stack, FixedConfig::DEFAULT_1KHZ).expect("shipped stack");
            let mut digest = Digest::new();
            let (mut n, mut punctures) = (0u64, 0u64);
            for_each_path_tick_q16(i, depth_scale(scale_of), |_, p| {
                let _ = writeln!(
                    ticks,
                    "{} {i} {:x} {:x} {:x} {:x} {:x}",
                    stack.name, p[0] as u32, p[1] as u32, p[2] as u32, p[3] as u32, p[4] as u32
                );
                let e = ins.step(&needle_haptics::fixed::Pose::new(p[0], p[1], p[2], p[3], p[4]));
                digest.tick_fixed(e.wrench.to_array(), e.status.bits(), e.phase.code(), e.punctures, e.flags.bits());
                n += 1;
                punctures += u64::from(e.punctures);
            });
            want.push(format!(
                "fixed stack={} path={i} ticks={n} punctures={punctures} digest_hi={:#010x} digest_lo={:#010x}",
                stack.name,
                (digest.0 >> 32) as u32,
                digest.0 as u32
            ));
        }
    }
    (ticks, want)
}

#[test]
fn c_program_steps_the_fixed_point_insertion_bit_for_bit() {
    let dir = scratch("fixed-insertion");
    let lib = staticlib(None);
    let exe = dir.join("capi_fixed_insertion");
    run(
        Command::new("gcc")
            .args(["-std=c11", "-O2", "-Wall", "-Wextra", "-Werror", "-I"])
            .arg(&dir)
            .arg(manifest_dir().join("c").join("capi_fixed_insertion.c"))
            .arg(&lib)
            .args(["-lm", "-lpthread", "-ldl", "-o"])
            .arg(&exe),
        "gcc capi_fixed_insertion.c",
    );
    let (ticks, want) = fixed_ticks_and_expected();
    let file = dir.join("ticks.txt");
    std::fs::write(&file, &ticks).expect("write ticks.txt");
    let out = run(Command::new(&exe).arg(&file), "capi_fixed_insertion");
    let got: Vec<&str> = out.lines().filter(|l| l.starts_with("fixed stack=")).collect();
    assert_eq!(got, want, "the C program's fixed-point run differs from the library's");
    let total = ticks.lines().count();
    let end = out.lines().find(|l| l.starts_with("capi-fixed-insertion ")).unwrap_or_else(|| panic!("no summary:\n{out}"));
    assert_eq!(end, format!("capi-fixed-insertion ticks_read={total} failures=0 refusals=ok"));
    println!("{} fixed-point paths ({total} ticks) through the C API match the library", want.len());
}
