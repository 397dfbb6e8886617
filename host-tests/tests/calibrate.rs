//! `needle calibrate` on the shipped measured curve (Okamura, Simone and O'Leary 2004,
//! bovine liver, 1.27 mm needle at 3 mm/s: coeffs/default/measured/): every calibration
//! goal met, and the shipped liver stack is what the calibration writes; bad curves get
//! a clear error.
use needle_calibrate::{calibrate, events::EventRule, Options};
use std::path::{Path, PathBuf};

fn curve() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../coeffs/default/measured/okamura2004-bovine-liver/position_force.csv")
}

fn options(curve: &Path) -> Options<'_> {
    let set = Path::new(env!("CARGO_MANIFEST_DIR")).join("../coeffs/default");
    let mu0 = needle_codegen::tissue::read_fe_shear_modulus(&set).expect("campaign.toml").expect("a campaign");
    Options {
        curve,
        name: "liver".into(),
        needle_diameter_mm: 1.27,
        speed_mm_per_s: 3.0,
        rule: EventRule::default(),
        fe_shear_modulus_n_per_mm2: mu0,
    }
}

#[test]
fn the_okamura_liver_calibrates_within_every_goal() {
    let path = curve();
    let c = calibrate(&options(&path)).unwrap_or_else(|e| panic!("{e:#}"));
    assert!(c.events.len() >= 2, "the curve has the capsule puncture and later ones: {}", c.events.len());
    for check in &c.checks {
        println!(
            "{:<58} measured {:>9.4} model {:>9.4} error {:>+8.3} {} (goal {})",
            check.what, check.measured, check.model, check.error, check.unit, check.goal
        );
    }
    let missed: Vec<String> =
        c.checks.iter().filter(|k| !k.met()).map(|k| format!("{}: {:+.3} {} (goal {})", k.what, k.error, k.unit, k.goal)).collect();
    assert!(missed.is_empty(), "calibration goals missed: {missed:#?}");
    // the goals the issue names are all among the checks
    for what in ["contact onset", "puncture 1 position", "puncture 1 force", "pre-puncture RMS", "mean force"] {
        assert!(c.checks.iter().any(|k| k.what.starts_with(what)), "no check {what:?}");
    }
}

#[test]
fn the_shipped_liver_stack_is_the_calibration_of_the_shipped_curve() {
    let path = curve();
    let c = calibrate(&options(&path)).unwrap_or_else(|e| panic!("{e:#}"));
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("../coeffs/default/tissue/liver.toml");
    let file = needle_codegen::tissue::parse_stack(&shipped).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(file.layers, c.stack.layers, "coeffs/default/tissue/liver.toml is stale: rerun needle calibrate (docs/insertion.md)");
}

/// The error of a calibration that must be refused (a short panic when it is not).
fn refused<T, E: std::fmt::Display>(r: Result<T, E>, what: &str) -> String {
    match r {
        Ok(_) => panic!("{what}: accepted"),
        Err(e) => e.to_string(),
    }
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).expect("temp file");
    p
}

#[test]
fn bad_curves_are_refused_with_a_reason() {
    let dir = tempfile::tempdir().expect("temp dir");
    let text = std::fs::read_to_string(curve()).expect("curve");
    // up to the first peak (the largest force before 20 mm) only: no drop, no puncture
    let peak_line = text
        .lines()
        .enumerate()
        .skip(1)
        .filter_map(|(i, l)| l.split_once(',').and_then(|(p, f)| Some((i, p.parse::<f64>().ok()?, f.parse::<f64>().ok()?))))
        .filter(|(_, p, _)| *p < 20.0)
        .max_by(|a, b| a.2.total_cmp(&b.2))
        .map(|(i, _, _)| i)
        .expect("a peak");
    let rising: String = text.lines().take(peak_line + 1).map(|l| format!("{l}\n")).collect();
    let p = write(dir.path(), "rising.csv", &rising);
    let e = refused(calibrate(&options(&p)), "no puncture: refused");
    assert!(e.contains("no puncture found"), "{e}");
    // no contact: zero force
    let flat: String = std::iter::once("position_mm,force_n\n".to_string()).chain((0..50).map(|i| format!("{}.0,0.0\n", i))).collect();
    let p = write(dir.path(), "flat.csv", &flat);
    let e = refused(calibrate(&options(&p)), "no contact: refused");
    assert!(e.contains("no puncture found") || e.contains("no contact"), "{e}");
    // a bad row names its line and column
    let bad = text.replacen("10.14", "10.1x4", 1);
    let line = bad.lines().position(|l| l.contains("10.1x4")).expect("edited") + 1;
    let p = write(dir.path(), "bad.csv", &bad);
    let e = refused(calibrate(&options(&p)), "bad row: refused");
    assert!(e.contains(&format!("bad.csv:{line}: column position_mm")), "{e}");
    // a missing column
    let p = write(dir.path(), "nocol.csv", &text.replacen("force_n", "load_n", 1));
    let e = refused(calibrate(&options(&p)), "no force column: refused");
    assert!(e.contains("nocol.csv:1: no column \"force_n\""), "{e}");
    // a needle diameter that is not > 0
    let path = curve();
    let e = refused(calibrate(&Options { needle_diameter_mm: 0.0, ..options(&path) }), "diameter: refused");
    assert!(e.contains("--needle-diameter-mm"), "{e}");
}
