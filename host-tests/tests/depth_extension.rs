//! The depth extension (coeffs/README.md, "Depth extension"): the library's
//! `extended_wrench` past 6 mm against the fitter's f64 law and against the deep FE
//! centre run it was fitted on; `depth-extension.toml` is what `needle fit` writes.
use needle_fit::depth_extension::{fit, ratio};
use needle_haptics::{extended_wrench, wrench, Pose, Status};
use std::path::Path;

fn set() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../coeffs/default")
}

#[test]
fn the_shipped_set_has_a_depth_extension_and_the_library_compiled_it_in() {
    let e = fit(&set()).expect("fit").expect("coeffs/default/fe/deep/centre.csv: the set ships a deep centre run");
    assert!(
        std::hint::black_box(needle_haptics::depth_extension::tables::FITTED),
        "the library compiled the set's depth-extension.toml in"
    );
    assert_eq!(needle_haptics::depth_extension::tables::DEPTH_MAX_MM, e.depth_max_mm as f32);
    assert!(e.depth_max_mm > 9.0, "the deep run reaches {} mm", e.depth_max_mm);
}

#[test]
fn past_six_mm_the_library_follows_the_fitters_law() {
    let e = fit(&set()).expect("fit").expect("a deep centre run");
    let poses = [Pose::new(0.0, 0.0, 0.0, 0.0, 0.0), Pose::new(3.0, -2.0, 5.0, -7.0, 0.0), Pose::new(-6.0, 4.0, -10.0, 3.0, 0.0)];
    for p in poses {
        let at6 = wrench(&Pose { depth_mm: 6.0, ..p }).wrench.to_array();
        for k in 0..=100 {
            let d = 6.0 + (e.depth_max_mm - 6.0) * f64::from(k) / 100.0;
            let got = extended_wrench(&Pose { depth_mm: d as f32, ..p });
            assert_eq!(got.status, Status::OK, "{p:?} at {d} mm");
            let r = ratio(&e.coeffs, (d - 6.0) / (e.depth_max_mm - 6.0));
            for (c, (w6, w)) in at6.iter().zip(got.wrench.to_array()).enumerate() {
                let want = f64::from(*w6) * r;
                // f32: the ratio's Horner in f32 and one product, a few ulps of the result
                assert!((f64::from(w) - want).abs() <= 1e-6 * want.abs() + 1e-12, "{p:?} at {d} mm, component {c}: {w} vs {want}");
            }
        }
    }
    let beyond = extended_wrench(&Pose::new(0.0, 0.0, 0.0, 0.0, 40.0));
    assert!(beyond.status.contains(Status::SAT_DEPTH), "past the extension the depth is clamped and flagged");
}

#[test]
fn the_extended_centre_follows_the_deep_fe_run() {
    let path = set().join("fe/deep/centre.csv");
    let rows = needle_set::results::read_csv(&path).expect("deep centre run");
    let peak = rows.iter().map(|r| r.wrench[1].abs()).fold(0.0, f64::max);
    let mut worst = 0.0f64;
    for r in rows.iter().filter(|r| r.depth_mm >= 6.0) {
        let got = f64::from(extended_wrench(&Pose::new(0.0, 0.0, 0.0, 0.0, r.depth_mm as f32)).wrench.fy_n);
        worst = worst.max(100.0 * (got - r.wrench[1]).abs() / peak);
    }
    println!("extended centre Fy against the deep FE run, 6 mm to the end: largest error {worst:.3} % of the run's peak |Fy|");
    // the model's own error at 6 mm (the coupled fit, ~1 % of the campaign's peak) carries
    // into the extension, which scales it by R; 3 % is the coupled form's goal on any
    // held-out run (coeffs/README.md), kept here for the deeper range
    assert!(worst <= 3.0, "extended centre Fy off the deep FE run by {worst:.3} % of peak |Fy|");
}

/// The law's largest error past 6 mm against a deep half-model run, % of the run's peak
/// |Fy|: the model's own largest-error goal on held-out runs (3 %, `needle validate`), so
/// that past 6 mm the law costs no more than the fit does within it.
const LAW_MAX_PCT: f64 = 3.0;

#[test]
fn the_law_holds_on_the_deep_half_model_runs() {
    let e = fit(&set()).expect("fit").expect("a deep centre run");
    let folder = needle_set::set_folder::SetFolder::open(&set()).expect("the shipped set");
    let checks = needle_fit::depth_extension::law_checks(&folder, &e).expect("the deep runs");
    println!("{}", needle_fit::depth_extension::law_summary(&checks));
    assert!(checks.iter().any(|c| c.pose == "x+04"), "the set ships the deep x+04 run");
    for c in &checks {
        assert!(c.depth_mm >= e.depth_max_mm - 1e-9, "{}: reaches {} mm of {}", c.pose, c.depth_mm, e.depth_max_mm);
        for (k, v) in c.worst_pct.iter().enumerate() {
            assert!(*v <= LAW_MAX_PCT, "{} component {k}: the law is {v} % of peak |Fy| off the FE past 6 mm", c.pose);
        }
    }
}
