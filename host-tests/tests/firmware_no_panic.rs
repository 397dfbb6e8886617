//! The library on the three reference Cortex-M targets: it builds with every
//! combination of its features (enumerated from the root Cargo.toml), and the `no_panic`
//! (f32) and `no_panic_fixed` (fixed point) firmware link (their panic handlers call an
//! undefined function, so they link only if the optimiser removed every panic path from
//! the evaluator) and run under QEMU. The fixed-point evaluator is integer-only: its
//! disassembly calls no soft-float helper and has no FPU instruction on any core (and the
//! same check does find them in the f32 evaluator).
//!
//! Nothing skips: a missing rustup target, QEMU or fitted model fails with a message.
use needle_firmware_host::build::Features;
use needle_firmware_host::{self as firmware, build, float_check, qemu, size, CORES};
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
        let names = ["no_panic", "no_panic_fixed", "no_panic_stiffness", "no_panic_insertion", "no_panic_fixed_insertion"];
        let elfs = build::build_examples(core, &names, &set)
            .unwrap_or_else(|e| panic!("{} for {} ({}): {e:#}", names.join(", "), core.core, core.target));
        for elf in &elfs {
            let run = qemu::run(core, elf, false, Duration::from_secs(60)).unwrap_or_else(|e| panic!("{e:#}"));
            assert!(run.status.success(), "{} on {} exited with {}: {}{}", elf.display(), core.core, run.status, run.stdout, run.stderr);
        }
        println!("{} ({}): {} link and run", core.core, core.target, names.join(", "));
    }
}

#[test]
fn fixed_point_evaluator_has_no_floating_point_on_any_core() {
    let set = firmware::fitted_set(&firmware::compiled_set()).unwrap_or_else(|e| panic!("{e:#}"));
    for core in &CORES {
        let elfs = build::build_examples(core, &["no_panic", "no_panic_fixed", "no_panic_fixed_insertion"], &set)
            .unwrap_or_else(|e| panic!("{e:#}"));
        // The wrench and the stiffness's workers (their entry point only calls these).
        for function in [
            "needle_haptics::fixed::eval::wrench",
            "needle_haptics::fixed::eval_stiffness::wrench_and_depth_rates",
            "needle_haptics::fixed::eval_stiffness::along",
        ] {
            let fixed = float_check::analyse_elf(&elfs[1], function).unwrap_or_else(|e| panic!("{e:#}"));
            assert!(
                fixed.instructions > 100,
                "{}: {} is not the evaluator ({} instructions)",
                core.core,
                fixed.function,
                fixed.instructions
            );
            assert!(fixed.float_calls.is_empty(), "{}: {} calls soft-float helpers {:?}", core.core, fixed.function, fixed.float_calls);
            assert!(
                fixed.fpu_instructions.is_empty(),
                "{}: {} has FPU instructions: {:?}",
                core.core,
                fixed.function,
                &fixed.fpu_instructions[..fixed.fpu_instructions.len().min(5)]
            );
            println!(
                "{} ({}): {} ({} instructions) calls {:?}, no float",
                core.core, core.target, fixed.function, fixed.instructions, fixed.calls
            );
        }
        // Nothing in the whole fixed-point image is floating point, with the fixed-point
        // insertion (its stacks converted at compile time) as without it.
        for (elf, what) in [(&elfs[1], "fixed"), (&elfs[2], "fixed-insertion")] {
            let report = size::measure(core, elf, what).unwrap_or_else(|e| panic!("{e:#}"));
            let helpers: Vec<&str> = report.runtime.iter().map(|s| s.name.as_str()).filter(|n| float_check::is_float_helper(n)).collect();
            assert!(helpers.is_empty(), "{}: the {what} firmware links float helpers {helpers:?}", core.core);
        }
        let step =
            float_check::analyse_elf(&elfs[2], "needle_haptics::fixed::insertion::Insertion::step").unwrap_or_else(|e| panic!("{e:#}"));
        assert!(step.instructions > 100, "{}: {} is not the insertion step ({} instructions)", core.core, step.function, step.instructions);
        assert!(step.float_calls.is_empty() && step.fpu_instructions.is_empty(), "{}: {} uses floating point", core.core, step.function);
        println!(
            "{} ({}): {} ({} instructions) calls {:?}, no float",
            core.core, core.target, step.function, step.instructions, step.calls
        );
        // The same check on the f32 evaluator does see floating point (soft float on the
        // M0 and M3, FPU instructions on the M4F): it can fail.
        let f32_use = float_check::analyse_elf(&elfs[0], "needle_haptics::float::eval::wrench").unwrap_or_else(|e| panic!("{e:#}"));
        if core.name == "m4f" {
            assert!(!f32_use.fpu_instructions.is_empty(), "{}: no FPU instruction found in {}", core.core, f32_use.function);
        } else {
            assert!(
                f32_use.float_calls.iter().any(|c| c.starts_with("__aeabi_f")),
                "{}: no soft-float call found in {} (calls {:?})",
                core.core,
                f32_use.function,
                f32_use.calls
            );
        }
        println!(
            "{} ({}): f32 evaluator: {} float calls, {} FPU instructions",
            core.core,
            core.target,
            f32_use.float_calls.len(),
            f32_use.fpu_instructions.len()
        );
    }
}

/// Issue 41's flash budget for the whole insertion: the model, its depth extension, the
/// insertion model with its guard stiffness and every compiled-in stack, in the
/// `no_panic_insertion` image (library code + `.rodata` + compiler runtime, the same
/// accounting as `needle firmware size`), <= 24 KiB on every core, for the elastic build
/// and for the build with the `viscoelastic` feature (the filter: it must hold more than
/// the elastic one, or the filter is not in it).
#[test]
fn insertion_flash_within_24_kib_on_every_core() {
    insertion_flash_within_24_kib(["no_panic", "no_panic_insertion"], ["f32", "insertion", "insertion+qlv"]);
}

/// The same budget for the fixed-point insertion: the fixed-point model, its depth
/// extension, `fixed::insertion` and every stack in integers (`no_panic_fixed_insertion`).
#[test]
fn fixed_point_insertion_flash_within_24_kib_on_every_core() {
    insertion_flash_within_24_kib(["no_panic_fixed", "no_panic_fixed_insertion"], ["fixed", "fixed-insertion", "fixed-insertion+qlv"]);
}

fn insertion_flash_within_24_kib([model_example, insertion_example]: [&str; 2], [model_name, elastic_name, qlv_name]: [&'static str; 3]) {
    let set = firmware::fitted_set(&firmware::compiled_set()).unwrap_or_else(|e| panic!("{e:#}"));
    for core in &CORES {
        let elfs = build::build_examples_with(core, &[model_example, insertion_example], &set, Features::Elastic)
            .unwrap_or_else(|e| panic!("{e:#}"));
        let model = size::measure(core, &elfs[0], model_name).unwrap_or_else(|e| panic!("{e:#}"));
        let report = size::measure(core, &elfs[1], elastic_name).unwrap_or_else(|e| panic!("{e:#}"));
        let qlv_elf = build::build_examples(core, &[insertion_example], &set).unwrap_or_else(|e| panic!("{e:#}")).remove(0);
        let qlv = size::measure(core, &qlv_elf, qlv_name).unwrap_or_else(|e| panic!("{e:#}"));
        println!(
            "{} ({}): {elastic_name} model + insertion flash {} (model alone {}), static RAM {} B; with the viscoelastic filter {} (+{} B)",
            core.core,
            core.target,
            size::bytes(report.model_flash()),
            size::bytes(model.model_flash()),
            report.static_ram(),
            size::bytes(qlv.model_flash()),
            qlv.model_flash().saturating_sub(report.model_flash())
        );
        assert!(report.model_flash() > model.model_flash(), "{}: the insertion image holds more than the model", core.core);
        assert!(qlv.model_flash() > report.model_flash(), "{}: the viscoelastic build holds the filter", core.core);
        assert!(
            report.model_flash() <= 24 * 1024,
            "{}: {elastic_name} model + insertion flash {} B > 24 KiB",
            core.core,
            report.model_flash()
        );
        assert!(qlv.model_flash() <= 24 * 1024, "{}: {qlv_name} model + insertion flash {} B > 24 KiB", core.core, qlv.model_flash());
    }
}

/// Issue 64's cost goals with the `tissue-shape` feature (a layer's family member and its
/// pre-puncture softening, the shaped stacks compiled in): the insertion images link (no
/// panic path: their panic handlers call an undefined symbol) and run on every core, and
/// each holds the model, the insertion and every stack of its build within 24 KiB of flash,
/// f32 and fixed point, elastic and with the viscoelastic filter. The feature must cost
/// flash (or its code is not in the image) and the shaped stack must be in the build.
/// The images of the build with both `viscoelastic` and `tissue-shape` that miss issue
/// 64's 24 KiB, as measured (the issue stays open for them, the closing note has the
/// figures): none. With both features f32 M4F 16,364, M3 23,668 and M0 23,276 B, fixed
/// point M4F 24,094, M3 24,082 and M0 24,358 B (before: f32 M3 25,720 and M0 24,914 B,
/// fixed point M4F 25,820, M3 25,806 and M0 26,764 B; the member 8 B per layer slot
/// instead of 56, the softening 32 instead of 40, the soft-float stiffness's sweeps and
/// Horner out of line, the M0's own 64-bit division, the gains' products in one copy).
/// Not a tolerance: every image must fit; an image listed here is still printed.
const FLASH_MISSED_WITH_SHAPE: [(&str, &str); 0] = [];

#[test]
fn shaped_insertion_firmware_links_runs_and_fits_in_24_kib_on_every_core() {
    let set = firmware::fitted_set(&firmware::compiled_set()).unwrap_or_else(|e| panic!("{e:#}"));
    let shaped = |f: Features| needle_haptics::insertion::stacks::ALL.iter().filter(|s| f.compiles(s)).count();
    assert!(shaped(Features::Shape) > shaped(Features::Viscoelastic), "no stack of the set needs tissue-shape");
    let names = ["no_panic_insertion", "no_panic_fixed_insertion"];
    let mut missed = Vec::new();
    for core in &CORES {
        for (features, without) in [(Features::ShapeElastic, Features::Elastic), (Features::Shape, Features::Viscoelastic)] {
            let elfs = build::build_examples_with(core, &names, &set, features).unwrap_or_else(|e| panic!("{e:#}"));
            let base = build::build_examples_with(core, &names, &set, without).unwrap_or_else(|e| panic!("{e:#}"));
            for ((elf, base_elf), name) in elfs.iter().zip(&base).zip(names) {
                let run = qemu::run(core, elf, false, Duration::from_secs(120)).unwrap_or_else(|e| panic!("{e:#}"));
                assert!(run.status.success(), "{name} ({features:?}) on {}: exit {}: {}{}", core.core, run.status, run.stdout, run.stderr);
                let report = size::measure(core, elf, "insertion").unwrap_or_else(|e| panic!("{e:#}"));
                let before = size::measure(core, base_elf, "insertion").unwrap_or_else(|e| panic!("{e:#}"));
                println!(
                    "{} ({}): {name} {features:?}: model + insertion flash {} (without tissue-shape {}, +{} B), static RAM {} B",
                    core.core,
                    core.target,
                    size::bytes(report.model_flash()),
                    size::bytes(before.model_flash()),
                    report.model_flash().saturating_sub(before.model_flash()),
                    report.static_ram()
                );
                assert!(
                    report.model_flash() > before.model_flash(),
                    "{}: {name} {features:?} holds no more than without the feature",
                    core.core
                );
                let known = features == Features::Shape && FLASH_MISSED_WITH_SHAPE.contains(&(core.name, name));
                if report.model_flash() > 24 * 1024 && known {
                    println!("MISSED (issue 64, open): {}: {name} {features:?}: {} B > 24 KiB", core.core, report.model_flash());
                } else if report.model_flash() > 24 * 1024 {
                    missed.push(format!("{}: {name} {features:?}: {} B > 24 KiB", core.core, report.model_flash()));
                }
            }
        }
    }
    assert!(missed.is_empty(), "flash per image with tissue-shape:\n{}", missed.join("\n"));
}

/// Issue 64's goal for the material family's tables: the f32 law's constants and their
/// integer form together within 1 KiB.
#[test]
fn the_family_tables_fit_in_1_kib() {
    use needle_haptics::float::family::tables as t;
    let f32_bytes = std::mem::size_of_val(&t::COEFFS)
        + std::mem::size_of_val(&t::DEPTH_MAX_MM)
        + std::mem::size_of_val(&t::INV_DEPTH_MAX_PER_MM)
        + std::mem::size_of_val(&t::FITTED);
    let fixed_bytes = needle_haptics::fixed::family::TABLE_BYTES;
    println!("family tables: f32 {f32_bytes} B, fixed point {fixed_bytes} B, together {} B (goal <= 1,024 B)", f32_bytes + fixed_bytes);
    // at run time, not in a `const` block: a set without the law fails this test alone
    #[allow(clippy::assertions_on_constants)]
    {
        assert!(t::FITTED, "the set has no family law: nothing measured");
    }
    assert!(f32_bytes + fixed_bytes <= 1024, "the family's tables take {} B > 1 KiB", f32_bytes + fixed_bytes);
}
