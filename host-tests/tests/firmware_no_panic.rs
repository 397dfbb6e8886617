//! The library on the three reference Cortex-M targets: it builds with every
//! combination of its features (enumerated from the root Cargo.toml), and the `no_panic`
//! firmware links (its panic handler calls an undefined function, so it links only if the
//! optimiser removed every panic path from the evaluator) and runs under QEMU.
//!
//! Nothing skips: a missing rustup target, QEMU or fitted model fails with a message.
use needle_host::firmware::{self, build, qemu, CORES};
use std::time::Duration;

#[test]
fn library_builds_with_every_feature_combination_for_every_core() {
    let features = build::library_features().unwrap_or_else(|e| panic!("{e:#}"));
    let combos = build::feature_combinations(&features);
    assert_eq!(combos.len(), 1 << features.len());
    let set = firmware::compiled_set();
    for core in &CORES {
        for combo in &combos {
            build::build_library(core, combo, &set).unwrap_or_else(|e| panic!("{e:#}"));
        }
    }
    println!("features {features:?}: {} combinations built for {} targets", combos.len(), CORES.len());
}

#[test]
fn no_panic_firmware_links_and_runs_on_every_core() {
    // The placeholder of an unfitted set has no evaluator to check: require the model.
    let set = firmware::fitted_set(&firmware::compiled_set()).unwrap_or_else(|e| panic!("{e:#}"));
    for core in &CORES {
        let elf = build::build_examples(core, &["no_panic"], &set)
            .unwrap_or_else(|e| panic!("no_panic for {} ({}): {e:#}", core.core, core.target))
            .remove(0);
        let run = qemu::run(core, &elf, false, Duration::from_secs(60)).unwrap_or_else(|e| panic!("{e:#}"));
        assert!(run.status.success(), "no_panic on {} exited with {}: {}{}", core.core, run.status, run.stdout, run.stderr);
        println!("{} ({}): no_panic links and runs", core.core, core.target);
    }
}
