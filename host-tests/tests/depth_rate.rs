//! `wrench_and_depth_rate` (the insertion guard's stiffness) against
//! `wrench_and_stiffness` on every golden pose: the wrench and status bit for bit, and
//! the three force rates by depth bit for bit; past 6 mm `extended_wrench_and_depth_rate`
//! has `extended_wrench`'s bits and its rate is the derivative of the fitter's f64 law.
use needle_fit::depth_extension::{fit, ratio};
use needle_fit::golden::stiffness_float32::parse_csv;
use needle_fit::GOLDEN_STIFFNESS_FILE;
use needle_haptics::depth_extension::extended_wrench_and_depth_rate;
use needle_haptics::{extended_wrench, model_info, wrench, wrench_and_depth_rate, wrench_and_stiffness, Pose};
use std::path::Path;

fn same(a: f32, b: f32) -> bool {
    (a.is_nan() && b.is_nan()) || a.to_bits() == b.to_bits()
}

#[test]
fn depth_rate_has_the_bits_of_the_full_stiffness_on_every_golden_pose() {
    assert!(std::hint::black_box(model_info::FITTED), "the library was built without a fitted model");
    let path = Path::new(model_info::SET_DIR).join(GOLDEN_STIFFNESS_FILE);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let rows = parse_csv(&text, &path).unwrap_or_else(|e| panic!("{e:#}"));
    assert!(rows.len() > 4000, "{} golden poses", rows.len());
    let mut nonzero = 0;
    for row in &rows {
        let [x, z, tx, tz, d] = row.pose;
        let pose = Pose::new(x, z, tx, tz, d);
        let full = wrench_and_stiffness(&pose);
        let (e, rate) = wrench_and_depth_rate(&pose);
        assert_eq!(e.status, full.status, "{pose:?}");
        for (a, b) in e.wrench.to_array().into_iter().zip(full.wrench.to_array()) {
            assert!(same(a, b), "{pose:?}: wrench {:?} vs wrench_and_stiffness {:?}", e.wrench, full.wrench);
        }
        let want = full.stiffness.by_depth.to_array();
        for (c, (a, b)) in rate.into_iter().zip(want).enumerate() {
            assert!(same(a, b), "{pose:?}: depth rate of force {c}: {a} vs {b}");
            nonzero += usize::from(a != 0.0);
        }
    }
    assert!(nonzero > rows.len(), "the rates are not all zero ({nonzero} nonzero)");
}

#[test]
fn past_six_mm_the_rate_is_the_laws_derivative_and_the_wrench_is_extended_wrenchs() {
    let set = Path::new(env!("CARGO_MANIFEST_DIR")).join("../coeffs/default");
    let e = fit(&set).expect("fit").expect("a deep centre run");
    let span = e.depth_max_mm - 6.0;
    for p in [Pose::new(0.0, 0.0, 0.0, 0.0, 0.0), Pose::new(3.0, -2.0, 5.0, -7.0, 0.0)] {
        let at6 = wrench(&Pose { depth_mm: 6.0, ..p }).wrench.to_array();
        for k in 1..100 {
            let d = 6.0 + span * f64::from(k) / 100.0;
            let q = Pose { depth_mm: d as f32, ..p };
            let (got, rate) = extended_wrench_and_depth_rate(&q);
            let plain = extended_wrench(&q);
            assert_eq!(got.status, plain.status);
            assert_eq!(got.wrench.to_array().map(f32::to_bits), plain.wrench.to_array().map(f32::to_bits), "{q:?}");
            // the law's derivative in f64 by a central difference of its ratio (h = 1e-4
            // of the span: truncation ~h² of the quartic's third derivative, far below
            // the f32 rounding of the product allowed here)
            let h = 1e-4;
            let v = (d - 6.0) / span;
            let dr = (ratio(&e.coeffs, v + h) - ratio(&e.coeffs, v - h)) / (2.0 * h * span);
            for (c, (w6, r)) in at6.iter().zip(rate).enumerate() {
                let want = f64::from(*w6) * dr;
                assert!((f64::from(r) - want).abs() <= 1e-5 * want.abs() + 1e-9, "{q:?} force {c}: rate {r} vs the law's {want}");
            }
        }
    }
}
