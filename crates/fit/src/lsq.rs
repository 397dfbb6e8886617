//! Linear least squares in f64: Householder QR (nalgebra), never the normal equations.
//!
//! The fitter only ever solves small, well-scaled problems (at most 21 x 5, columns
//! `w^j` of a variable `w` normalised to [-1, 1]). The rank is checked first with the
//! singular values of the design matrix, so that a degenerate design (too few distinct
//! abscissae) is a clear error instead of a silently meaningless fit. Everything here is
//! deterministic: no threads, no matrix-multiply kernels chosen at run time (nalgebra
//! only hands products with every dimension > 5 to `matrixmultiply`).

use anyhow::{bail, Result};
use nalgebra::{DMatrix, DVector};

/// Largest accepted condition number (largest over smallest singular value) of a design
/// matrix. Powers 0..=4 of five or more distinct points spread over [-1, 1] are far below
/// it; a design with fewer distinct points than unknowns is far above it.
pub const MAX_CONDITION: f64 = 1e10;

/// Solve `min |a x - b|_2` for `x` (Householder QR of `a`, then back substitution).
///
/// `a` is `m x n` with `m >= n >= 1`, `b` has `m` entries. Units: whatever `a` and `b`
/// carry; `x` has the units of `b` over those of `a`'s columns.
///
/// # Errors
/// Shapes do not agree or `m < n`; a non-finite entry in `a` or `b`; `a` is rank
/// deficient or its condition number exceeds [`MAX_CONDITION`] (the message gives the
/// singular values).
pub fn lstsq(a: &DMatrix<f64>, b: &DVector<f64>) -> Result<DVector<f64>> {
    let (m, n) = a.shape();
    if n == 0 {
        bail!("least squares: the design matrix has no columns");
    }
    if b.len() != m {
        bail!("least squares: the design matrix has {m} rows but the right-hand side has {} entries", b.len());
    }
    if m < n {
        bail!("least squares: {m} equations for {n} unknowns: need at least as many equations as unknowns");
    }
    if let Some(v) = a.iter().chain(b.iter()).find(|v| !v.is_finite()) {
        bail!("least squares: non-finite input value {v}");
    }
    let sv = a.clone().svd(false, false).singular_values;
    let s_max = sv.iter().copied().fold(0.0f64, f64::max);
    let s_min = sv.iter().copied().fold(f64::INFINITY, f64::min);
    let well_posed = s_max > 0.0 && s_min * MAX_CONDITION >= s_max; // false on NaN too
    if !well_posed {
        let list: Vec<String> = sv.iter().map(|s| format!("{s:.3e}")).collect();
        bail!(
            "least squares: the {m} x {n} design matrix is rank deficient or too badly conditioned \
             (singular values {}; condition limit {MAX_CONDITION:e}); are there at least {n} distinct sample points?",
            list.join(", ")
        );
    }
    let qr = a.clone().qr();
    let mut qtb = b.clone();
    qr.q_tr_mul(&mut qtb);
    let r = qr.r(); // n x n upper triangular
    let mut x = DVector::<f64>::zeros(n);
    for i in (0..n).rev() {
        let mut s = qtb[i];
        for j in i + 1..n {
            s -= r[(i, j)] * x[j];
        }
        let d = r[(i, i)];
        if d == 0.0 {
            bail!("least squares: zero pivot in R at column {i}: rank deficient design");
        }
        x[i] = s / d;
    }
    Ok(x)
}

/// Least-squares polynomial of degree `degree` through the points `(w[k], y[k])`:
/// returns `p` with `p[j]` multiplying `w^j` (j = 0..=degree). `w` should already be
/// normalised to about [-1, 1] (the fitter's u and t are).
///
/// # Errors
/// `w` and `y` differ in length; fewer points than `degree + 1`; as [`lstsq`] (in
/// particular fewer than `degree + 1` distinct abscissae).
pub fn polyfit(w: &[f64], y: &[f64], degree: usize) -> Result<Vec<f64>> {
    if w.len() != y.len() {
        bail!("polynomial fit: {} abscissae but {} values", w.len(), y.len());
    }
    let n = degree + 1;
    if w.len() < n {
        bail!("polynomial fit of degree {degree}: {} points, need at least {n}", w.len());
    }
    let a = vandermonde(w, degree);
    let b = DVector::from_column_slice(y);
    let x = lstsq(&a, &b)?;
    Ok(x.iter().copied().collect())
}

/// The design matrix of a polynomial fit: row k is `(1, w_k, w_k^2, .., w_k^degree)`.
pub fn vandermonde(w: &[f64], degree: usize) -> DMatrix<f64> {
    DMatrix::from_fn(w.len(), degree + 1, |k, j| {
        let mut p = 1.0;
        for _ in 0..j {
            p *= w[k];
        }
        p
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_through_noisy_points() {
        // y = 1 + 2 w with residuals +-0.1 that are orthogonal to (1, w): exact recovery.
        let w = [-1.0, 0.0, 1.0, 2.0];
        let y = [-1.0 + 0.1, 1.0 - 0.1, 3.0 - 0.1, 5.0 + 0.1];
        let p = polyfit(&w, &y, 1).unwrap_or_default();
        assert_eq!(p.len(), 2);
        assert!((p[0] - 1.0).abs() < 1e-12 && (p[1] - 2.0).abs() < 1e-12, "{p:?}");
    }

    #[test]
    fn rank_deficient_is_an_error() {
        let e = polyfit(&[0.5, 0.5, 0.5, -0.5, -0.5], &[1.0; 5], 4);
        let msg = format!("{:#}", e.err().map(|e| e.to_string()).unwrap_or_default());
        assert!(msg.contains("rank deficient"), "{msg}");
    }
}
