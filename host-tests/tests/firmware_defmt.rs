//! The `defmt` feature end to end: the `defmt_log` firmware (Cortex-M4F under QEMU,
//! `defmt-semihosting` logger) writes binary defmt frames; `defmt-print` decodes them with
//! the ELF's string table. The decoded log must show the model's identity, every tick's
//! `Sample` (its `fy_n` equal to the library's wrench of the logged pose), the stale tick's
//! flags, and the parser's `FrameError`.
//!
//! Nothing skips: a missing QEMU, rustup target or `defmt-print` (.ci/test installs it
//! with `cargo install defmt-print`) fails with a message.
use needle_firmware_host::{self as firmware, build, qemu};
use std::io::Write;
use std::process::{Command, Stdio};

fn build_defmt_log() -> std::path::PathBuf {
    let core = firmware::core("m4f").unwrap_or_else(|e| panic!("{e:#}"));
    build::check_target(core.target).unwrap_or_else(|e| panic!("{e:#}"));
    let set = firmware::fitted_set(&firmware::compiled_set()).unwrap_or_else(|e| panic!("{e:#}"));
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let out = Command::new(cargo)
        .current_dir(needle_stdx::workspace_root())
        .args(["build", "--release", "-p", "needle-haptics", "--example", "defmt_log", "--features", "defmt"])
        .args(["--target", core.target, "--target-dir"])
        .arg(build::target_dir())
        .env("NEEDLE_COEFFS", &set)
        .stdin(Stdio::null())
        .output()
        .expect("run cargo");
    assert!(out.status.success(), "cargo build of defmt_log failed:\n{}", String::from_utf8_lossy(&out.stderr));
    build::examples_dir(&core).join("defmt_log")
}

#[test]
fn defmt_log_decodes_on_the_host() {
    let elf = build_defmt_log();
    let core = firmware::core("m4f").unwrap_or_else(|e| panic!("{e:#}"));
    let qemu = qemu::qemu().unwrap_or_else(|e| panic!("{e:#}"));
    let run = Command::new(qemu)
        .args(["-machine", core.machine, "-cpu", core.cpu, "-display", "none", "-monitor", "none", "-serial", "null"])
        .args(["-semihosting-config", "enable=on,target=native", "-kernel"])
        .arg(&elf)
        .stdin(Stdio::null())
        .output()
        .expect("run qemu");
    assert!(run.status.success(), "defmt_log exited with {}: {}", run.status, String::from_utf8_lossy(&run.stderr));
    assert!(!run.stdout.is_empty(), "no defmt frames");
    let printer = qemu::find_on_path("defmt-print").unwrap_or_else(|| {
        panic!("defmt-print is not on PATH: `cargo install defmt-print --locked` (.ci/test does it); this test never skips")
    });
    let mut child = Command::new(printer)
        .arg("-e")
        .arg(&elf)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run defmt-print");
    child.stdin.take().expect("stdin").write_all(&run.stdout).expect("feed defmt-print");
    let out = child.wait_with_output().expect("defmt-print");
    let log = String::from_utf8_lossy(&out.stdout).into_owned();
    println!("{log}");
    let set = needle_haptics::model_info::SET;
    assert!(log.contains(&format!("defmt-log set={set} fitted=true")), "{log}\n{}", String::from_utf8_lossy(&out.stderr));
    let samples: Vec<&str> = log.lines().filter(|l| l.contains("defmt-log sample Sample {")).collect();
    assert_eq!(samples.len(), 6, "{log}");
    for (k, l) in samples.iter().take(5).enumerate() {
        let i = (k + 1) as f32;
        let pose = needle_haptics::Pose::new(2.0, -1.0, 2.0 * i, 0.0, 1.2 * i);
        let want = needle_haptics::wrench(&pose).wrench.fy_n;
        let fy: f32 = l
            .split("fy_n: ")
            .nth(1)
            .and_then(|r| r.split([',', ' ']).next())
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("no fy_n in {l}"));
        assert_eq!(fy, want, "tick {}: logged fy_n {fy} vs library {want}: {l}", k + 1);
        assert!(l.contains(&format!("tick: {}", k + 1)), "{l}");
    }
    assert!(log.contains("defmt-log stale pose: flags LoopFlags(0x0021)"), "{log}");
    assert!(log.contains("defmt-log frame Err(Malformed("), "{log}");
    assert!(log.contains("defmt-log frame Ok(SetMode(RampToZero))"), "{log}");
    assert!(log.lines().any(|l| l.contains("defmt-log end")), "{log}");
}
