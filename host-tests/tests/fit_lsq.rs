//! The least-squares core of the fitter: exact recovery of polynomials, clear errors on
//! degenerate input.

use nalgebra::{DMatrix, DVector};
use needle_fit::lsq::{lstsq, polyfit, vandermonde};

fn eval(p: &[f64], w: f64) -> f64 {
    p.iter().rev().fold(0.0, |acc, c| acc * w + c)
}

#[test]
fn recovers_an_exact_quartic_from_depth_samples() {
    // 21 depths 0..6 mm as the FE runs have them, u = d/3 - 1
    let p = [0.31, -1.27, 2.53, 0.71, -1.93];
    let u: Vec<f64> = (0..=20).map(|k| (6.0 * f64::from(k) / 20.0) / 3.0 - 1.0).collect();
    let y: Vec<f64> = u.iter().map(|&w| eval(&p, w)).collect();
    let q = polyfit(&u, &y, 4).expect("well-posed fit");
    assert_eq!(q.len(), 5);
    for (a, b) in p.iter().zip(&q) {
        assert!((a - b).abs() <= 1e-12, "coefficients {p:?} recovered as {q:?}");
    }
}

#[test]
fn recovers_an_exact_quartic_from_sweep_samples() {
    // 6 sweep values 0, 2, 4, 8, 12, 15 deg, t = |v| * 2/15 - 1; coefficients of mixed scale
    let p = [-3.2e-3, 7.5e-2, -1.1e-4, 4.0e-3, 2.2e-5];
    let t: Vec<f64> = [0.0f64, 2.0, 4.0, 8.0, 12.0, 15.0].iter().map(|v| v * 2.0 / 15.0 - 1.0).collect();
    let y: Vec<f64> = t.iter().map(|&w| eval(&p, w)).collect();
    let q = polyfit(&t, &y, 4).expect("well-posed fit");
    for (a, b) in p.iter().zip(&q) {
        assert!((a - b).abs() <= 1e-12, "coefficients {p:?} recovered as {q:?}");
    }
}

#[test]
fn least_squares_solution_is_orthogonal_to_the_columns() {
    let w: Vec<f64> = (0..15).map(|k| -1.0 + 2.0 * f64::from(k) / 14.0).collect();
    let y: Vec<f64> = w.iter().map(|&x| (3.0 * x).sin() + 0.1 * x.exp()).collect();
    let a = vandermonde(&w, 4);
    let b = DVector::from_column_slice(&y);
    let x = lstsq(&a, &b).expect("well-posed fit");
    let r = &a * &x - &b;
    let g = a.transpose() * r;
    assert!(g.amax() < 1e-13, "A^T r = {g}");
}

#[test]
fn rank_deficient_input_is_a_clear_error() {
    // three distinct abscissae cannot determine five coefficients
    let w = [-1.0, -1.0, 0.0, 0.0, 1.0, 1.0];
    let y = [1.0, 1.0, 0.5, 0.5, 2.0, 2.0];
    let e = polyfit(&w, &y, 4).expect_err("must refuse a rank-deficient design");
    let msg = format!("{e:#}");
    assert!(msg.contains("rank deficient"), "message: {msg}");
    assert!(msg.contains("distinct"), "message should say why: {msg}");
}

#[test]
fn too_few_points_and_bad_shapes_are_errors() {
    let e = polyfit(&[0.0, 0.5, 1.0], &[1.0, 2.0, 3.0], 4).expect_err("3 points for 5 unknowns");
    assert!(format!("{e:#}").contains("need at least 5"), "{e:#}");
    let e = polyfit(&[0.0, 0.5], &[1.0], 1).expect_err("length mismatch");
    assert!(format!("{e:#}").contains("abscissae"), "{e:#}");
    let a = DMatrix::<f64>::from_element(4, 2, 1.0);
    let e = lstsq(&a, &DVector::from_element(3, 1.0)).expect_err("rows mismatch");
    assert!(format!("{e:#}").contains("right-hand side"), "{e:#}");
    let e = polyfit(&[0.0, 0.5, f64::NAN], &[1.0, 2.0, 3.0], 1).expect_err("NaN input");
    assert!(format!("{e:#}").contains("non-finite"), "{e:#}");
}
