//! The `golden` firmware on the three reference cores under QEMU, against the golden
//! vectors of the set compiled into the library (`NEEDLE_COEFFS`, default
//! coeffs/default): every status and wrench bit of every row must be the golden file's
//! (NaN by class, signed zeros by bits), and every integer of the fixed-point evaluator
//! the one in golden-fixed.csv, and every stiffness rate the one in
//! golden-stiffness-f32.csv and golden-stiffness-fixed.csv. Soft-float add and multiply are correctly
//! rounded, so the M3 and M0 must match as well as the M4F's FPU.
//!
//! Nothing skips: a missing QEMU, rustup target, model.toml or golden file fails with a
//! message that says what to install or run.
use needle_firmware_host::{self as firmware, golden, golden_fixed, golden_stiffness};
use needle_fit::{eval::float32::Tables32, fixed_formats::TablesFixed, model_file};
use std::path::Path;

mod made_up_model;

fn golden_on(name: &str) {
    let set = firmware::fitted_set(&firmware::compiled_set()).unwrap_or_else(|e| panic!("{e:#}"));
    golden_of_set_on(name, &set);
}

/// Every section of the `golden` firmware of the set at `set` on core `name`: at least
/// 2,000 rows each (the contract's minimum), none differing.
fn golden_of_set_on(name: &str, set: &Path) {
    let core = firmware::core(name).unwrap_or_else(|e| panic!("{e:#}"));
    let run = golden::run(&core, set).unwrap_or_else(|e| panic!("{} ({}): {e:#}", core.core, core.target));
    let sections = [
        ("golden-f32.csv", &run.comparison),
        ("golden-fixed.csv", &run.fixed),
        ("golden-stiffness-f32.csv", &run.stiffness),
        ("golden-stiffness-fixed.csv", &run.stiffness_fixed),
    ];
    for (file, c) in sections {
        assert!(c.rows >= 2000, "{}: only {} rows of {file} (the contract asks for >= 2,000)", set.display(), c.rows);
        assert!(
            c.mismatches.is_empty(),
            "{} of {} rows of {file} differ on {} ({}, QEMU {}); first ones:\n{}",
            c.mismatches.len(),
            c.rows,
            core.core,
            core.target,
            core.machine,
            c.mismatches.iter().take(10).cloned().collect::<Vec<_>>().join("\n")
        );
        println!("{} ({}): {} rows of {file} exactly", core.core, core.machine, c.rows);
    }
    println!("{} ({}): golden firmware ran {:.1} s ({})", core.core, core.machine, run.run_time.as_secs_f64(), run.comparison.banner);
}

#[test]
fn golden_bits_on_cortex_m4f_mps2_an386() {
    golden_on("m4f");
}

#[test]
fn golden_bits_on_cortex_m3_mps2_an385() {
    golden_on("m3");
}

#[test]
fn golden_bits_on_cortex_m0_microbit() {
    golden_on("m0");
}

/// The coupled form's generated code (cross terms and their rates, f32 and fixed point)
/// on the M4F with cross terms in every component (the shipped set has them in fy and my
/// only): a set folder with the default model's baseline and deviations plus made-up
/// cross terms of degree <= 3 (`made_up_model`) and golden files written by
/// the fitter's own implementations, compiled into the `golden` firmware. Not a fitted
/// model: it lives in a temporary folder, never under coeffs/.
#[test]
fn golden_bits_of_a_coupled_model_on_cortex_m4f_mps2_an386() {
    let dir = tempfile::tempdir().expect("temporary set folder");
    let set = dir.path().join("made-up-coupled");
    let text = made_up_model::coupled_default_text();
    let model = model_file::parse(&text, &set.join("model.toml")).unwrap_or_else(|e| panic!("{e:#}"));
    assert!(model.cross.as_ref().is_some_and(|c| c.terms.terms.iter().all(|t| !t.is_empty())), "cross terms in every component");
    write_made_up_set(&set, text);
    golden_of_set_on("m4f", &set);
}

/// The evaluators' exact Horner trimming (`src/horner.rs`, the cross terms' code from
/// `needle-codegen`) on a made-up coupled model with `+0.0` and `-0.0` coefficients
/// wherever a start at the wrong coefficient would change a bit
/// (`made_up_model::signed_zeros_text`), against golden files from the fitter's untrimmed
/// implementations: on the M4F (the unrolled evaluator, starts decided at compile time)
/// and the M0 (the soft-float loop).
#[test]
fn golden_bits_of_signed_zero_coefficients_on_cortex_m4f_and_m0() {
    let dir = tempfile::tempdir().expect("temporary set folder");
    let set = dir.path().join("made-up-signed-zeros");
    write_made_up_set(&set, made_up_model::signed_zeros_text());
    golden_of_set_on("m4f", &set);
    golden_of_set_on("m0", &set);
}

/// A set folder at `set` with the model file `text` and the four golden files written
/// by the fitter's own implementations.
fn write_made_up_set(set: &Path, text: String) {
    use needle_fit::golden::{fixed as gfixed, float32 as g32, stiffness_fixed as gsfixed, stiffness_float32 as gs32};
    std::fs::create_dir(set).expect("set folder");
    let model = model_file::parse(&text, &set.join("model.toml")).unwrap_or_else(|e| panic!("{e:#}"));
    let t32 = Tables32::from_model(&model);
    let tfixed = TablesFixed::from_model(&model).unwrap_or_else(|e| panic!("{e:#}"));
    let files = [
        ("golden-f32.csv", g32::to_csv(&t32)),
        ("golden-stiffness-f32.csv", gs32::to_csv(&t32)),
        ("golden-fixed.csv", gfixed::to_csv(&tfixed).unwrap_or_else(|e| panic!("{e:#}"))),
        ("golden-stiffness-fixed.csv", gsfixed::to_csv(&tfixed).unwrap_or_else(|e| panic!("{e:#}"))),
        ("model.toml", text),
    ];
    for (name, body) in files {
        std::fs::write(set.join(name), body).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
}

/// The comparison itself, on hand-made output: one flipped bit, a sign of zero, a
/// status, and NaN payloads.
#[test]
fn comparison_catches_one_bit_and_allows_nan_payloads() {
    let h = golden::header();
    let csv = format!(
        "{h}\n\
         0x00000000,0x00000000,0x00000000,0x00000000,0x40000000,0x00,0x3f800000,0x80000000,0x7fc00000,0x00000000,0x00000000,0x00000000\n"
    );
    let out = |row: &str| format!("needle-golden target=t set=s fe_sha256=ab rows=1\n{h}\n{row}\nneedle-golden end rows=1\n");
    let ok =
        "0x00000000,0x00000000,0x00000000,0x00000000,0x40000000,0x00,0x3f800000,0x80000000,0x7fc00001,0x00000000,0x00000000,0x00000000";
    let c = golden::compare(&out(ok), &csv, "ab").expect("well-formed");
    assert!(c.mismatches.is_empty(), "{:?}", c.mismatches);
    for bad in [
        "0x00000000,0x00000000,0x00000000,0x00000000,0x40000000,0x00,0x3f800001,0x80000000,0x7fc00000,0x00000000,0x00000000,0x00000000",
        "0x00000000,0x00000000,0x00000000,0x00000000,0x40000000,0x00,0x3f800000,0x00000000,0x7fc00000,0x00000000,0x00000000,0x00000000",
        "0x00000000,0x00000000,0x00000000,0x00000000,0x40000000,0x01,0x3f800000,0x80000000,0x7fc00000,0x00000000,0x00000000,0x00000000",
        "0x00000000,0x00000000,0x00000000,0x00000000,0x40000000,0x00,0x3f800000,0x80000000,0x3fc00000,0x00000000,0x00000000,0x00000000",
    ] {
        let c = golden::compare(&out(bad), &csv, "ab").expect("well-formed");
        assert_eq!(c.mismatches.len(), 1, "{bad}");
    }
    assert!(golden::compare(&out(ok), &csv, "cd").is_err(), "another set's firmware must be refused");
    assert!(golden::compare(&out(ok).replace("needle-golden end rows=1\n", ""), &csv, "ab").is_err(), "truncated output");
}

/// The fixed-point comparison on hand-made output: one flipped bit of one integer, a
/// status, a missing section and a truncated one are all caught.
#[test]
fn fixed_comparison_catches_one_bit() {
    let h = golden_fixed::header();
    let row = "0,0,0,0,196608,0x00,0,80000,-3,17,0,-5";
    let csv = format!("{h}\n{row}\n");
    let out = |r: &str| format!("needle-golden end rows=9\nneedle-golden-fixed rows=1\n{r}\nneedle-golden-fixed end rows=1\n");
    let c = golden_fixed::compare(&out(row), &csv).expect("well-formed");
    assert!(c.mismatches.is_empty(), "{:?}", c.mismatches);
    for bad in [
        "0,0,0,0,196608,0x00,0,80001,-3,17,0,-5", // Fy one bit off
        "0,0,0,0,196608,0x00,0,80000,-3,17,0,-4", // Mz: -5 ^ 1
        "0,0,0,0,196608,0x10,0,80000,-3,17,0,-5", // status
    ] {
        let c = golden_fixed::compare(&out(bad), &csv).expect("well-formed");
        assert_eq!(c.mismatches.len(), 1, "{bad}");
    }
    assert!(golden_fixed::compare("needle-golden end rows=9\n", &csv).is_err(), "no fixed section");
    assert!(golden_fixed::compare(&out(row).replace("needle-golden-fixed end rows=1\n", ""), &csv).is_err(), "truncated");
}

/// The stiffness comparison on hand-made output: one flipped bit of one rate, a status,
/// a wrench the firmware found different from `wrench`'s, a missing and a truncated
/// section are all caught.
#[test]
fn stiffness_comparison_catches_one_bit_and_a_differing_wrench() {
    let h = needle_fit::golden::stiffness_float32::header();
    let inputs = "0x00000000,0x00000000,0x00000000,0x00000000,0x40400000";
    let rates: Vec<String> = (0..18).map(|i| format!("0x3c{i:06x}")).collect();
    let row = format!("{inputs},0x00,{}", rates.join(","));
    let csv = format!("{h}\n{row}\n");
    let out = |r: &str, differs: u32| {
        format!("needle-golden-fixed end rows=1\nneedle-golden-stiffness rows=1\n{r}\nneedle-golden-stiffness end rows=1 wrench_differs={differs}\n")
    };
    let c = golden_stiffness::compare(&out(&row, 0), &csv).expect("well-formed");
    assert!(c.mismatches.is_empty(), "{:?}", c.mismatches);
    let mut flipped = rates.clone();
    flipped[7] = "0x3c000006".to_string(); // dfy_dx one bit off (0x3c000007 ^ 1)
    for bad in [format!("{inputs},0x00,{}", flipped.join(",")), format!("{inputs},0x10,{}", rates.join(","))] {
        let c = golden_stiffness::compare(&out(&bad, 0), &csv).expect("well-formed");
        assert_eq!(c.mismatches.len(), 1, "{bad}");
    }
    assert!(golden_stiffness::compare(&out(&row, 1), &csv).is_err(), "a wrench differing from wrench()'s");
    assert!(golden_stiffness::compare("needle-golden-fixed end rows=1\n", &csv).is_err(), "no stiffness section");
    assert!(
        golden_stiffness::compare(&out(&row, 0).replace("needle-golden-stiffness end rows=1 wrench_differs=0\n", ""), &csv).is_err(),
        "truncated"
    );
}

/// The fixed-point stiffness section's comparison: one integer off, another status, a
/// wrench the firmware found differing, a missing or truncated section are all caught.
#[test]
fn fixed_stiffness_comparison_catches_one_unit_and_a_differing_wrench() {
    let h = needle_fit::golden::stiffness_fixed::header();
    let inputs = "0,0,0,0,196608";
    let rates: Vec<String> = (0..18).map(|i| format!("{}", 1000 * i - 7000)).collect();
    let row = format!("{inputs},0x00,{}", rates.join(","));
    let csv = format!("{h}\n{row}\n");
    let tag = "needle-golden-stiffness-fixed";
    let out = |r: &str, differs: u32| {
        format!("needle-golden-stiffness end rows=1 wrench_differs=0\n{tag} rows=1\n{r}\n{tag} end rows=1 wrench_differs={differs}\n")
    };
    let c = golden_fixed::compare_stiffness(&out(&row, 0), &csv).expect("well-formed");
    assert!(c.mismatches.is_empty(), "{:?}", c.mismatches);
    let mut off = rates.clone();
    off[7] = "1".to_string(); // dfy_dx: 0 in the file
    for bad in [format!("{inputs},0x00,{}", off.join(",")), format!("{inputs},0x10,{}", rates.join(","))] {
        let c = golden_fixed::compare_stiffness(&out(&bad, 0), &csv).expect("well-formed");
        assert_eq!(c.mismatches.len(), 1, "{bad}");
    }
    assert!(golden_fixed::compare_stiffness(&out(&row, 1), &csv).is_err(), "a wrench differing from fixed::wrench()'s");
    assert!(golden_fixed::compare_stiffness("needle-golden-stiffness end rows=1\n", &csv).is_err(), "no section");
    let truncated = out(&row, 0).replace(&format!("{tag} end rows=1 wrench_differs=0\n"), "");
    assert!(golden_fixed::compare_stiffness(&truncated, &csv).is_err(), "truncated");
}
