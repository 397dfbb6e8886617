//! The coupled form's fixed-point path on a model file with made-up cross terms (the
//! default set's fitted paper part plus cross terms of every monomial of degree <= 3,
//! coefficients of the size the default set's sweeps have): the generator
//! (`needle-codegen`) and the fitter's independent fixed-point tables pick the same
//! formats; the fitter's integer evaluation never leaves 2^30 and stays within the
//! generated error bound of the f64 coupled model; the f32 evaluation stays close to it;
//! the paper part is unchanged. Not a fitted model: nothing here goes under coeffs/.
mod made_up_model;

use needle_fit::eval::fixed::eval as eval_fixed;
use needle_fit::eval::float32::{eval as eval32, Tables32};
use needle_fit::eval::float64::{eval as eval64, eval_paper};
use needle_fit::fixed_formats::TablesFixed;
use needle_fit::model_file::parse;
use std::path::Path;

use needle_contract::COMPONENTS;

/// A deterministic spread of Q16.16 poses over the whole domain, edges included.
fn poses() -> Vec<[i32; 5]> {
    let axis = |half: i32| [-half, -half / 3, -1, 0, 1, half / 5, half / 2, half];
    let (xz, th, d) = (12 << 16, 15 << 16, 6 << 16);
    let mut out = Vec::new();
    for x in axis(xz) {
        for z in axis(xz) {
            for tx in axis(th) {
                for tz in axis(th) {
                    for depth in [0, 1, d / 7, d / 2, d - 1, d] {
                        out.push([x, z, tx, tz, depth]);
                    }
                }
            }
        }
    }
    out
}

#[test]
fn generator_and_fitter_agree_and_the_bound_holds() {
    let text = made_up_model::coupled_default_text();
    let path = Path::new("made-up-coupled/model.toml");
    let model = parse(&text, path).unwrap_or_else(|e| panic!("{e:#}"));
    let cross = model.cross.as_ref().expect("coupled");
    assert_eq!(cross.terms.terms.iter().map(Vec::len).sum::<usize>(), 2 * 8 + 6 + 2 * 6 + 4, "cross terms of degree <= 3");
    let generated = needle_codegen::parse_model_str(&text, path).unwrap_or_else(|e| panic!("{e}"));
    let fixed = needle_codegen::fixed_tables(&generated, path).unwrap_or_else(|e| panic!("{e}"));
    let host = TablesFixed::from_model(&model).unwrap_or_else(|e| panic!("{e:#}"));
    for c in 0..needle_contract::COMPONENT_COUNT {
        let comp = &fixed.components[c];
        assert_eq!(comp.frac_bits, host.acc_frac[c], "{}: accumulator format", COMPONENTS[c]);
        assert_eq!(comp.baseline.map(i64::from), host.baseline[c], "{}: baseline", COMPONENTS[c]);
        assert_eq!(comp.cross.len(), host.cross[c].len());
        for (g, (e, q, f)) in comp.cross.iter().zip(&host.cross[c]) {
            assert_eq!((g.exponents, g.frac_bits), (*e, *f), "{}: cross format", COMPONENTS[c]);
            assert_eq!(g.coeffs.iter().map(|v| i64::from(*v)).collect::<Vec<_>>(), *q);
        }
    }
    let t32 = Tables32::from_model(&model);
    let mut max_err = [0.0f64; needle_contract::COMPONENT_COUNT];
    let mut max_cross = [0.0f64; needle_contract::COMPONENT_COUNT];
    for p in poses() {
        let exact = p.map(|v| f64::from(v) / 65536.0);
        let (w64, _) = eval64(&model, exact);
        let (wp, _) = eval_paper(&model, exact);
        let (wq, _) = eval_fixed(&host, p).unwrap_or_else(|o| panic!("pose {p:?}: {o}"));
        let (w32, _) = eval32(&t32, exact.map(|v| v as f32));
        for c in 0..needle_contract::COMPONENT_COUNT {
            let err = (f64::from(wq[c]) - w64[c] * 1e6).abs();
            max_err[c] = max_err[c].max(err);
            max_cross[c] = max_cross[c].max((w64[c] - wp[c]).abs());
            let bound = fixed.components[c].error_bound.total();
            assert!(err <= bound, "{} at {p:?}: fixed {} uN vs f64 {} uN: error {err} > bound {bound}", COMPONENTS[c], wq[c], w64[c] * 1e6);
            let scale: f64 = if needle_contract::is_force(c) { 1e-3 } else { 6e-2 };
            assert!((f64::from(w32[c]) - w64[c]).abs() <= 1e-4 * scale.max(w64[c].abs()), "{} f32 at {p:?}", COMPONENTS[c]);
        }
    }
    for c in 0..needle_contract::COMPONENT_COUNT {
        // not vacuous: the cross terms change every component and the integer path rounds
        assert!(max_cross[c] > 1e-4, "{}: the cross terms change nothing ({:e})", COMPONENTS[c], max_cross[c]);
        assert!(max_err[c] > 0.0, "{}: no rounding at all", COMPONENTS[c]);
    }
}

#[test]
fn a_paper_file_reads_back_without_cross_terms() {
    let text = made_up_model::paper_default_text();
    let model = parse(&text, Path::new("paper.toml")).unwrap_or_else(|e| panic!("{e:#}"));
    assert!(model.cross.is_none());
    let coupled = parse(&made_up_model::coupled_default_text(), Path::new("m.toml")).expect("coupled");
    let pose = [2.0, -1.0, 7.0, -4.0, 4.5];
    assert_eq!(eval_paper(&coupled, pose), eval64(&model, pose), "the coupled file's paper part is the paper model");
    assert_ne!(eval64(&coupled, pose).0, eval64(&model, pose).0);
}
