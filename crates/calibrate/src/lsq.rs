//! Small least-squares problems with non-negative unknowns (at most a few columns).
use nalgebra::{DMatrix, DVector};

/// Minimises `|A x - b|²` subject to `x >= 0` by trying every subset of active columns
/// (exact for the few columns a layer has); returns `x` and the sum of squares.
#[must_use]
pub fn non_negative(columns: &[Vec<f64>], b: &[f64]) -> (Vec<f64>, f64) {
    let n = columns.len();
    let mut best: Option<(Vec<f64>, f64)> = None;
    for mask in 0u32..(1 << n) {
        let active: Vec<usize> = (0..n).filter(|k| mask & (1 << k) != 0).collect();
        let Some(x) = solve(columns, b, &active) else { continue };
        if x.iter().any(|v| *v < 0.0) {
            continue;
        }
        let sse = residual(columns, b, &x);
        if best.as_ref().is_none_or(|(_, s)| sse < *s) {
            best = Some((x, sse));
        }
    }
    best.unwrap_or_else(|| (vec![0.0; n], b.iter().map(|v| v * v).sum()))
}

/// The unconstrained solution on the `active` columns (the others zero), by SVD.
fn solve(columns: &[Vec<f64>], b: &[f64], active: &[usize]) -> Option<Vec<f64>> {
    let mut x = vec![0.0; columns.len()];
    if active.is_empty() {
        return Some(x);
    }
    let a = DMatrix::from_fn(b.len(), active.len(), |r, c| columns[active[c]][r]);
    let rhs = DVector::from_column_slice(b);
    let sol = a.svd(true, true).solve(&rhs, 1e-12).ok()?;
    for (k, &col) in active.iter().enumerate() {
        x[col] = sol[k];
    }
    Some(x)
}

/// `|A x - b|²`.
#[must_use]
pub fn residual(columns: &[Vec<f64>], b: &[f64], x: &[f64]) -> f64 {
    b.iter()
        .enumerate()
        .map(|(r, bv)| {
            let ax: f64 = columns.iter().zip(x).map(|(c, xv)| c[r] * xv).sum();
            (ax - bv) * (ax - bv)
        })
        .sum()
}
