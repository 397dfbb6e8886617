//! The C API from C: `c/capi_golden.c`, compiled with the host's gcc against this build's
//! `libneedle_capi.a` and the generated `needle.h`, checks every golden vector (f32 and
//! fixed point, wrench and stiffness), the loop's
//! duties, pins and ramp, and the commands; and the same program compiled and linked with
//! arm-none-eabi-gcc (newlib, semihosting) for the Cortex-M4F against the
//! thumbv7em-none-eabihf staticlib, then run under QEMU (mps2-an386) on the same golden
//! file, read through semihosting. `c/m4f_vectors.c` is its vector table: it enables the
//! FPU and enters newlib's crt0.
//!
//! Nothing skips: a missing gcc, arm-none-eabi-gcc, newlib or rustup target fails with a
//! message (.ci/test installs them).
use std::path::Path;
use std::process::Command;

mod common;

use common::{golden_csv, manifest_dir, run, scratch, staticlib};

#[test]
fn header_declares_the_api() {
    for item in [
        "needle_wrench(",
        "needle_fixed_wrench(",
        "needle_fixed_wrench_and_stiffness(",
        "} needle_fixed_stiffness_t;",
        "needle_model_info(",
        "needle_hub_from_tip_mm(",
        "needle_loop_init(",
        "needle_loop_tick(",
        "needle_loop_set_force_limit_n(",
        "needle_loop_set_passivity(",
        "} needle_passivity_t;",
        "needle_loop_command(",
        "needle_insertion_init(",
        "needle_insertion_step(",
        "needle_loop_set_insertion(",
        "} needle_pose_t;",
        "} needle_loop_t;",
        "#define NEEDLE_POSE_STALE 1",
    ] {
        assert!(needle_capi::HEADER.contains(item), "needle.h lacks {item:?}:\n{}", needle_capi::HEADER);
    }
}

#[test]
fn host_c_program_checks_golden_vectors_loop_and_commands() {
    let dir = scratch("host");
    let lib = staticlib(None);
    let exe = dir.join("capi_golden");
    run(
        Command::new("gcc")
            .args(["-std=c11", "-O2", "-Wall", "-Wextra", "-Werror", "-ffp-contract=off", "-I"])
            .arg(&dir)
            .arg(manifest_dir().join("c").join("capi_golden.c"))
            .arg(&lib)
            .args(["-lm", "-lpthread", "-ldl", "-o"])
            .arg(&exe),
        "gcc capi_golden.c",
    );
    let set = Path::new(needle_haptics::model_info::SET_DIR);
    let others = ["golden-stiffness-f32.csv", "golden-fixed.csv", "golden-stiffness-fixed.csv"].map(|f| set.join(f));
    for f in &others {
        assert!(f.is_file(), "{}: no golden vectors; run `needle fit`", f.display());
    }
    let out = run(Command::new(&exe).arg(golden_csv()).args(&others), "capi_golden");
    println!("{out}");
    assert!(out.contains("wrench_mismatches=0 ") && out.contains("loop_failures=0 ") && out.contains("command_failures=0"), "{out}");
    for section in ["capi-golden-stiffness", "capi-golden-fixed"] {
        let line = out.lines().find(|l| l.starts_with(&format!("{section} rows="))).unwrap_or_else(|| panic!("no {section} line:\n{out}"));
        assert!(line.ends_with(" mismatches=0"), "{line}");
    }
}

#[test]
fn arm_c_program_links_and_runs_on_cortex_m4f() {
    let dir = scratch("m4f");
    let lib = staticlib(Some("thumbv7em-none-eabihf"));
    let elf = dir.join("capi_golden.elf");
    run(
        Command::new("arm-none-eabi-gcc")
            .args([
                "-mcpu=cortex-m4",
                "-mthumb",
                "-mfpu=fpv4-sp-d16",
                "-mfloat-abi=hard",
                "-std=c11",
                "-O2",
                "-Wall",
                "-Werror",
                "-ffp-contract=off",
                "--specs=rdimon.specs",
                "-Wl,--gc-sections",
                "-Wl,--undefined=vectors",
                "-Wl,--section-start=.vectors=0x0",
                "-Wl,--no-warn-execstack",
                "-I",
            ])
            .arg(&dir)
            .arg(manifest_dir().join("c").join("capi_golden.c"))
            .arg(manifest_dir().join("c").join("m4f_vectors.c"))
            .arg(&lib)
            .args(["-lm", "-o"])
            .arg(&elf),
        "arm-none-eabi-gcc capi_golden.c",
    );
    let size = run(Command::new("arm-none-eabi-size").arg(&elf), "arm-none-eabi-size");
    println!("{size}");
    let nm = run(Command::new("arm-none-eabi-nm").arg(&elf), "arm-none-eabi-nm");
    for f in ["needle_wrench", "needle_loop_tick", "needle_loop_command"] {
        assert!(nm.lines().any(|l| l.ends_with(&format!(" T {f}"))), "{f} not in the ARM image");
    }
    let golden = golden_csv();
    let semihosting = format!("enable=on,target=native,arg=capi_golden,arg={}", golden.display());
    let out = run(
        // coreutils' timeout: a faulting firmware spins in a handler instead of exiting.
        Command::new("timeout")
            .args([
                "300",
                "qemu-system-arm",
                "-cpu",
                "cortex-m4",
                "-machine",
                "mps2-an386",
                "-display",
                "none",
                "-monitor",
                "none",
                "-serial",
                "null",
            ])
            .args(["-semihosting-config", &semihosting, "-kernel"])
            .arg(&elf),
        "capi_golden on QEMU mps2-an386",
    );
    println!("{out}");
    assert!(out.contains("wrench_mismatches=0 ") && out.contains("loop_failures=0 ") && out.contains("command_failures=0"), "{out}");
}
