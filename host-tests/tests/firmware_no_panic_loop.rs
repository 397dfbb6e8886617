//! The control loop, telemetry and host-link commands have no panic path on the three
//! reference cores: the `no_panic_loop` firmware (whose panic handler calls an undefined
//! function) links and runs under QEMU. Its flash is reported beside the model-only
//! `no_panic` image.
//!
//! Nothing skips: a missing rustup target, QEMU or fitted model fails with a message.
use needle_firmware_host::{self as firmware, build, qemu, size, CORES};
use std::time::Duration;

#[test]
fn no_panic_loop_firmware_links_and_runs_on_every_core() {
    let set = firmware::fitted_set(&firmware::compiled_set()).unwrap_or_else(|e| panic!("{e:#}"));
    for core in &CORES {
        let elfs = build::build_examples(core, &["no_panic", "no_panic_loop"], &set)
            .unwrap_or_else(|e| panic!("no_panic_loop for {} ({}): {e:#}", core.core, core.target));
        let run = qemu::run(core, &elfs[1], false, Duration::from_secs(60)).unwrap_or_else(|e| panic!("{e:#}"));
        assert!(run.status.success(), "no_panic_loop on {} exited with {}: {}{}", core.core, run.status, run.stdout, run.stderr);
        let (model, with_loop) = (
            size::measure(core, &elfs[0], "f32").unwrap_or_else(|e| panic!("{e:#}")),
            size::measure(core, &elfs[1], "f32 + loop").unwrap_or_else(|e| panic!("{e:#}")),
        );
        println!(
            "{} ({}): no_panic_loop links and runs; flash (text + data) {} B, model-only no_panic {} B: loop, telemetry and commands add {} B; static RAM {} B",
            core.core,
            core.target,
            with_loop.text + with_loop.data,
            model.text + model.data,
            (with_loop.text + with_loop.data).saturating_sub(model.text + model.data),
            with_loop.static_ram()
        );
    }
}
