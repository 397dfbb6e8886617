//! The polynomials of the contract in f64: Horner and the deviation `D(t, u)`.

use super::contract::NCOEF;

/// Horner, highest power first: `(((p4 w + p3) w + p2) w + p1) w + p0`.
pub fn horner(p: &[f64; NCOEF], w: f64) -> f64 {
    let mut acc = p[NCOEF - 1];
    for c in p[..NCOEF - 1].iter().rev() {
        acc = acc * w + c;
    }
    acc
}

/// `D(t, u)`: `r_i = h(rows[i], t)`, then `h(r, u)`.
pub fn deviation(rows: &[[f64; NCOEF]; NCOEF], t: f64, u: f64) -> f64 {
    let mut r = [0.0; NCOEF];
    for (ri, row) in r.iter_mut().zip(rows) {
        *ri = horner(row, t);
    }
    horner(&r, u)
}
