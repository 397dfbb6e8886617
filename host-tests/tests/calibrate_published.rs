//! `needle calibrate-published` on the shipped published model (Davidor et al. 2023,
//! coeffs/default/measured/davidor2023-epidural/): the shipped `epidural` stack and the
//! sampled curve are what the derivation writes, the derived values follow the stated
//! rules, and bad tables are refused with `file:line`.
use needle_calibrate::from_model::{calibrate_published, ModelOptions};
use needle_calibrate::published::{read_pieces, sample, NO_RESISTANCE_N};
use std::path::{Path, PathBuf};

fn folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../coeffs/default/measured/davidor2023-epidural")
}

/// The options of the documented command (coeffs/default/measured/davidor2023-epidural/README.md).
fn options<'a>(pieces: &'a Path, sources: &'a Path) -> ModelOptions<'a> {
    let set = Path::new(env!("CARGO_MANIFEST_DIR")).join("../coeffs/default");
    let shipped = needle_codegen::tissue::parse_stack(&set.join("tissue/epidural.toml")).unwrap_or_else(|e| panic!("{e}"));
    ModelOptions {
        pieces,
        layer_sources: sources,
        name: "epidural".into(),
        description: shipped.description,
        needle_diameter_mm: shipped.needle_diameter_mm,
        replay_speed_mm_per_s: 3.0,
        with_prony: false,
        fe_shear_modulus_n_per_mm2: needle_codegen::tissue::read_fe_shear_modulus(&set).expect("campaign.toml").expect("a campaign"),
    }
}

#[test]
fn the_shipped_epidural_stack_is_the_derivation_of_the_published_model() {
    let (pieces, sources) = (folder().join("pieces.csv"), folder().join("layers.csv"));
    // the documented command writes the layers' published terms (`--with-prony`)
    let c = calibrate_published(&ModelOptions { with_prony: true, ..options(&pieces, &sources) }).unwrap_or_else(|e| panic!("{e:#}"));
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("../coeffs/default/tissue/epidural.toml");
    let file = needle_codegen::tissue::parse_stack(&shipped).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        file.layers, c.stack.layers,
        "coeffs/default/tissue/epidural.toml is stale: rerun needle calibrate-published (docs/insertion.md)"
    );
    for check in &c.checks {
        println!(
            "{:<58} published {:>9.4} model {:>9.4} error {:>+8.3} {}",
            check.what, check.measured, check.model, check.error, check.unit
        );
    }
    // the sampled curve in the folder is the command's, point for point
    let text = std::fs::read_to_string(folder().join("sampled_position_force.csv")).expect("sampled curve");
    let rows: Vec<(f64, f64)> = text
        .lines()
        .skip(1)
        .map(|l| l.split_once(',').and_then(|(p, f)| Some((p.parse().ok()?, f.parse().ok()?))).expect("a number pair"))
        .collect();
    let want: Vec<(f64, f64)> = c.points.iter().map(|p| (p.position_mm, p.force_n)).collect();
    assert_eq!(rows, want, "sampled_position_force.csv is stale: rerun needle calibrate-published");
}

#[test]
fn the_derived_values_follow_the_published_table() {
    let (pieces, sources) = (folder().join("pieces.csv"), folder().join("layers.csv"));
    let c = calibrate_published(&options(&pieces, &sources)).unwrap_or_else(|e| panic!("{e:#}"));
    let names: Vec<&str> = c.stack.layers.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(names, ["skin", "fat", "muscle", "interspinous ligament", "ligamentum flavum", "epidural space"]);
    // Protocol_Layer_Thickness_Test.txt row 1 (71.1 kg): 13.92 3.23 2.22 0.63 3.18 18 3.61 3.59 8.6 mm
    let want_mm = [13.92, 3.23, 2.22 + 0.63, 3.18 + 18.0, 3.61 + 3.59, 8.6];
    for (l, w) in c.stack.layers.iter().zip(want_mm) {
        assert!((l.thickness_mm - w).abs() < 1e-12, "{}: {} mm, published {w} mm", l.name, l.thickness_mm);
    }
    let published = read_pieces(&pieces).expect("pieces");
    let force = |piece: usize, x: f64| published[piece].force_n(x);
    let layer = |name: &str| c.stack.layers.iter().find(|l| l.name == name).expect("layer");
    // punctures at the published peaks: the skin's continues into the fat's piece
    // (maximum of 6.0372 + 0.4516 x - 0.5287 x^2 at x = 0.4516 / (2 * 0.5287) mm), the
    // others at the ends of the rising pieces
    let fat_peak = force(1, (0.4516f64 / (2.0 * 0.5287) / 0.01).round() * 0.01);
    assert!((layer("skin").puncture_force_n - fat_peak).abs() < 1e-12);
    assert!((layer("interspinous ligament").puncture_force_n - force(5, 0.0)).abs() < 1e-12, "the plateau's first point");
    assert!((layer("ligamentum flavum").puncture_force_n - force(7, 0.0)).abs() < 1e-12, "LF after starts at the LF's peak");
    // the advancing force: the plateau is all cutting, falling pieces their mean, no friction
    assert!((layer("interspinous ligament").cutting_force_n - 7.467).abs() < 1e-9);
    for l in &c.stack.layers {
        assert_eq!(l.friction_coulomb_n_per_mm, 0.0, "{}: no published advancing force grows with the inserted length", l.name);
    }
    // rule 5: the fat (past the skin's peak it only falls), the muscle (its peak, where
    // MS after starts, lies below the fat's cutting force carried onto its boundary) and
    // the epidural space (0 N)
    assert!(force(3, 0.0) < layer("fat").cutting_force_n, "MS after starts at the muscle's peak");
    for (name, above) in [("fat", "skin"), ("muscle", "fat"), ("epidural space", "ligamentum flavum")] {
        assert_eq!(layer(name).puncture_force_n, NO_RESISTANCE_N, "{name}");
        assert_eq!(layer(name).stiffness_scale, layer(above).stiffness_scale, "{name}");
    }
    assert_eq!(layer("epidural space").cutting_force_n, 0.0);
    // the sampled curve keeps the published jumps: two points at 48.38 mm, 10.0 N then 0 N
    let points = sample(&published);
    let at: Vec<f64> = points.iter().filter(|p| (p.position_mm - 48.38).abs() < 1e-9).map(|p| p.force_n).collect();
    assert_eq!(at.len(), 2);
    assert!((at[0] - force(7, 3.59)).abs() < 1e-12 && at[1] == 0.0, "{at:?}");
}

/// `--with-prony`: the skin's published relaxation function (one QLV term, Wang et al.
/// 2015: tau1 0.19 s, G_inf 0.28) goes into the stack in the long-term normalisation, the
/// skin's scale is fitted to the published rise at the replay speed through it, and the
/// replay at that speed punctures the skin where the published curve does, as the
/// elastic derivation does; without the flag the derived stack is elastic and names the
/// terms in `prony_source`.
#[test]
fn the_published_skin_terms_go_in_with_prony_and_keep_the_puncture_at_the_replay_speed() {
    let (pieces, sources) = (folder().join("pieces.csv"), folder().join("layers.csv"));
    let elastic = calibrate_published(&options(&pieces, &sources)).unwrap_or_else(|e| panic!("{e:#}"));
    let visco = calibrate_published(&ModelOptions { with_prony: true, ..options(&pieces, &sources) }).unwrap_or_else(|e| panic!("{e:#}"));
    let skin = |c: &needle_calibrate::Calibration| c.stack.layers.first().cloned().expect("a skin");
    let (e, v) = (skin(&elastic), skin(&visco));
    assert!(e.prony.is_empty() && e.prony_source.as_deref().is_some_and(|s| s.starts_with(needle_calibrate::from_model::NOT_COMPILED_IN)));
    // the published G_inf = 0.28: g = (1 - 0.28) / 0.28 of the long-term response
    assert_eq!(v.prony.len(), 1);
    assert!((v.prony[0].g - 0.72 / 0.28).abs() < 1e-12 && v.prony[0].tau_s == 0.19, "{:?}", v.prony);
    assert!(
        v.stiffness_scale < e.stiffness_scale,
        "the long-term scale lies below the elastic one: {} vs {}",
        v.stiffness_scale,
        e.stiffness_scale
    );
    let position_error = |c: &needle_calibrate::Calibration| {
        c.checks.iter().find(|k| k.what == "puncture 1 position").map(|k| k.error.abs()).expect("the first puncture's check")
    };
    assert!(
        position_error(&visco) <= 0.5,
        "with the skin's terms the replay punctures {} mm off the published curve",
        position_error(&visco)
    );
    assert!(position_error(&elastic) <= 0.5);
    // only the skin has terms
    assert!(visco.stack.layers.iter().skip(1).all(|l| l.prony.is_empty()));
}

fn refused(pieces: &Path, sources: &Path) -> String {
    match calibrate_published(&options(pieces, sources)) {
        Ok(_) => panic!("accepted"),
        Err(e) => format!("{e:#}"),
    }
}

#[test]
fn bad_tables_are_refused_with_file_and_line() {
    let dir = tempfile::tempdir().expect("temp dir");
    let good = std::fs::read_to_string(folder().join("pieces.csv")).expect("pieces");
    let sources = folder().join("layers.csv");
    let write = |name: &str, text: &str| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).expect("write");
        p
    };
    let bad_number = write("number.csv", &good.replacen("0.0116", "0.01x6", 1));
    let e = refused(&bad_number, &sources);
    assert!(e.contains("number.csv:2: column c1_n_per_mm") && e.contains("not a number"), "{e}");
    let negative = write("negative.csv", &good.replacen(",3.23,", ",-3.23,", 1));
    let e = refused(&negative, &sources);
    assert!(e.contains("negative.csv:3: column thickness_mm") && e.contains("> 0"), "{e}");
    let no_column = write("column.csv", &good.replacen("c3_n_per_mm3", "c3", 1));
    assert!(refused(&no_column, &sources).contains("column.csv:1: no column \"c3_n_per_mm3\""));
    let split = good.lines().enumerate().map(|(i, l)| if i == 3 { l.replacen("MS before,muscle", "MS before,skin", 1) } else { l.into() });
    let split = write("split.csv", &(split.collect::<Vec<String>>().join("\n") + "\n"));
    assert!(refused(&split, &sources).contains("split.csv:4: layer \"skin\": its pieces must be consecutive"));
    let uncited =
        std::fs::read_to_string(&sources).expect("sources").lines().filter(|l| !l.starts_with("fat,")).collect::<Vec<_>>().join("\n");
    let uncited = write("uncited.csv", &uncited);
    assert!(refused(&folder().join("pieces.csv"), &uncited).contains("no row for layer \"fat\""));
    // the skin's published relaxation function (row 2: `0.72,0.19,...`), spoilt
    let table = std::fs::read_to_string(&sources).expect("sources");
    assert!(table.contains(",0.72,0.19,"), "the skin's row carries its terms");
    for (name, with, want) in [
        ("weight.csv", ",0.7x,0.19,", "weight.csv:2: column prony_g_instantaneous: \"0.7x\" is not a number"),
        (
            "sum.csv",
            ",0.72;0.3,0.19;5,",
            "sum.csv:2: column prony_g_instantaneous: \"0.72;0.3\": each weight must be finite and >= 0, their sum below 1",
        ),
        ("tau.csv", ",0.72,0,", "tau.csv:2: column prony_tau_s: 0 s: must be finite and > 0"),
        ("count.csv", ",0.72,0.19;5,", "count.csv:2: columns prony_g_instantaneous and prony_tau_s: 1 weights, 2 time constants"),
    ] {
        let bad = write(name, &table.replacen(",0.72,0.19,", with, 1));
        let e = refused(&folder().join("pieces.csv"), &bad);
        assert!(e.contains(want), "{e}");
    }
    let unsourced: Vec<String> = table
        .lines()
        .map(|l| {
            if l.starts_with("skin,") {
                l.rsplit_once(",0.19,").map_or(l.to_string(), |(a, _)| format!("{a},0.19,"))
            } else {
                l.to_string()
            }
        })
        .collect();
    let e = refused(&folder().join("pieces.csv"), &write("unsourced.csv", &(unsourced.join("\n") + "\n")));
    assert!(e.contains("unsourced.csv:2: column prony_source"), "{e}");
}
