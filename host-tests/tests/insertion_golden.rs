//! Golden insertion sequences: the five trajectories of `examples/common/insertion_paths.rs`
//! and its three glitch paths (issue 66: depth and x jumping to 1e6 mm, x alternating
//! every tick, NaN, infinity, poses replayed backwards) through every shipped tissue stack give the same bits on the host and on the
//! emulated Cortex-M4F, M3 and M0 (the `insertion_golden` firmware under QEMU), with the
//! f32 insertion and with the fixed-point one (`fixed::insertion`), through the C API
//! and in wasm: every
//! tick's six wrench components, status, phase, punctures and flags, compared as a digest per
//! path (FNV-1a over every tick's words; one differing bit changes it). The firmware is
//! built twice: the product's features (`viscoelastic`: the stacks without a family member
//! or a softening) and with `tissue-shape` too (every stack, the shaped ones: issue 64);
//! the host, the C API and wasm have both features and run every stack.
#[path = "../../examples/common/insertion_paths.rs"]
mod paths;

use needle_firmware_host::build::Features;
use needle_firmware_host::{build, core, qemu};
use needle_haptics::fixed;
use needle_haptics::fixed::insertion::{stacks as fixed_stacks, Insertion as FixedInsertion, InsertionConfig as FixedConfig};
use needle_haptics::insertion::{stacks, Insertion, InsertionConfig, Phase, Stack};
use needle_haptics::Pose;
use paths::{depth_scale, for_each_path_tick, for_each_path_tick_q16, for_each_tick, Digest, PATHS, PATH_COUNT};
use std::time::Duration;

/// The host's lines, in the firmware's format: every stack (the host crates have every
/// library feature).
fn host_lines() -> Vec<String> {
    host_lines_of(|_| true)
}

/// The host's lines of the stacks `keep` takes (those a firmware build compiles in).
fn host_lines_of(keep: impl Fn(&Stack<'_>) -> bool) -> Vec<String> {
    let mut lines = Vec::new();
    for stack in stacks::ALL.iter().filter(|s| keep(s)) {
        for i in 0..PATH_COUNT {
            let mut insertion = Insertion::new(stack, InsertionConfig::DEFAULT_1KHZ).expect("shipped stack");
            let mut digest = Digest::new();
            let (mut ticks, mut punctures) = (0u64, 0u64);
            for_each_path_tick(i, depth_scale(stack), |_, p| {
                let e = insertion.step(&Pose { x_mm: p[0], z_mm: p[1], theta_x_deg: p[2], theta_z_deg: p[3], depth_mm: p[4] });
                digest.tick(e.wrench.to_array(), e.status.bits(), e.phase.code(), e.punctures, e.flags.bits());
                ticks += 1;
                punctures += u64::from(e.punctures);
            });
            lines.push(line("", stack.name, i, ticks, punctures, digest));
        }
    }
    lines
}

/// One path's line, as the firmware prints it.
fn line(prefix: &str, name: &str, i: usize, ticks: u64, punctures: u64, digest: Digest) -> String {
    format!(
        "{prefix}stack={name} path={i} ticks={ticks} punctures={punctures} digest_hi={:#010x} digest_lo={:#010x}",
        (digest.0 >> 32) as u32,
        digest.0 as u32
    )
}

/// The host's lines of the fixed-point insertion (`fixed::insertion`, the paths' Q16.16
/// poses), in the firmware's format: every stack.
fn host_fixed_lines() -> Vec<String> {
    host_fixed_lines_of(|_| true)
}

/// The host's fixed-point lines of the stacks `keep` takes (by their f32 form).
fn host_fixed_lines_of(keep: impl Fn(&Stack<'_>) -> bool) -> Vec<String> {
    let mut lines = Vec::new();
    for (stack, scale_of) in fixed_stacks::ALL.iter().zip(&stacks::ALL).filter(|(_, s)| keep(s)) {
        for i in 0..PATH_COUNT {
            let mut insertion = FixedInsertion::new(stack, FixedConfig::DEFAULT_1KHZ).expect("shipped stack");
            let mut digest = Digest::new();
            let (mut ticks, mut punctures) = (0u64, 0u64);
            for_each_path_tick_q16(i, depth_scale(scale_of), |_, p| {
                let e = insertion.step(&fixed::Pose::new(p[0], p[1], p[2], p[3], p[4]));
                digest.tick_fixed(e.wrench.to_array(), e.status.bits(), e.phase.code(), e.punctures, e.flags.bits());
                ticks += 1;
                punctures += u64::from(e.punctures);
            });
            lines.push(line("fixed ", stack.name, i, ticks, punctures, digest));
        }
    }
    lines
}

#[test]
fn the_golden_paths_cross_punctures_and_withdraw() {
    assert!(!stacks::ALL.is_empty(), "the default set ships tissue stacks");
    for line in host_lines() {
        println!("{line}");
        let punctures: u64 = line.split(' ').find_map(|w| w.strip_prefix("punctures=")).and_then(|v| v.parse().ok()).expect("punctures");
        assert!(punctures >= 1, "every golden path punctures at least once: {line}");
    }
}

/// The liver's paths are the paths as drawn (depth factor 1, so their digests are the
/// ones before the epidural stack); the epidural stack's reach its epidural space: some
/// path punctures its last layer's boundary (the loss of resistance).
#[test]
fn the_golden_paths_reach_the_deepest_layer_of_every_stack() {
    assert_eq!(depth_scale(&stacks::LIVER).to_bits(), 1.0f32.to_bits(), "the liver's paths are not scaled");
    let deepest = PATHS.iter().flat_map(|p| p.iter().map(|w| w.1[4])).fold(f32::NEG_INFINITY, f32::max);
    assert_eq!(paths::PATHS_DEEPEST_MM, deepest);
    for stack in &stacks::ALL {
        let last = u8::try_from(stack.layers.len() - 1).expect("layer count");
        let mut into_last = Vec::new();
        for (i, path) in PATHS.iter().enumerate() {
            let mut insertion = Insertion::new(stack, InsertionConfig::DEFAULT_1KHZ).expect("shipped stack");
            let mut reached = false;
            for_each_tick(path, depth_scale(stack), |_, p| {
                let e = insertion.step(&Pose { x_mm: p[0], z_mm: p[1], theta_x_deg: p[2], theta_z_deg: p[3], depth_mm: p[4] });
                reached |= e.punctures > 0 && matches!(e.phase, Phase::Cutting(l) | Phase::InTrack(l) if l == last);
            });
            if reached {
                into_last.push(i);
            }
        }
        println!("{}: paths {into_last:?} puncture into the last layer ({})", stack.name, last);
        assert!(!into_last.is_empty(), "{}: no golden path punctures into its last layer", stack.name);
    }
}

/// The `insertion_golden` firmware built with `features` on `core_name` under QEMU against
/// the host's lines of the stacks that build compiles in.
fn on(core_name: &str, features: Features) {
    let core = core(core_name).unwrap_or_else(|e| panic!("{e:#}"));
    let set = needle_firmware_host::compiled_set();
    let elf = build::build_examples_with(&core, &["insertion_golden"], &set, features).unwrap_or_else(|e| panic!("{e:#}")).remove(0);
    let run = qemu::run(&core, &elf, false, Duration::from_secs(900)).unwrap_or_else(|e| panic!("{e:#}"));
    assert!(run.status.success(), "{core_name}: exit {}: {}\n{}", run.status, run.stdout, run.stderr);
    let got: Vec<&str> = run.stdout.lines().filter(|l| l.starts_with("stack=") || l.starts_with("fixed stack=")).collect();
    let keep = |s: &Stack<'_>| features.compiles(s);
    let want: Vec<String> = host_lines_of(keep).into_iter().chain(host_fixed_lines_of(keep)).collect();
    assert_eq!(got.len(), want.len(), "{core_name}: {} paths printed, the host has {}:\n{}", got.len(), want.len(), run.stdout);
    for (g, w) in got.iter().zip(&want) {
        assert_eq!(g, w, "{core_name}: the firmware's path differs from the host's");
    }
    assert!(run.stdout.lines().any(|l| l == "needle-insertion-golden end"), "{core_name}: no end line");
    println!("{core_name} ({features:?}): {} golden insertion paths bit-exact ({:.1} s under QEMU)", got.len(), run.elapsed.as_secs_f64());
}

#[test]
fn golden_insertions_on_cortex_m4f_mps2_an386() {
    on("m4f", Features::Viscoelastic);
}

#[test]
fn golden_insertions_on_cortex_m3_mps2_an385() {
    on("m3", Features::Viscoelastic);
}

#[test]
fn golden_insertions_on_cortex_m0_microbit() {
    on("m0", Features::Viscoelastic);
}

/// The shipped stacks that only a build with `tissue-shape` compiles in (a family member or
/// a softening): the shaped goldens below run them, so they cannot pass without one.
fn shaped_stacks() -> Vec<&'static str> {
    stacks::ALL.iter().filter(|s| Features::Shape.compiles(s) && !Features::Viscoelastic.compiles(s)).map(|s| s.name).collect()
}

/// The same paths with the `tissue-shape` feature (and `viscoelastic`): every stack, the
/// shaped ones too, f32 and fixed point (issue 64).
fn shaped_on(core_name: &str) {
    assert!(!shaped_stacks().is_empty(), "the set ships no stack with a family member or a softening");
    on(core_name, Features::Shape);
}

#[test]
fn golden_shaped_insertions_on_cortex_m4f_mps2_an386() {
    shaped_on("m4f");
}

#[test]
fn golden_shaped_insertions_on_cortex_m3_mps2_an385() {
    shaped_on("m3");
}

#[test]
fn golden_shaped_insertions_on_cortex_m0_microbit() {
    shaped_on("m0");
}

/// The C API's run of the paths (`needle_insertion_*` through their C ABI), in the
/// firmware's line format.
fn c_api_lines() -> Vec<String> {
    use needle_capi::{
        needle_insertion_init, needle_insertion_result_t, needle_insertion_step, needle_insertion_t, needle_pose_t, NEEDLE_OK,
    };
    let mut lines = Vec::new();
    for stack in &stacks::ALL {
        let name = std::ffi::CString::new(stack.name).expect("stack name");
        for i in 0..PATH_COUNT {
            let mut state = needle_insertion_t { storage: [0; needle_capi::NEEDLE_INSERTION_STORAGE_WORDS], magic: 0 };
            let config = InsertionConfig::DEFAULT_1KHZ;
            // SAFETY: valid pointers to local values and a NUL-terminated name.
            let rc = unsafe { needle_insertion_init(&mut state, name.as_ptr(), config.period_s, config.velocity_time_constant_s) };
            assert_eq!(rc, NEEDLE_OK, "needle_insertion_init({})", stack.name);
            let mut digest = Digest::new();
            let (mut ticks, mut punctures) = (0u64, 0u64);
            for_each_path_tick(i, depth_scale(stack), |_, p| {
                let pose = needle_pose_t { x_mm: p[0], z_mm: p[1], theta_x_deg: p[2], theta_z_deg: p[3], depth_mm: p[4] };
                let mut out = needle_insertion_result_t::default();
                // SAFETY: valid pointers to local values; the state was initialised above.
                assert_eq!(unsafe { needle_insertion_step(&mut state, &pose, &mut out) }, NEEDLE_OK);
                let w = out.wrench;
                digest.tick([w.fx_n, w.fy_n, w.fz_n, w.mx_nmm, w.my_nmm, w.mz_nmm], out.status, out.phase, out.punctures, out.flags);
                ticks += 1;
                punctures += u64::from(out.punctures);
            });
            lines.push(format!(
                "stack={} path={i} ticks={ticks} punctures={punctures} digest_hi={:#010x} digest_lo={:#010x}",
                stack.name,
                (digest.0 >> 32) as u32,
                digest.0 as u32
            ));
        }
    }
    lines
}

#[test]
fn golden_insertions_through_the_c_api() {
    assert_eq!(c_api_lines(), host_lines());
}

/// The C API's run of the paths with the fixed-point insertion (`needle_fixed_insertion_*`).
fn c_api_fixed_lines() -> Vec<String> {
    use needle_capi::{
        needle_fixed_insertion_init, needle_fixed_insertion_result_t, needle_fixed_insertion_step, needle_fixed_insertion_t,
        needle_fixed_pose_t, NEEDLE_FIXED_INSERTION_STORAGE_WORDS, NEEDLE_OK,
    };
    let mut lines = Vec::new();
    for (stack, scale_of) in fixed_stacks::ALL.iter().zip(&stacks::ALL) {
        let name = std::ffi::CString::new(stack.name).expect("stack name");
        for i in 0..PATH_COUNT {
            let mut state = needle_fixed_insertion_t { storage: [0; NEEDLE_FIXED_INSERTION_STORAGE_WORDS], magic: 0 };
            let c = FixedConfig::DEFAULT_1KHZ;
            // SAFETY: valid pointers to local values and a NUL-terminated name.
            let rc = unsafe { needle_fixed_insertion_init(&mut state, name.as_ptr(), c.period_us, c.velocity_time_constant_us) };
            assert_eq!(rc, NEEDLE_OK, "needle_fixed_insertion_init({})", stack.name);
            let mut digest = Digest::new();
            let (mut ticks, mut punctures) = (0u64, 0u64);
            for_each_path_tick_q16(i, depth_scale(scale_of), |_, p| {
                let pose = needle_fixed_pose_t {
                    x_mm_q16: p[0],
                    z_mm_q16: p[1],
                    theta_x_deg_q16: p[2],
                    theta_z_deg_q16: p[3],
                    depth_mm_q16: p[4],
                };
                let mut out = needle_fixed_insertion_result_t::default();
                // SAFETY: valid pointers to local values; the state was initialised above.
                assert_eq!(unsafe { needle_fixed_insertion_step(&mut state, &pose, &mut out) }, NEEDLE_OK);
                let w = out.wrench;
                digest.tick_fixed(
                    [w.fx_un, w.fy_un, w.fz_un, w.mx_unmm, w.my_unmm, w.mz_unmm],
                    out.status,
                    out.phase,
                    out.punctures,
                    out.flags,
                );
                ticks += 1;
                punctures += u64::from(out.punctures);
            });
            lines.push(line("fixed ", stack.name, i, ticks, punctures, digest));
        }
    }
    lines
}

#[test]
fn golden_fixed_point_insertions_through_the_c_api() {
    assert_eq!(c_api_fixed_lines(), host_fixed_lines());
}

#[test]
fn the_c_api_refuses_bad_fixed_point_arguments() {
    use needle_capi::*;
    let mut state = needle_fixed_insertion_t { storage: [0; NEEDLE_FIXED_INSERTION_STORAGE_WORDS], magic: 0 };
    let name = std::ffi::CString::new(fixed_stacks::ALL[0].name).expect("stack name");
    let pose = needle_fixed_pose_t::default();
    let mut out = needle_fixed_insertion_result_t::default();
    // SAFETY: valid or NULL pointers, as each case says.
    unsafe {
        assert_eq!(needle_fixed_insertion_step(&mut state, &pose, &mut out), NEEDLE_E_UNINIT);
        assert_eq!(needle_fixed_insertion_init(std::ptr::null_mut(), name.as_ptr(), 1000, 5000), NEEDLE_E_NULL);
        assert_eq!(needle_fixed_insertion_init(&mut state, c"no-such-stack".as_ptr(), 1000, 5000), NEEDLE_E_ARG);
        assert_eq!(needle_fixed_insertion_init(&mut state, name.as_ptr(), 0, 5000), NEEDLE_E_CONFIG);
        assert_eq!(state.magic, 0, "nothing written on an error");
        assert_eq!(needle_fixed_insertion_init(&mut state, name.as_ptr(), 1000, 5000), NEEDLE_OK);
        assert_eq!(needle_fixed_insertion_step(&mut state, std::ptr::null(), &mut out), NEEDLE_E_NULL);
        assert_eq!(needle_fixed_insertion_set_scales(&mut state, [1i32 << 16].as_ptr(), 99), NEEDLE_E_ARG);
        assert_eq!(needle_fixed_insertion_set_scales(&mut state, std::ptr::null(), 1), NEEDLE_E_NULL);
        assert_eq!(needle_fixed_insertion_reset(std::ptr::null_mut()), NEEDLE_E_NULL);
        assert_eq!(needle_fixed_insertion_reset(&mut state), NEEDLE_OK);
    }
}

#[test]
fn the_c_api_refuses_bad_arguments() {
    use needle_capi::*;
    let mut state = needle_insertion_t { storage: [0; NEEDLE_INSERTION_STORAGE_WORDS], magic: 0 };
    let liver = c"liver";
    let pose = needle_pose_t::default();
    let mut out = needle_insertion_result_t::default();
    // SAFETY: valid or NULL pointers, as each case says.
    unsafe {
        assert_eq!(needle_insertion_step(&mut state, &pose, &mut out), NEEDLE_E_UNINIT);
        assert_eq!(needle_insertion_init(std::ptr::null_mut(), liver.as_ptr(), 0.001, 0.005), NEEDLE_E_NULL);
        assert_eq!(needle_insertion_init(&mut state, c"no-such-stack".as_ptr(), 0.001, 0.005), NEEDLE_E_ARG);
        assert_eq!(needle_insertion_init(&mut state, liver.as_ptr(), 0.0, 0.005), NEEDLE_E_CONFIG);
        assert_eq!(needle_insertion_init(&mut state, liver.as_ptr(), f32::INFINITY, 0.005), NEEDLE_E_CONFIG);
        assert_eq!(needle_insertion_init(&mut state, liver.as_ptr(), 0.001, f32::NAN), NEEDLE_E_CONFIG);
        assert_eq!(state.magic, 0, "nothing written on an error");
        assert_eq!(needle_insertion_init(&mut state, liver.as_ptr(), 0.001, 0.005), NEEDLE_OK);
        assert_eq!(needle_insertion_step(&mut state, std::ptr::null(), &mut out), NEEDLE_E_NULL);
        assert_eq!(needle_insertion_set_scales(&mut state, [1.0f32].as_ptr(), 99), NEEDLE_E_ARG);
        assert_eq!(needle_insertion_set_scales(&mut state, std::ptr::null(), 1), NEEDLE_E_NULL);
        assert_eq!(needle_insertion_reset(std::ptr::null_mut()), NEEDLE_E_NULL);
    }
}

#[test]
fn golden_insertions_in_wasm_under_node() {
    let root = needle_stdx::workspace_root();
    let set = root.join("coeffs/default");
    let wasm = needle_explore::wasm::build(&set).expect("build the wasm evaluator");
    let dir = tempfile::tempdir().expect("temp dir");
    let poses = dir.path().join("poses.txt");
    let mut text = String::new();
    for (s, stack) in stacks::ALL.iter().enumerate() {
        for i in 0..PATH_COUNT {
            for_each_path_tick(i, depth_scale(stack), |_, p| {
                text.push_str(&format!(
                    "{s} {i} {:x} {:x} {:x} {:x} {:x}\n",
                    p[0].to_bits(),
                    p[1].to_bits(),
                    p[2].to_bits(),
                    p[3].to_bits(),
                    p[4].to_bits()
                ));
            });
        }
    }
    std::fs::write(&poses, text).expect("poses file");
    let names: Vec<&str> = stacks::ALL.iter().map(|s| s.name).collect();
    let out = std::process::Command::new("node")
        .arg(root.join("host-tests/tests/explore/insertion.mjs"))
        .arg(&wasm)
        .arg(&poses)
        .env("NEEDLE_STACK_NAMES", names.join(","))
        .output()
        .expect("node must be installed (apt nodejs): the wasm check runs under it");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "node: {stdout}{}", String::from_utf8_lossy(&out.stderr));
    let got: Vec<String> = stdout.lines().map(str::to_string).collect();
    assert_eq!(got, host_lines(), "the wasm module's insertion differs from the host's");

    // the fixed-point insertion: the Q16.16 poses of the same paths
    let mut text = String::new();
    for (s, scale_of) in stacks::ALL.iter().enumerate() {
        for i in 0..PATH_COUNT {
            for_each_path_tick_q16(i, depth_scale(scale_of), |_, p| {
                text.push_str(&format!(
                    "{s} {i} {:x} {:x} {:x} {:x} {:x}\n",
                    p[0] as u32, p[1] as u32, p[2] as u32, p[3] as u32, p[4] as u32
                ));
            });
        }
    }
    std::fs::write(&poses, text).expect("poses file");
    let out = std::process::Command::new("node")
        .arg(root.join("host-tests/tests/explore/insertion.mjs"))
        .arg(&wasm)
        .arg(&poses)
        .env("NEEDLE_STACK_NAMES", names.join(","))
        .env("NEEDLE_FIXED", "1")
        .output()
        .expect("node must be installed (apt nodejs): the wasm check runs under it");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "node: {stdout}{}", String::from_utf8_lossy(&out.stderr));
    let got: Vec<String> = stdout.lines().map(str::to_string).collect();
    assert_eq!(got, host_fixed_lines(), "the wasm module's fixed-point insertion differs from the host's");
}
