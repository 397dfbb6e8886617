//! The cross terms of the coupled form (coeffs/README.md, "The coupled form"): their
//! monomials, which keep the block's mirror symmetries exactly, and their f64 value.
//! Fitting them is [`super::coupled`].
//!
//! A term of component `c` is `m(xi, zeta, alpha, beta) * P(u)` with `xi = x / 12 mm`,
//! `zeta = z / 12 mm`, `alpha = theta_x / 15 deg`, `beta = theta_z / 15 deg` (signed,
//! clamped to the domain), `u = d / 3 - 1`, `m` a product of powers of at least two of
//! the inputs and `P` a polynomial in `u`.
//!
//! **Mirror symmetries, exact by construction**: the mirror `x -> -x` maps
//! `(xi, beta) -> (-xi, -beta)` and flips fx, my, mz; the mirror `z -> -z` maps
//! `(zeta, alpha) -> (-zeta, -alpha)` and flips fz, mx, my ([`Sweep::is_odd`]). A
//! monomial of component `c` is kept only when its degree in `(xi, beta)` is odd exactly
//! when `c` is odd under the first mirror, and its degree in `(zeta, alpha)` likewise
//! under the second; every kept term then has `c`'s parities, for every coefficient value.

use super::contract::Pose64;
use super::contract::{u_of, Sweep, DEPTH_MAX_MM};
use crate::contract::COMPONENT_COUNT;

/// Exponents of `(xi, zeta, alpha, beta)` in one cross monomial.
pub type Exponents = [u8; 4];

/// The two size parameters of the cross terms.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub struct CrossForm {
    /// Largest total degree of a cross monomial in the pose inputs (>= 2).
    pub max_degree: u8,
    /// Degree of each monomial's polynomial in depth `u`.
    pub depth_degree: u8,
}

/// The cross forms a model file may hold (the generator accepts these): total degree 2..=4
/// in the pose, 2..=4 in depth. The fitter tries the subset [`super::coupled::CROSS_FORMS`].
pub const CANDIDATES: [CrossForm; 9] = {
    let mut out = [CrossForm { max_degree: 2, depth_degree: 2 }; 9];
    let mut i = 0;
    while i < 9 {
        out[i] = CrossForm { max_degree: 2 + (i / 3) as u8, depth_degree: 2 + (i % 3) as u8 };
        i += 1;
    }
    out
};

/// Fitted cross terms.
#[derive(Debug, Clone, PartialEq)]
pub struct CrossTerms {
    /// Their size.
    pub form: CrossForm,
    /// Per component in contract order: each monomial and its depth polynomial's
    /// coefficients (`coeffs[i]` multiplies `u^i`; unit of the component).
    pub terms: [Vec<(Exponents, Vec<f64>)>; COMPONENT_COUNT],
}

/// Whether monomial `e` has component `c`'s mirror parities (module docs).
pub fn has_parity(e: Exponents, c: usize) -> bool {
    let odd_x = (e[0] + e[3]) % 2 == 1;
    let odd_z = (e[1] + e[2]) % 2 == 1;
    odd_x == Sweep::X.is_odd(c) && odd_z == Sweep::Z.is_odd(c)
}

/// The cross monomials of component `c` up to total degree `max_degree`, in a fixed
/// order (by total degree, then lexicographically by exponents, highest first).
pub fn monomials(c: usize, max_degree: u8) -> Vec<Exponents> {
    let mut out = Vec::new();
    for total in 2..=max_degree {
        for a in (0..=total).rev() {
            for b in (0..=total - a).rev() {
                for p in (0..=total - a - b).rev() {
                    let e = [a, b, p, total - a - b - p];
                    let inputs = e.iter().filter(|&&k| k > 0).count();
                    if inputs >= 2 && has_parity(e, c) {
                        out.push(e);
                    }
                }
            }
        }
    }
    out
}

/// The normalised, clamped pose inputs `(xi, zeta, alpha, beta)` and `u` (NaN inputs
/// give zeros: the paper form reports the error status for them).
pub fn normalised(pose: Pose64) -> ([f64; 4], f64) {
    if pose.iter().any(|v| !v.is_finite()) {
        return ([0.0; 4], 0.0);
    }
    let n: [f64; 4] = std::array::from_fn(|i| {
        let m = Sweep::ALL[i].half_range();
        pose[i].clamp(-m, m) / m
    });
    (n, u_of(pose[4].clamp(0.0, DEPTH_MAX_MM)))
}

pub fn mono(e: Exponents, n: &[f64; 4]) -> f64 {
    e.iter().zip(n).map(|(&k, v)| v.powi(i32::from(k))).product()
}

pub fn poly(coeffs: &[f64], u: f64) -> f64 {
    coeffs.iter().rev().fold(0.0, |acc, c| acc * u + c)
}

/// The cross terms' contribution to each component at `pose` (f64).
pub fn cross_value(t: &CrossTerms, pose: Pose64) -> [f64; COMPONENT_COUNT] {
    let (n, u) = normalised(pose);
    std::array::from_fn(|c| t.terms[c].iter().map(|(e, p)| mono(*e, &n) * poly(p, u)).sum())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contract::COMPONENTS;

    /// Every monomial flips exactly like its component under both mirrors.
    #[test]
    fn monomials_keep_the_mirror_symmetries() {
        let n = [0.3, -0.7, 0.45, 0.9];
        let mx = [-n[0], n[1], n[2], -n[3]];
        let mz = [n[0], -n[1], -n[2], n[3]];
        for c in 0..COMPONENT_COUNT {
            let ms = monomials(c, 4);
            assert!(!ms.is_empty(), "{}: no cross terms", COMPONENTS[c]);
            for e in ms {
                assert!(e.iter().filter(|&&k| k > 0).count() >= 2 && (2..=4).contains(&e.iter().sum::<u8>()));
                let sx = if Sweep::X.is_odd(c) { -1.0 } else { 1.0 };
                let sz = if Sweep::Z.is_odd(c) { -1.0 } else { 1.0 };
                assert!((mono(e, &mx) - sx * mono(e, &n)).abs() < 1e-15, "{e:?} {}", COMPONENTS[c]);
                assert!((mono(e, &mz) - sz * mono(e, &n)).abs() < 1e-15, "{e:?} {}", COMPONENTS[c]);
            }
        }
        // the four parity classes split the 53 cross monomials of degree 2..=4
        let all: usize = [0, 1, 2, 4].iter().map(|&c| monomials(c, 4).len()).sum();
        assert_eq!(all, 6 + 16 + 31);
        assert_eq!(monomials(1, 2), vec![[1, 0, 0, 1], [0, 1, 1, 0]], "fy: x*theta_z and z*theta_x");
    }
}
