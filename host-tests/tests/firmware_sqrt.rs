//! The library's square root on the Cortex-M4F (`needle_fpu::sqrtf`: the FPU's
//! `vsqrt.f32`) gives libm's bits, which every other target uses: the `sqrt_exact`
//! firmware under QEMU compares the two over 1,047,817 inputs (every 4,099th bit pattern
//! and the special values) and counts the instructions of one root each way. A missing
//! QEMU or rustup target fails with a message; nothing skips.
use needle_firmware_host::{self as firmware, build, qemu};
use std::time::Duration;

fn field<'a>(line: &'a str, key: &str) -> Option<&'a str> {
    line.split_whitespace().find_map(|w| w.strip_prefix(key).and_then(|v| v.strip_prefix('=')))
}

#[test]
fn the_fpu_root_is_libm_s_bit_for_bit_on_cortex_m4f() {
    let core = firmware::core("m4f").unwrap_or_else(|e| panic!("{e:#}"));
    let set = firmware::fitted_set(&firmware::compiled_set()).unwrap_or_else(|e| panic!("{e:#}"));
    let elf = build::build_examples(&core, &["sqrt_exact"], &set).unwrap_or_else(|e| panic!("{e:#}")).remove(0);
    let run = qemu::run(&core, &elf, true, Duration::from_secs(300)).unwrap_or_else(|e| panic!("{e:#}"));
    println!("{}", run.stdout);
    let line = |prefix: &str| run.stdout.lines().find(|l| l.starts_with(prefix)).map(str::to_string);
    let count = line("needle-sqrt compared=").unwrap_or_else(|| panic!("no comparison line:\n{}{}", run.stdout, run.stderr));
    assert_eq!(field(&count, "compared"), Some("1047817"), "{count}");
    assert_eq!(field(&count, "differing"), Some("0"), "{count}\n{}", run.stdout);
    assert!(run.status.success(), "sqrt_exact exited with {}:\n{}{}", run.status, run.stdout, run.stderr);
    let head = line("needle-sqrt target=").unwrap_or_default();
    assert_eq!(field(&head, "deterministic"), Some("yes"), "not under -icount: {head}");
    let cost = |what: &str| -> f64 {
        run.stdout
            .lines()
            .find(|l| field(l, "what") == Some(what))
            .and_then(|l| field(l, "instructions")?.parse().ok())
            .unwrap_or_else(|| panic!("no {what} figure:\n{}", run.stdout))
    };
    // the reason for the crate: the instruction is cheaper than the software root
    assert!(cost("fpu") < cost("libm"), "fpu {} vs libm {} instructions per root", cost("fpu"), cost("libm"));
}
