//! The error bound of the fixed-point evaluation against the f64 evaluation of the same
//! model (coeffs/README.md, "Fixed-point error bound"), per component, in micro-units.
//!
//! For a pose in the domain, with exact normalised inputs `u`, `t_k` and the integer
//! evaluator's `U / 2^15`, `T_k / 2^15` (within half a Q15 step of them):
//!
//! |fixed - f64| <= arithmetic + coefficients + inputs + output
//!
//! - *arithmetic*: every floor of the integer evaluation loses less than one unit of its
//!   format, and every later step multiplies that loss by `|t|` or `|u|` <= 1: four
//!   floors per row polynomial (`4 * 2^-f`), one per alignment shift that is not zero
//!   (`2^-G`), four in the Horner in u (`4 * 2^-G`);
//! - *coefficients*: `sum |P * 2^-f - c * 10^6|` over every coefficient (each multiplies a
//!   product of powers of `|u|, |t|` <= 1), plus the rounding of `c * 10^6` in f64; a
//!   row's constant `c` is the f64 evaluation's, `-sum_{j>=1} (-1)^j c_j` ([`f64_row`]),
//!   and its `P0` the same sum of the row's integers;
//! - *inputs*: the model's slope times the rounding of the inputs:
//!   `2^-16 * (sup|dw/du| + sum_k sup|dD_k/dt|)`, each `sup` over `[-1, 1]^2` bounded by
//!   the maximum on a 257 x 257 grid plus (half the grid step) x (a coefficient-sum bound
//!   of the polynomial's own slopes), so that it is rigorous between grid points;
//! - *output*: the final rounding to whole micro-units, 0.5;
//! - *cross terms* (coupled form): per coefficient, its quantisation, `|p_i|` times the
//!   error of the Q15 monomial, and the floors of the product and the shift (see
//!   [`error_bound`]).
use crate::error::CodegenError;
use crate::fixed::{fixed_formats, ErrorBound, FixedComponent, FixedTables, NORM_FRAC_BITS, OUTPUT_SCALE};
use crate::model::Model;
use std::path::Path;

/// Grid intervals per axis of the slope bounds.
const GRID: usize = 256;

/// A polynomial `sum a[i][j] u^i t^j` on `[-1, 1]^2`.
type Poly2 = Vec<Vec<f64>>;

fn eval_row(row: &[f64], w: f64) -> f64 {
    row.iter().rev().fold(0.0, |acc, c| acc * w + c)
}

/// `d/du` (`wrt_u`) or `d/dt` of `a`.
fn derivative(a: &Poly2, wrt_u: bool) -> Poly2 {
    if wrt_u {
        a.iter().enumerate().skip(1).map(|(i, row)| row.iter().map(|c| i as f64 * c).collect()).collect()
    } else {
        a.iter().map(|row| row.iter().enumerate().skip(1).map(|(j, c)| j as f64 * c).collect()).collect()
    }
}

/// `sum |coefficients|` of `a`: a bound of `|a|` on the box.
fn abs_sum(a: &Poly2) -> f64 {
    a.iter().flatten().map(|c| c.abs()).sum()
}

/// A rigorous bound of `sup |a|` over `[-1, 1]^2`: the maximum over the grid plus half the
/// grid step times bounds of both slopes.
fn sup_abs(a: &Poly2) -> f64 {
    if a.is_empty() {
        return 0.0;
    }
    let node = |n: usize| -1.0 + 2.0 * n as f64 / GRID as f64;
    let mut max = 0.0f64;
    for nt in 0..=GRID {
        let t = node(nt);
        let r: Vec<f64> = a.iter().map(|row| eval_row(row, t)).collect();
        for nu in 0..=GRID {
            max = max.max(eval_row(&r, node(nu)).abs());
        }
    }
    let half_step = 1.0 / GRID as f64;
    max + half_step * (abs_sum(&derivative(a, true)) + abs_sum(&derivative(a, false)))
}

fn pow2(e: i32) -> f64 {
    2f64.powi(e)
}

/// A deviation row as the f64 evaluation sees it (coeffs/README.md, "The model"): its
/// terms `j >= 1` in the basis `t^j - (-1)^j`, that is with the constant
/// `-sum_{j>=1} (-1)^j rows[i][j]` in place of `rows[i][0]` (which holds the f32 tables'
/// constant). The fixed-point row's `P0` is derived the same way from its other integers,
/// so the quantisation error of `P0` is at most that of the others.
fn f64_row(row: &[f64; 5]) -> [f64; 5] {
    let [_, c1, c2, c3, c4] = *row;
    [c1 - c2 + c3 - c4, c1, c2, c3, c4]
}

/// The error bound of component `c` with the tables `comp`.
pub(crate) fn error_bound(model: &Model, c: usize, comp: &FixedComponent) -> ErrorBound {
    let g = comp.frac_bits;
    let lsb_g = pow2(-(g as i32));
    let coef_err = |q: i32, f: u32, v: f64| -> f64 {
        let exact = v * OUTPUT_SCALE;
        (f64::from(q) * pow2(-(f as i32)) - exact).abs() + exact.abs() * pow2(-52)
    };
    let mut arithmetic = 4.0 * lsb_g;
    let mut coefficients = 0.0;
    let base = &model.baseline[c].coeffs;
    for (i, b) in base.iter().enumerate() {
        coefficients += coef_err(comp.baseline[i], g, *b);
    }
    let base_poly: Poly2 = base.iter().map(|b| vec![*b]).collect();
    let mut slope_u = sup_abs(&derivative(&base_poly, true));
    let mut slope_t = 0.0;
    for m in model.matrices.iter().filter(|m| m.component == c) {
        let k = m.sweep;
        let rows = m.rows.map(|r| f64_row(&r));
        for (i, row) in rows.iter().enumerate() {
            let fr = &comp.rows[k][i];
            arithmetic += 4.0 * pow2(-(fr.frac_bits as i32));
            if comp.shifts[k][i] > 0 {
                arithmetic += lsb_g;
            }
            for (j, v) in row.iter().enumerate() {
                coefficients += coef_err(fr.coeffs[j], fr.frac_bits, *v);
            }
        }
        let poly: Poly2 = rows.iter().map(|r| r.to_vec()).collect();
        slope_u += sup_abs(&derivative(&poly, true));
        slope_t += sup_abs(&derivative(&poly, false));
    }
    // Cross terms (coupled form): per coefficient i, the quantisation of P[i] (times
    // |M| <= 1), |p_i| times the monomial's error, the floor of the product (2^-F) and of
    // the shift (2^-G); each then multiplies |u|^i <= 1. The monomial of degree n from
    // inputs within 2^-16 of n_k (|n_k| <= 1) and n - 1 floored Q15 products is within
    // n 2^-16 + (n - 1) 2^-15 of the exact product. Its slope in u is bounded by the
    // coefficient sum sum_i i |p_i| (|m| <= 1, |u| <= 1).
    for (x, t) in comp.cross.iter().zip(model.cross.iter().filter(|t| t.component == c)) {
        let degree: i32 = x.exponents.iter().map(|&k| i32::from(k)).sum();
        let mono_err = f64::from(degree) * pow2(-16) + f64::from(degree - 1) * pow2(-15);
        for (i, (q, v)) in x.coeffs.iter().zip(&t.coeffs).enumerate() {
            coefficients += coef_err(*q, x.frac_bits, *v) + v.abs() * OUTPUT_SCALE * mono_err;
            arithmetic += pow2(-(x.frac_bits as i32));
            if x.shift > 0 {
                arithmetic += lsb_g;
            }
            slope_u += i as f64 * v.abs();
        }
    }
    let half_step = pow2(-(NORM_FRAC_BITS as i32) - 1);
    let inputs = (slope_u + slope_t) * OUTPUT_SCALE * half_step;
    ErrorBound { arithmetic, coefficients, inputs, output: 0.5 }
}

/// Chooses every format of `model`, quantises its coefficients ([`fixed_formats`]) and
/// bounds each component's error (`error_bound`): the fixed-point tables the generator
/// writes.
///
/// # Errors
/// As [`fixed_formats`].
pub fn fixed_tables(model: &Model, model_path: &Path) -> Result<FixedTables, CodegenError> {
    let mut t = fixed_formats(model, model_path)?;
    for (c, comp) in t.components.iter_mut().enumerate() {
        comp.error_bound = error_bound(model, c, comp);
    }
    Ok(t)
}
