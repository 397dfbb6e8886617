//! An independent f32 implementation of the contract's evaluation algorithm
//! (coeffs/README.md, "Evaluation algorithm"): it writes the golden vectors, so it must
//! not call the `needle-haptics` library. Every operation is a plain binary32 `*`, `+`
//! or `-` (Rust never fuses them), each rounded to nearest even on its own.

use crate::contract::COMPONENT_COUNT;
use crate::contract::{
    NCOEF, STATUS_ERROR, STATUS_FE_UNSOLVED, STATUS_SAT_DEPTH, STATUS_SAT_THETA_X, STATUS_SAT_THETA_Z, STATUS_SAT_X, STATUS_SAT_Z,
};
use crate::model::Model;
use needle_contract::{DEPTH_MAX_MM, HALF_RANGES};

/// The f32 nearest 1/3 (IEEE division is correctly rounded): 0x3eaaaaab.
pub const ONE_THIRD: f32 = needle_contract::ONE_THIRD_F32;
/// The f32 nearest 2/12, the scale of x and z: 0x3e2aaaab.
pub const S_XZ: f32 = needle_contract::SWEEP_SCALES_F32[0];
/// The f32 nearest 2/15, the scale of theta_x and theta_z: 0x3e088889.
pub const S_THETA: f32 = needle_contract::SWEEP_SCALES_F32[2];
/// The f32 nearest 1/12, the cross terms' scale of x and z: 0x3daaaaab.
pub const R_XZ: f32 = needle_contract::CROSS_SCALES_F32[0];
/// The f32 nearest 1/15, the cross terms' scale of theta_x and theta_z: 0x3d888889.
pub const R_THETA: f32 = needle_contract::CROSS_SCALES_F32[2];

/// `ODD[k][c]`: component c changes sign under sweep k's mirror (the contract's table).
pub use needle_contract::ODD;

/// The coefficients the firmware uses: every f64 coefficient rounded to the nearest f32.
#[derive(Debug, Clone, PartialEq)]
pub struct Tables32 {
    /// `baseline[c][i]` multiplies `u^i`.
    pub baseline: [[f32; NCOEF]; COMPONENT_COUNT],
    /// `rows[k][c][i][j]` multiplies `u^i t^j` for sweep k, component c.
    pub rows: [[[[f32; NCOEF]; NCOEF]; COMPONENT_COUNT]; 4],
    /// The coupled form's cross terms per component, in file order: exponents of
    /// `(xi, zeta, alpha, beta)` and the depth polynomial (`p[i]` multiplies `u^i`).
    /// Empty for the paper form.
    pub cross: [Vec<([u8; 4], Vec<f32>)>; COMPONENT_COUNT],
    /// The set's unsolved region (`unsolved.toml`; empty: no pose is flagged).
    pub unsolved: Vec<crate::unsolved::Entry>,
}

impl Tables32 {
    /// Round every coefficient of `model` to the nearest f32 (`as`, round to nearest even).
    pub fn from_model(model: &Model) -> Self {
        let cross = std::array::from_fn(|c| match &model.cross {
            Some(k) => k.terms.terms[c].iter().map(|(e, p)| (*e, p.iter().map(|v| *v as f32).collect())).collect(),
            None => Vec::new(),
        });
        let mut t = Tables32 {
            baseline: [[0.0; NCOEF]; COMPONENT_COUNT],
            rows: [[[[0.0; NCOEF]; NCOEF]; COMPONENT_COUNT]; 4],
            cross,
            unsolved: Vec::new(),
        };
        for (dst, src) in t.baseline.iter_mut().zip(&model.baseline) {
            for (d, s) in dst.iter_mut().zip(&src.coeffs) {
                *d = *s as f32;
            }
        }
        for (dk, sk) in t.rows.iter_mut().zip(&model.matrices) {
            for (dc, sc) in dk.iter_mut().zip(sk) {
                for (di, si) in dc.iter_mut().zip(&sc.rows) {
                    for (d, s) in di.iter_mut().zip(si) {
                        *d = *s as f32;
                    }
                }
            }
        }
        t
    }

    /// The same tables with the unsolved region `entries` (`FE_UNSOLVED` in the status).
    #[must_use]
    pub fn with_unsolved(mut self, entries: Vec<crate::unsolved::Entry>) -> Self {
        self.unsolved = entries;
        self
    }
}

/// `h(p, w) = (((p4*w + p3)*w + p2)*w + p1)*w + p0` in f32 (degree 4): from the top
/// coefficient down, one rounded multiply and one rounded add per step.
#[inline(never)]
pub fn h32(p: &[f32; NCOEF], w: f32) -> f32 {
    let mut acc = p[NCOEF - 1];
    for i in (0..NCOEF - 1).rev() {
        acc = acc * w + p[i];
    }
    acc
}

/// Clamp to `[lo, hi]` by comparison: a value inside (either zero sign included) is
/// returned unchanged.
pub fn clamp32(v: f32, lo: f32, hi: f32) -> f32 {
    if v < lo {
        lo
    } else if v > hi {
        hi
    } else {
        v
    }
}

/// Evaluate at `pose = [x_mm, z_mm, theta_x_deg, theta_z_deg, depth_mm]` (f32): the wrench
/// `[fx_n, fy_n, fz_n, mx_nmm, my_nmm, mz_nmm]` (N, N·mm) and the status byte, bit for
/// bit as coeffs/README.md specifies.
pub fn eval(t: &Tables32, pose: [f32; 5]) -> ([f32; COMPONENT_COUNT], u8) {
    // 1. error
    for v in pose {
        if !v.is_finite() {
            return ([0.0; COMPONENT_COUNT], STATUS_ERROR);
        }
    }
    let [x, z, tx, tz, d] = pose;
    // 2. saturation
    let [vx, vz, vtx, vtz] = HALF_RANGES.map(|v| v as f32);
    let xc = clamp32(x, -vx, vx);
    let zc = clamp32(z, -vz, vz);
    let txc = clamp32(tx, -vtx, vtx);
    let tzc = clamp32(tz, -vtz, vtz);
    let dc = clamp32(d, 0.0, DEPTH_MAX_MM as f32);
    let mut status = 0u8;
    if xc != x {
        status |= STATUS_SAT_X;
    }
    if zc != z {
        status |= STATUS_SAT_Z;
    }
    if txc != tx {
        status |= STATUS_SAT_THETA_X;
    }
    if tzc != tz {
        status |= STATUS_SAT_THETA_Z;
    }
    if dc != d {
        status |= STATUS_SAT_DEPTH;
    }
    // 3. normalisation
    let u = dc * ONE_THIRD - 1.0;
    let vals = [xc, zc, txc, tzc];
    let scales = [S_XZ, S_XZ, S_THETA, S_THETA];
    let mut tt = [0.0f32; 4];
    let mut negative = [false; 4];
    for k in 0..4 {
        tt[k] = vals[k].abs() * scales[k] - 1.0;
        negative[k] = vals[k] < 0.0;
    }
    // 4. polynomials, 5. superposition
    let mut w = [0.0f32; COMPONENT_COUNT];
    for c in 0..COMPONENT_COUNT {
        let mut acc = h32(&t.baseline[c], u);
        for k in 0..4 {
            let m = &t.rows[k][c];
            let r: [f32; NCOEF] = std::array::from_fn(|i| h32(&m[i], tt[k]));
            let dev = h32(&r, u);
            if negative[k] && ODD[k][c] {
                acc -= dev;
            } else {
                acc += dev;
            }
        }
        w[c] = acc;
    }
    // 6. cross terms (coupled form)
    let n = [xc * R_XZ, zc * R_XZ, txc * R_THETA, tzc * R_THETA];
    for (wc, terms) in w.iter_mut().zip(&t.cross) {
        for (e, p) in terms {
            *wc += monomial32(*e, &n) * horner_n32(p, u);
        }
    }
    // 7. the unsolved region (on the clamped pose)
    if crate::unsolved::inside_f32(&t.unsolved, n, dc) {
        status |= STATUS_FE_UNSOLVED;
    }
    (w, status)
}

/// `m = n_k1 * n_k2 * ...`: each input `k` in order repeated `e[k]` times, multiplied
/// left to right starting from the first factor.
pub fn monomial32(e: [u8; 4], n: &[f32; 4]) -> f32 {
    let mut factors = e.iter().zip(n).flat_map(|(&k, &v)| std::iter::repeat_n(v, usize::from(k)));
    let first = factors.next().unwrap_or(1.0);
    factors.fold(first, |m, v| m * v)
}

/// Horner over any number of coefficients, highest power first, starting from the last
/// coefficient: `(p_d * u + p_{d-1}) * u + ... + p_0`.
pub fn horner_n32(p: &[f32], u: f32) -> f32 {
    match p.split_last() {
        Some((last, rest)) => rest.iter().rev().fold(*last, |acc, c| acc * u + c),
        None => 0.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constants_are_the_nearest_f32() {
        assert_eq!(R_XZ.to_bits(), 0x3daa_aaab);
        assert_eq!(R_THETA.to_bits(), 0x3d88_8889);
        assert_eq!(ONE_THIRD.to_bits(), 0x3eaa_aaab);
        assert_eq!(S_XZ.to_bits(), 0x3e2a_aaab);
        assert_eq!(S_THETA.to_bits(), 0x3e08_8889);
        for (c, exact) in [(ONE_THIRD, 1.0 / 3.0), (S_XZ, 2.0 / 12.0), (S_THETA, 2.0 / 15.0), (R_XZ, 1.0 / 12.0), (R_THETA, 1.0 / 15.0)] {
            let below = f32::from_bits(c.to_bits() - 1) as f64;
            let above = f32::from_bits(c.to_bits() + 1) as f64;
            let e = (c as f64 - exact).abs();
            assert!(e < (below - exact).abs() && e < (above - exact).abs());
        }
    }

    #[test]
    fn odd_table_matches_contract() {
        use crate::contract::Sweep;
        for k in Sweep::ALL {
            for (c, odd) in ODD[k.index()].iter().enumerate() {
                assert_eq!(k.is_odd(c), *odd);
            }
        }
    }
}
