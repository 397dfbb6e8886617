//! The f64 stiffness (`fit::eval::rate_float64`) against central differences of the f64 model,
//! and the f32 stiffness (`fit::eval::rate_float32`, which writes the golden file) against the
//! f64 stiffness, on the shipped paper model and on a coupled model with made-up cross
//! terms (`made_up_model`), at 400 poses inside the domain.
mod made_up_model;

use needle_contract::COMPONENT_COUNT;
use needle_fit::eval::float32::Tables32;
use needle_fit::eval::float64::eval;
use needle_fit::eval::rate_float32::eval_rates as rates32;
use needle_fit::eval::rate_float64::eval_rates as rates64;
use needle_fit::model::Model;
use needle_fit::model_file::{parse, read};
use rand::{Rng, SeedableRng};
use std::path::Path;

const INPUTS: [&str; 3] = ["depth", "x", "z"];

/// Poses with every input at least 0.01 (mm or deg) from the domain's edges and from the
/// kinks at x = 0 and z = 0, so that a central difference of step 1e-4 mm stays on one
/// polynomial piece.
fn poses() -> Vec<[f64; 5]> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(20);
    let mut side = |lo: f64, hi: f64| if rng.gen_bool(0.5) { rng.gen_range(lo..hi) } else { -rng.gen_range(lo..hi) };
    (0..400)
        .map(|_| {
            let (x, z, tx, tz) = (side(0.01, 11.99), side(0.01, 11.99), side(0.0, 14.99), side(0.0, 14.99));
            [x, z, tx, tz, 0.01 + (x.abs() * 7.3 + z.abs() * 3.1) % 5.98]
        })
        .collect()
}

/// Checks one model; returns the worst relative errors (analytic vs central difference,
/// f32 vs f64) for the closing report.
fn check(model: &Model, what: &str) -> (f64, f64) {
    const H_MM: f64 = 1e-4;
    let poses = poses();
    let analytic: Vec<[[f64; COMPONENT_COUNT]; 3]> = poses.iter().map(|p| rates64(model, *p).0).collect();
    // Per input and component: the largest |rate| over the poses, the scale of the
    // "relative" error where a rate passes through zero.
    let mut scale = [[0.0f64; COMPONENT_COUNT]; 3];
    for r in &analytic {
        for (s, v) in scale.iter_mut().flatten().zip(r.iter().flatten()) {
            *s = s.max(v.abs());
        }
    }
    let tables = Tables32::from_model(model);
    let (mut worst_fd, mut worst_32) = (0.0f64, 0.0f64);
    let mut failures = Vec::new();
    for (p, a) in poses.iter().zip(&analytic) {
        let (r32, status) = rates32(&tables, p.map(|v| v as f32));
        assert_eq!(status, 0, "{what}: pose {p:?} is inside the domain");
        for (j, input) in [4usize, 0, 1].into_iter().enumerate() {
            let (mut hi, mut lo) = (*p, *p);
            hi[input] += H_MM;
            lo[input] -= H_MM;
            let (fh, fl) = (eval(model, hi).0, eval(model, lo).0);
            for c in 0..needle_contract::COMPONENT_COUNT {
                let fd = (fh[c] - fl[c]) / (2.0 * H_MM);
                if scale[j][c] == 0.0 {
                    assert!(a[j][c] == 0.0 && fd == 0.0, "{what}: component {c} by {} is zero at every other pose", INPUTS[j]);
                    continue;
                }
                let denom = fd.abs().max(1e-3 * scale[j][c]);
                let e_fd = (a[j][c] - fd).abs() / denom;
                let e_32 = (f64::from(r32[j][c]) - a[j][c]).abs() / scale[j][c];
                worst_fd = worst_fd.max(e_fd);
                worst_32 = worst_32.max(e_32);
                if e_fd > 1e-6 || e_32 > 1e-4 {
                    failures.push(format!(
                        "{what}: pose {p:?}, component {c} by {}: analytic {:e}, central difference {fd:e}, f32 {:e}",
                        INPUTS[j], a[j][c], r32[j][c]
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{} rates off; first:\n{}", failures.len(), failures[..failures.len().min(8)].join("\n"));
    println!("{what}: worst |analytic - central difference| / max(|cd|, 1e-3 scale) = {worst_fd:.2e}; worst |f32 - f64| / scale = {worst_32:.2e}");
    (worst_fd, worst_32)
}

#[test]
fn paper_model_rates_match_central_differences() {
    let model = read(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../coeffs/default/model.toml")).expect("coeffs/default/model.toml");
    check(&model, "default set (paper form)");
}

#[test]
fn coupled_model_rates_match_central_differences() {
    let model = parse(&made_up_model::coupled_default_text(), Path::new("made-up-coupled/model.toml")).expect("coupled model");
    assert!(model.cross.is_some(), "the made-up model is coupled");
    check(&model, "made-up coupled model");
}
