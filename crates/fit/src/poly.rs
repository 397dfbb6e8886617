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

/// `D(t, u)`: `r_i = h(rows[i], t) - h(rows[i], -1)`, then `h(r, u)`.
///
/// In f64 a deviation is the row's terms `j >= 1` in the basis `t^j - (-1)^j`
/// (coeffs/README.md, "The model"): `rows[i][0]` holds the f32 evaluation's constant,
/// which makes the f32 row exactly 0 at `t = -1`, and is within `2^-21 sum_j
/// |rows[i][j]|` of `-sum_{j>=1} rows[i][j] (-1)^j`; subtracting the row's value at
/// `t = -1` makes `D(-1, u)` exactly 0 in f64 too (a sweep at 0 adds nothing, so the
/// odd components are exactly antisymmetric), whatever that constant.
pub fn deviation(rows: &[[f64; NCOEF]; NCOEF], t: f64, u: f64) -> f64 {
    horner(&deviation_rows(rows, t), u)
}

/// The `r_i = h(rows[i], t) - h(rows[i], -1)` of [`deviation`]: each row's value, 0 at
/// `t = -1` exactly.
pub fn deviation_rows(rows: &[[f64; NCOEF]; NCOEF], t: f64) -> [f64; NCOEF] {
    std::array::from_fn(|i| horner(&rows[i], t) - horner(&rows[i], -1.0))
}
