//! Bad tissue files are refused with their file and line, by the one reader that
//! `build.rs` and `needle calibrate` share (`needle_codegen::tissue`), and a good one
//! (every shipped stack) is read.
use needle_codegen::tissue::{parse_stack, parse_stack_str, read_stacks};
use std::path::Path;

const GOOD: &str = r#"format = 1
name = "two"
description = "two layers"
needle_diameter_mm = 1.27

[[layer]]
name = "capsule"
thickness_mm = 10.0
stiffness_scale = 2.0
puncture_force_n = 1.4
cutting_force_n = 0.1
friction_static_n_per_mm = 0.01
friction_coulomb_n_per_mm = 0.01
friction_viscous_n_s_per_mm2 = 0.0
stick_band_mm_per_s = 1.0
track_stiffness_n_per_mm2 = 0.0
source = "test"

[[layer]]
name = "parenchyma"
thickness_mm = 20.0
stiffness_scale = 1.0
puncture_force_n = 1.0
cutting_force_n = 0.2
friction_static_n_per_mm = 0.02
friction_coulomb_n_per_mm = 0.02
friction_viscous_n_s_per_mm2 = 0.0
stick_band_mm_per_s = 1.0
track_stiffness_n_per_mm2 = 0.0
source = "test"
"#;

/// The line (1-based) of the `n`-th occurrence of `key =` in GOOD.
fn line_of(key: &str, n: usize) -> usize {
    GOOD.lines().enumerate().filter(|(_, l)| l.starts_with(&format!("{key} ="))).nth(n).map(|(i, _)| i + 1).expect("key in GOOD")
}

/// GOOD with the `n`-th `key = ...` line replaced by `key = value`.
fn with(key: &str, n: usize, value: &str) -> String {
    let target = line_of(key, n);
    GOOD.lines()
        .enumerate()
        .map(|(i, l)| if i + 1 == target { format!("{key} = {value}") } else { l.to_string() })
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn a_good_file_is_read() {
    let s = parse_stack_str(GOOD, Path::new("two.toml")).expect("good file");
    assert_eq!(s.layers.len(), 2);
    assert_eq!(s.layers[1].name, "parenchyma");
}

#[test]
fn out_of_range_values_are_refused_at_their_line() {
    let cases = [
        ("thickness_mm", 1, "-1.0"),
        ("thickness_mm", 0, "0.0"),
        ("stiffness_scale", 0, "0.0"),
        ("stiffness_scale", 1, "-2.0"),
        ("puncture_force_n", 0, "0.0"),
        ("cutting_force_n", 1, "-0.1"),
        ("friction_static_n_per_mm", 0, "-0.01"),
        ("friction_coulomb_n_per_mm", 1, "-0.01"),
        ("friction_viscous_n_s_per_mm2", 0, "-1e-3"),
        ("stick_band_mm_per_s", 1, "0.0"),
        ("track_stiffness_n_per_mm2", 0, "-1.0"),
        ("needle_diameter_mm", 0, "0.0"),
        ("thickness_mm", 0, "nan"),
        ("puncture_force_n", 1, "inf"),
        ("stiffness_scale", 0, "1e39"),
    ];
    for (key, n, value) in cases {
        let text = with(key, n, value);
        let e = parse_stack_str(&text, Path::new("bad.toml")).expect_err(&format!("{key} = {value} must be refused"));
        assert_eq!(e.line, Some(line_of(key, n)), "{key} = {value}: {e}");
        assert!(e.message.starts_with(&format!("{key} = ")), "{key} = {value}: the message names the field: {e}");
        assert!(e.to_string().starts_with("bad.toml:"), "{e}");
    }
}

#[test]
fn a_missing_field_an_unknown_field_and_a_bad_name_are_refused() {
    let target = line_of("cutting_force_n", 1);
    let missing: String = GOOD.lines().enumerate().filter(|(i, _)| i + 1 != target).map(|(_, l)| format!("{l}\n")).collect();
    let e = parse_stack_str(&missing, Path::new("bad.toml")).expect_err("missing field");
    assert!(e.message.contains("cutting_force_n"), "{e}");
    assert!(e.line.is_some(), "{e}");

    let unknown = GOOD.replacen("source = \"test\"", "source = \"test\"\nfriction = 0.5", 1);
    let e = parse_stack_str(&unknown, Path::new("bad.toml")).expect_err("unknown field");
    assert!(e.message.contains("friction"), "{e}");

    let e = parse_stack_str(&with("name", 0, "\"Two Layers\""), Path::new("bad.toml")).expect_err("bad name");
    assert_eq!(e.line, Some(2), "{e}");

    let e = parse_stack_str(&with("format", 0, "3"), Path::new("bad.toml")).expect_err("format");
    assert_eq!(e.line, Some(1), "{e}");
}

/// GOOD as format 2 with `lines` added after the second layer's `source`.
fn format2(lines: &str) -> String {
    format!("{}\n{lines}\n", with("format", 0, "2"))
}

/// Format 2's keys (issue 64): read with their values, refused in a format 1 file, and
/// each out of its range refused at its line; a weight below the members the set's FE
/// covers is refused with that range.
#[test]
fn format_2_keys_are_read_checked_and_refused_in_format_1() {
    let good = format2("family_weight = 0.05\nfamily_weight_range = [0.01, 0.1]\nsoftening_fraction = 0.15\nsoftening_onset_ratio = 0.6");
    let s = parse_stack_str(&good, Path::new("two.toml")).unwrap_or_else(|e| panic!("{e}"));
    let l = &s.layers[1];
    assert_eq!(
        (l.family_weight, l.family_weight_range, l.softening_fraction, l.softening_onset_ratio),
        (0.05, Some([0.01, 0.1]), 0.15, 0.6)
    );
    assert_eq!((s.layers[0].family_weight, s.layers[0].softening_fraction), (1.0, 0.0), "the defaults: the paper's tissue, no softening");
    let again = parse_stack_str(&s.to_toml("round trip"), Path::new("two.toml")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(again, s, "format 2 round-trips");

    let in_format_1 = format!("{GOOD}family_weight = 0.05\n");
    let e = parse_stack_str(&in_format_1, Path::new("bad.toml")).expect_err("a format 2 key in format 1");
    assert!(e.to_string().contains("format = 2"), "{e}");
    for (line, what) in [
        ("family_weight = 1.5", "family_weight = 1.5"),
        ("softening_fraction = 0.5", "softening_fraction = 0.5"),
        ("softening_fraction = -0.1", "softening_fraction = -0.1"),
        ("softening_onset_ratio = 1.0", "softening_onset_ratio = 1"),
        ("family_weight = 0.2\nfamily_weight_range = [0.3, 0.5]", "family_weight_range = [0.3, 0.5]"),
    ] {
        let text = format2(line);
        let e = parse_stack_str(&text, Path::new("bad.toml")).expect_err(line);
        assert!(e.to_string().contains(what), "{line}: {e}");
        assert!(e.line.is_some_and(|n| n > GOOD.lines().count()), "{line}: the key's own line, after GOOD's: {e}");
    }
    let domain = needle_codegen::tissue::FamilyDomain { weight_min: 0.01 };
    let text = format2("family_weight = 0.005");
    let e = needle_codegen::tissue::parse_stack_str_in(&text, Path::new("bad.toml"), &domain).expect_err("below the FE's members");
    assert!(e.to_string().contains("0.01 to 1") && e.to_string().contains("not extrapolated"), "{e}");
    assert_eq!(e.line, Some(text.lines().count()), "{e}");
    needle_codegen::tissue::parse_stack_str_in(&format2("family_weight = 0.01"), Path::new("two.toml"), &domain)
        .unwrap_or_else(|e| panic!("the softest covered member: {e}"));
}

#[test]
fn every_shipped_stack_is_read_and_named_after_its_file() {
    let set = Path::new(env!("CARGO_MANIFEST_DIR")).join("../coeffs/default");
    let stacks = read_stacks(&set).expect("shipped stacks");
    assert!(!stacks.is_empty(), "coeffs/default/tissue/ holds the shipped stacks");
    for (path, stack) in &stacks {
        assert_eq!(parse_stack(path).expect("readable"), *stack);
    }
}

/// GOOD with `lines` added after the second layer's `source` (its last line).
fn with_prony(lines: &str) -> String {
    format!("{GOOD}{lines}\n")
}

/// The 1-based line of the first line of `text` that starts with `start`.
fn line_in(text: &str, start: &str) -> usize {
    text.lines().position(|l| l.starts_with(start)).map(|i| i + 1).expect("line in text")
}

#[test]
fn prony_terms_are_read_in_the_long_term_normalisation() {
    let text =
        with_prony("prony = [{ g = 0.8, tau_s = 0.05 }, { g = 0.5, tau_s = 1.0 }, { g = 0.3, tau_s = 20.0 }]\nprony_source = \"test\"");
    let s = parse_stack_str(&text, Path::new("two.toml")).expect("good prony terms");
    let p: Vec<(f64, f64)> = s.layers[1].prony.iter().map(|t| (t.g, t.tau_s)).collect();
    assert_eq!(p, [(0.8, 0.05), (0.5, 1.0), (0.3, 20.0)]);
    assert!(s.layers[0].prony.is_empty(), "a layer without terms is elastic");
    // written back (needle calibrate's to_toml) and read again: the same stack
    let again = parse_stack_str(&s.to_toml("round trip"), Path::new("two.toml")).expect("round trip");
    assert_eq!(again, s);
    // the sum at its bound (9) is allowed
    let text = with_prony("prony = [{ g = 5.0, tau_s = 1.0 }, { g = 4.0, tau_s = 2.0 }]\nprony_source = \"test\"");
    parse_stack_str(&text, Path::new("two.toml")).expect("sum 9");
}

#[test]
fn bad_prony_terms_are_refused_at_their_line() {
    let cases = [
        ("prony = [{ g = -0.1, tau_s = 1.0 }]", "prony g = -0.1: must be finite and >= 0"),
        ("prony = [{ g = 0.5, tau_s = 0.0 }]", "prony tau_s = 0: must be finite and > 0"),
        ("prony = [{ g = 0.5, tau_s = -2.0 }]", "prony tau_s = -2: must be finite and > 0"),
        ("prony = [{ g = nan, tau_s = 1.0 }]", "prony g = NaN: must be finite and >= 0"),
        ("prony = [{ g = 0.5, tau_s = inf }]", "prony tau_s = inf: must be finite and > 0"),
        ("prony = [{ g = 5.0, tau_s = 1.0 }, { g = 4.5, tau_s = 2.0 }]", "prony: sum of g = 9.5: must be <= 9"),
        (
            "prony = [{ g = 0.1, tau_s = 1.0 }, { g = 0.1, tau_s = 2.0 }, { g = 0.1, tau_s = 3.0 }, { g = 0.1, tau_s = 4.0 }]",
            "4 prony terms: a layer has at most 3",
        ),
    ];
    for (line, message) in cases {
        let text = with_prony(&format!("{line}\nprony_source = \"test\""));
        let e = parse_stack_str(&text, Path::new("bad.toml")).expect_err(&format!("{line} must be refused"));
        assert_eq!(e.line, Some(line_in(&text, "prony =")), "{line}: {e}");
        assert!(e.message.starts_with(message), "{line}: {e}");
        assert!(e.to_string().starts_with("bad.toml:"), "{e}");
    }
    // terms without their citation
    let text = with_prony("prony = [{ g = 0.5, tau_s = 1.0 }]");
    let e = parse_stack_str(&text, Path::new("bad.toml")).expect_err("terms need a source");
    assert_eq!(e.line, Some(line_in(&text, "prony =")), "{e}");
    assert!(e.message.contains("prony_source"), "{e}");
    // an unknown key in a term
    let text = with_prony("prony = [{ g = 0.5, tau = 1.0 }]\nprony_source = \"test\"");
    let e = parse_stack_str(&text, Path::new("bad.toml")).expect_err("unknown key");
    assert!(e.message.contains("tau"), "{e}");
}

/// The build's entry point (`build.rs` calls `needle_codegen::generate_tissue`) refuses a
/// set whose tissue file has bad Prony terms, naming the file and the line.
#[test]
fn the_build_refuses_bad_prony_terms_with_file_and_line() {
    let dir = std::env::temp_dir().join(format!("needle-prony-build-{}", std::process::id()));
    let tissue = dir.join("tissue");
    std::fs::create_dir_all(&tissue).expect("temp set");
    let text = with_prony("prony = [{ g = 0.5, tau_s = 1.0 }, { g = -0.2, tau_s = 5.0 }]\nprony_source = \"test\"");
    let path = tissue.join("two.toml");
    std::fs::write(&path, &text).expect("write");
    let out = dir.join("out");
    std::fs::create_dir_all(&out).expect("out dir");
    let e = needle_codegen::generate_tissue(&dir, &out).expect_err("bad prony terms");
    let shown = e.to_string();
    assert!(shown.starts_with(&format!("{}:{}:", path.display(), line_in(&text, "prony ="))), "{shown}");
    assert!(shown.contains("prony g = -0.2"), "{shown}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The presliding keys (issue 65): read with their values and round-tripped, none by
/// default (the Karnopp friction), refused in a format 1 file, out of their range, and
/// the shaft's terms, the relaxation's slip distance or the tissue's tent without a
/// presliding distance, each at its line.
#[test]
fn presliding_keys_are_read_checked_and_refused_at_their_line() {
    let good =
        format2("presliding_mm = 1.5\nrelaxation_slip_mm = 0.2\ntent_n_per_mm = 0.16\n\n[[layer.shaft_prony]]\ng = 0.6\ntau_s = 1.9");
    let s = parse_stack_str(&good, Path::new("two.toml")).unwrap_or_else(|e| panic!("{e}"));
    let l = &s.layers[1];
    assert_eq!((l.presliding_mm, l.relaxation_slip_mm, l.shaft_prony.len()), (Some(1.5), Some(0.2), 1));
    assert_eq!((l.tent_n_per_mm, s.layers[0].tent_n_per_mm), (Some(0.16), None), "the tent, none by default");
    assert_eq!((l.shaft_prony[0].g, l.shaft_prony[0].tau_s), (0.6, 1.9));
    assert_eq!((s.layers[0].presliding_mm, s.layers[0].shaft_prony.len()), (None, 0), "the default: none");
    let again = parse_stack_str(&s.to_toml("round trip"), Path::new("two.toml")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(again, s, "the presliding keys round-trip");

    let e = parse_stack_str(&format!("{GOOD}presliding_mm = 1.5\n"), Path::new("bad.toml")).expect_err("format 1");
    assert!(e.to_string().contains("format = 2"), "{e}");
    for (lines, what) in [
        ("presliding_mm = 0.0", "presliding_mm = 0"),
        ("presliding_mm = 51.0", "presliding_mm = 51"),
        ("presliding_mm = 1.0\nrelaxation_slip_mm = 0.00005", "relaxation_slip_mm = 0.00005: must be from 0.0001 to 50 mm"),
        ("presliding_mm = 1.0\nrelaxation_slip_mm = 51.0", "relaxation_slip_mm = 51"),
        ("relaxation_slip_mm = 0.2", "relaxation_slip_mm needs presliding_mm"),
        ("presliding_mm = 1.0\ntent_n_per_mm = 0.0", "tent_n_per_mm = 0: must be from 0.001 to 100 N/mm"),
        ("presliding_mm = 1.0\ntent_n_per_mm = 101.0", "tent_n_per_mm = 101"),
        ("tent_n_per_mm = 0.2", "tent_n_per_mm needs presliding_mm"),
        ("\n[[layer.shaft_prony]]\ng = 0.5\ntau_s = 1.0", "shaft_prony needs presliding_mm"),
        ("presliding_mm = 1.0\n\n[[layer.shaft_prony]]\ng = -0.5\ntau_s = 1.0", "prony g = -0.5"),
    ] {
        let text = format2(lines);
        let e = parse_stack_str(&text, Path::new("bad.toml")).expect_err(lines);
        assert!(e.to_string().contains(what), "{lines}: {e}");
        assert!(e.line.is_some_and(|n| n > GOOD.lines().count()), "{lines}: the key's own line, after GOOD's: {e}");
    }
}
