//! What no model of the contract's form can beat on one FE run: the floor of the
//! validation errors that the FE curve's own shape sets.
//!
//! At a fixed pose every form of the model (the paper's and the coupled one) is a
//! polynomial of degree [`DEGREE`](crate::contract::DEGREE) in depth: the baseline and every deviation are
//! polynomials of that degree in `u`, and a cross term multiplies one of degree
//! `depth_degree <= DEGREE` by a constant of the pose. So the best such polynomial
//! fitted to the run alone bounds every model from below:
//! - **RMS floor** of a component: the RMS of the least-squares polynomial's residual over
//!   all the run's depths. No model has a smaller RMS error on that run (least squares
//!   minimises exactly that), in the same units as `needle validate`'s RMS.
//! - **Table 2 floor**: a lower bound of the smallest possible largest relative Fy error
//!   at depths >= `min_depth_mm` (`needle validate` passes its Table 2 goal's 1 mm: its
//!   "Fy rel d>=1 %"). For any
//!   weights `l_k >= 0` summing to 1, the polynomial minimising `sum l_k e_k^2` (`e_k` the
//!   relative error at depth k) has `sqrt(sum l_k e_k^2)` at most the weighted sum of the
//!   minimax polynomial, which is at most the minimax error squared: so every such value
//!   is a lower bound. Lawson's iteration (`l_k <- l_k |e_k| / sum l_j |e_j|`, from equal
//!   weights) raises it towards the minimax error; the largest value reached is kept.
//!
//! Both are lower bounds, not estimates: a goal below its floor is out of reach for the
//! data as it is (the FE curve's must points are not on a polynomial of this degree:
//! its contact events and mesh steps, `needle fe verify --smooth`).
//!
//! The degree is a parameter ([`depth_floor`]): `needle validate` uses the contract's
//! [`DEGREE`](crate::contract::DEGREE); `needle validate --floor-degree N` asks what a contract of depth degree
//! `N` could reach on the same runs.

use super::contract::{u_of, COMPONENT_COUNT};
use super::lsq::{lstsq, vandermonde};
use super::model::rms_max;
use anyhow::{bail, Result};
use nalgebra::DVector;
use needle_set::results::Row;
use serde::Serialize;

/// The floors of one run (module docs).
#[derive(Debug, Clone, Copy, Serialize, Default, PartialEq)]
pub struct DepthFloor {
    /// Lower bound of the largest |Fy_model - Fy_FE| / |Fy_FE| at depths >= `min_depth_mm`
    /// of any model of the contract's form, % (module docs).
    pub fy_rel_pct: f64,
    /// Per component, the smallest possible RMS error over all depths, in % of the
    /// run's scale (`scale[c]`, as `needle validate`'s RMS %).
    pub rms_pct: [f64; COMPONENT_COUNT],
}

impl DepthFloor {
    /// The largest of the components' RMS floors, %.
    pub fn worst_rms_pct(&self) -> f64 {
        self.rms_pct.iter().copied().fold(0.0, f64::max)
    }
}

/// Lawson iterations of the Table 2 floor (each a `degree + 1`-unknown least squares; the bound
/// reached is within 1e-6 of the minimax error on the test's equioscillating data).
pub const LAWSON_ITERATIONS: usize = 2000;

/// Weighted least-squares residuals `y - p(w)` of the degree-`degree` polynomial
/// minimising `sum (weight_k (y_k - p(w_k)))^2`.
fn residuals(w: &[f64], y: &[f64], weight: &[f64], degree: usize) -> Result<Vec<f64>> {
    let mut a = vandermonde(w, degree);
    for (k, s) in weight.iter().enumerate() {
        a.row_mut(k).scale_mut(*s);
    }
    let b = DVector::from_iterator(y.len(), y.iter().zip(weight).map(|(v, s)| v * s));
    let p = lstsq(&a, &b)?;
    let fitted = vandermonde(w, degree) * p;
    Ok(y.iter().zip(fitted.iter()).map(|(v, f)| v - f).collect())
}

/// The floors of the run with `rows` (depth in mm, wrench in N and N·mm) for models that
/// are polynomials of degree `degree` in depth at a pose (the contract's: [`DEGREE`](crate::contract::DEGREE)),
/// RMS floors in % of `scale` (N, N·mm per component, as `needle validate`), the relative
/// Fy floor over the depths >= `min_depth_mm`.
///
/// # Errors
/// Fewer than `degree + 1` distinct depths overall or at >= `min_depth_mm`; Fy zero at
/// one of the latter (no relative error); a non-finite value.
pub fn depth_floor(rows: &[Row], scale: [f64; COMPONENT_COUNT], min_depth_mm: f64, degree: usize) -> Result<DepthFloor> {
    let u: Vec<f64> = rows.iter().map(|r| u_of(r.depth_mm)).collect();
    let mut rms_pct = [0.0; COMPONENT_COUNT];
    for (c, out) in rms_pct.iter_mut().enumerate() {
        let y: Vec<f64> = rows.iter().map(|r| r.wrench[c]).collect();
        let res = residuals(&u, &y, &vec![1.0; y.len()], degree)?;
        *out = if scale[c] > 0.0 { 100.0 * rms_max(res).0 / scale[c] } else { 0.0 };
    }
    let deep: Vec<&Row> = rows.iter().filter(|r| r.depth_mm >= min_depth_mm - 1e-9).collect();
    if let Some(r) = deep.iter().find(|r| r.fy_n() == 0.0) {
        bail!("depth floor: Fy = 0 at {} mm: no relative error", r.depth_mm);
    }
    let ud: Vec<f64> = deep.iter().map(|r| u_of(r.depth_mm)).collect();
    let fy: Vec<f64> = deep.iter().map(|r| r.fy_n()).collect();
    Ok(DepthFloor { fy_rel_pct: 100.0 * minimax_lower_bound(&ud, &fy, degree)?, rms_pct })
}

/// Lower bound of `min over p of max_k |y_k - p(w_k)| / |y_k|` (module docs: Lawson).
/// The first iteration (equal weights) must solve; a later one that cannot (weights
/// collapsed onto fewer points than unknowns) ends the iteration with the best bound so far.
fn minimax_lower_bound(w: &[f64], y: &[f64], degree: usize) -> Result<f64> {
    let n = y.len() as f64;
    let mut l = vec![1.0 / n; y.len()];
    let mut best = 0.0f64;
    for it in 0..LAWSON_ITERATIONS {
        let weight: Vec<f64> = l.iter().zip(y).map(|(lk, v)| lk.sqrt() / v.abs()).collect();
        let res = match residuals(w, y, &weight, degree) {
            Ok(r) => r,
            Err(e) if it == 0 => return Err(e),
            Err(_) => break,
        };
        let e: Vec<f64> = res.iter().zip(y).map(|(r, v)| (r / v).abs()).collect();
        best = best.max(l.iter().zip(&e).map(|(lk, ek)| lk * ek * ek).sum::<f64>().sqrt());
        let total: f64 = l.iter().zip(&e).map(|(lk, ek)| lk * ek).sum();
        if total <= 0.0 {
            break; // an exact fit: the bound is 0
        }
        for (lk, ek) in l.iter_mut().zip(&e) {
            *lk *= ek / total;
        }
    }
    Ok(best)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contract::DEGREE;
    use needle_contract::FY;

    fn rows(f: impl Fn(f64) -> f64) -> Vec<Row> {
        (0..=20)
            .map(|k| {
                let d = 0.3 * f64::from(k);
                let mut w = [0.0; COMPONENT_COUNT];
                w[FY] = f(d);
                w[0] = 0.5 * f(d);
                Row { depth_mm: d, wrench: w }
            })
            .collect()
    }

    const SCALE: [f64; COMPONENT_COUNT] = [0.07; COMPONENT_COUNT];

    #[test]
    fn a_polynomial_of_the_model_degree_has_no_floor() {
        let f = |d: f64| 1e-3 * d + 2e-3 * d * d - 1e-4 * d.powi(4);
        let fl = depth_floor(&rows(f), SCALE, 1.0, DEGREE).unwrap();
        assert!(fl.fy_rel_pct < 1e-9 && fl.worst_rms_pct() < 1e-9, "{fl:?}");
    }

    #[test]
    fn a_bump_sets_a_floor_that_no_polynomial_beats() {
        let smooth = |d: f64| 2e-3 * d * d;
        let bumped = |d: f64| smooth(d) + if (d - 1.2).abs() < 1e-9 { 6e-4 } else { 0.0 };
        let rs = rows(bumped);
        let fl = depth_floor(&rs, SCALE, 1.0, DEGREE).unwrap();
        // The smooth curve itself is a candidate model: its errors are the bump alone.
        let bump_rel = 100.0 * 6e-4 / bumped(1.2);
        assert!(fl.fy_rel_pct > 0.1 && fl.fy_rel_pct <= bump_rel, "{} vs {bump_rel}", fl.fy_rel_pct);
        // A weighted fit (the first Lawson step) can be checked for optimality directly.
        let bump_rms = 100.0 * (6e-4f64 * 6e-4 / 21.0).sqrt() / SCALE[FY];
        assert!(fl.rms_pct[FY] > 0.0 && fl.rms_pct[FY] <= bump_rms, "{} vs {bump_rms}", fl.rms_pct[FY]);
        // Optimality: moving the fit's polynomial in any coefficient raises the weighted RMS.
        let u: Vec<f64> = rs.iter().filter(|r| r.depth_mm >= 1.0 - 1e-9).map(|r| u_of(r.depth_mm)).collect();
        let fy: Vec<f64> = rs.iter().filter(|r| r.depth_mm >= 1.0 - 1e-9).map(Row::fy_n).collect();
        let wt: Vec<f64> = fy.iter().map(|v| 1.0 / v.abs()).collect();
        let res = residuals(&u, &fy, &wt, DEGREE).unwrap();
        let base: f64 = res.iter().zip(&wt).map(|(e, s)| (e * s).powi(2)).sum();
        for j in 0..=DEGREE {
            for step in [-1e-6, 1e-6] {
                let moved: f64 = res.iter().zip(&u).zip(&wt).map(|((e, w), s)| ((e - step * w.powi(j as i32)) * s).powi(2)).sum();
                assert!(moved > base, "coefficient {j} step {step}: {moved} <= {base}");
            }
        }
    }

    #[test]
    fn the_table2_floor_reaches_the_minimax_error_of_equioscillating_data() {
        // Six depths >= 1 mm, Fy = q / (1 - delta (-1)^k) with q of degree 2: q's relative
        // error is delta (-1)^k, alternating at 6 = DEGREE + 2 points, so by Chebyshev's
        // alternation theorem q is the minimax polynomial and delta the minimax error.
        let delta = 0.03;
        let q = |d: f64| 1e-3 * d + 2e-3 * d * d;
        let deep = [1.2, 2.1, 3.0, 3.9, 4.8, 6.0];
        let mut rs: Vec<Row> = [0.0, 0.3].iter().map(|d| Row { depth_mm: *d, wrench: [q(*d); COMPONENT_COUNT] }).collect();
        for (k, d) in deep.iter().enumerate() {
            let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
            rs.push(Row { depth_mm: *d, wrench: [q(*d) / (1.0 - delta * sign); COMPONENT_COUNT] });
        }
        let fl = depth_floor(&rs, SCALE, 1.0, DEGREE).unwrap();
        let bound = fl.fy_rel_pct / 100.0;
        assert!(bound <= delta * (1.0 + 1e-9), "a lower bound above the minimax error: {bound}");
        assert!(bound >= delta * (1.0 - 1e-6), "Lawson did not reach the minimax error: {bound} vs {delta}");
    }

    #[test]
    fn a_higher_degree_lowers_the_floor_of_a_curve_of_that_degree_to_zero() {
        let f = |d: f64| 1e-3 * d + 2e-3 * d * d + 4e-5 * d.powi(5) + 1e-4 * d.powi(6) / 6.0;
        let contract = depth_floor(&rows(f), SCALE, 1.0, DEGREE).unwrap();
        let sixth = depth_floor(&rows(f), SCALE, 1.0, 6).unwrap();
        assert!(contract.fy_rel_pct > 1e-3 && contract.worst_rms_pct() > 1e-4, "{contract:?}");
        assert!(sixth.fy_rel_pct < 1e-9 && sixth.worst_rms_pct() < 1e-9, "{sixth:?}");
    }

    #[test]
    fn zero_fy_at_depth_is_an_error() {
        let e = depth_floor(&rows(|_| 0.0), SCALE, 1.0, DEGREE).unwrap_err();
        assert!(e.to_string().contains("Fy = 0 at 1.2 mm"), "{e}");
    }
}
