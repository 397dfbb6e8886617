//! The coupled model form (coeffs/README.md, "The coupled form"): the paper's additive
//! superposition plus cross terms fitted on the combined-pose training runs.
//!
//! `W_c(pose) = paper_c(pose) + sum_m  m(xi, zeta, alpha, beta) * P_cm(u)` where
//! `xi = x / 12 mm`, `zeta = z / 12 mm`, `alpha = theta_x / 15 deg`,
//! `beta = theta_z / 15 deg` (signed, after the paper form's clamping to the domain),
//! `u = d / 3 - 1`, `m` runs over the cross monomials of component `c` (products of
//! powers of at least two inputs, total degree 2 ..= `max_degree`) and `P_cm` is a
//! polynomial in `u` of degree `depth_degree`.
//!
//! **Mirror symmetries, exact by construction**: the mirror `x -> -x` maps
//! `(xi, beta) -> (-xi, -beta)` and flips fx, my, mz; the mirror `z -> -z` maps
//! `(zeta, alpha) -> (-zeta, -alpha)` and flips fz, mx, my ([`Sweep::is_odd`]). A
//! monomial of component `c` is kept only when its degree in `(xi, beta)` is odd exactly
//! when `c` is odd under the first mirror, and its degree in `(zeta, alpha)` likewise
//! under the second; every kept term then has `c`'s parities, for every coefficient value.
//!
//! The paper part is the sweep fit as it is ([`super::model::fit`]); the cross terms are
//! fitted by least squares ([`lstsq`], QR) to what it leaves, `FE - paper`, over every
//! depth of the training runs (sweep runs add nothing: every cross monomial is zero on
//! them). `max_degree` and `depth_degree` are chosen by k-fold cross-validation over the
//! training runs ([`select`]).

use super::contract::{u_of, Sweep, COMPONENTS};
use super::data::Run;
use super::eval_f64::{eval as eval_paper, Pose64};
use super::lsq::lstsq;
use super::model::Model;
use anyhow::{bail, Context, Result};
use nalgebra::{DMatrix, DVector};

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

/// The candidates of the cross-validation: total degree 2..=4 in the pose, 2..=4 in depth.
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
    pub terms: [Vec<(Exponents, Vec<f64>)>; 6],
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
fn normalised(pose: Pose64) -> ([f64; 4], f64) {
    if pose.iter().any(|v| !v.is_finite()) {
        return ([0.0; 4], 0.0);
    }
    let n: [f64; 4] = std::array::from_fn(|i| {
        let m = Sweep::ALL[i].half_range();
        pose[i].clamp(-m, m) / m
    });
    (n, u_of(pose[4].clamp(0.0, super::contract::DEPTH_MAX_MM)))
}

fn mono(e: Exponents, n: &[f64; 4]) -> f64 {
    e.iter().zip(n).map(|(&k, v)| v.powi(i32::from(k))).product()
}

fn poly(coeffs: &[f64], u: f64) -> f64 {
    coeffs.iter().rev().fold(0.0, |acc, c| acc * u + c)
}

/// The cross terms' contribution to each component at `pose` (f64).
pub fn cross_value(t: &CrossTerms, pose: Pose64) -> [f64; 6] {
    let (n, u) = normalised(pose);
    std::array::from_fn(|c| t.terms[c].iter().map(|(e, p)| mono(*e, &n) * poly(p, u)).sum())
}

/// The coupled model at `pose`: the paper form's wrench and status plus the cross terms.
pub fn eval(paper: &Model, t: &CrossTerms, pose: Pose64) -> ([f64; 6], u8) {
    let (mut w, status) = eval_paper(paper, pose);
    if status & super::contract::STATUS_ERROR == 0 {
        let x = cross_value(t, pose);
        for (a, b) in w.iter_mut().zip(x) {
            *a += b;
        }
    }
    (w, status)
}

/// Fit the cross terms of size `form` to `FE - paper` over every depth of `runs`.
///
/// # Errors
/// Fewer equations than unknowns or a rank-deficient design (too few training runs for
/// the form); the message names the component.
pub fn fit(paper: &Model, runs: &[&Run], form: CrossForm) -> Result<CrossTerms> {
    let mut terms: [Vec<(Exponents, Vec<f64>)>; 6] = Default::default();
    let nd = usize::from(form.depth_degree) + 1;
    for (c, out) in terms.iter_mut().enumerate() {
        let ms = monomials(c, form.max_degree);
        let rows: Vec<(Pose64, f64)> = runs
            .iter()
            .flat_map(|r| {
                let p = &r.pose;
                r.rows.iter().map(move |row| {
                    let pose = [p.x_mm, p.z_mm, p.theta_x_deg, p.theta_z_deg, row.depth_mm];
                    (pose, row.wrench[c] - eval_paper(paper, pose).0[c])
                })
            })
            .collect();
        let cols = ms.len() * nd;
        let a = DMatrix::from_fn(rows.len(), cols, |i, j| {
            let (n, u) = normalised(rows[i].0);
            mono(ms[j / nd], &n) * u.powi((j % nd) as i32)
        });
        let b = DVector::from_iterator(rows.len(), rows.iter().map(|r| r.1));
        let x = lstsq(&a, &b).with_context(|| {
            format!(
                "coupled form (cross degree {}, depth degree {}), {}: {} training runs",
                form.max_degree,
                form.depth_degree,
                COMPONENTS[c],
                runs.len()
            )
        })?;
        *out = ms.iter().enumerate().map(|(m, e)| (*e, x.as_slice()[m * nd..(m + 1) * nd].to_vec())).collect();
    }
    Ok(CrossTerms { form, terms })
}

/// Per-component error scales of a set of runs: the largest |Fy| over them (N) for the
/// forces, times `lever_arm_mm` for the moments (as `needle validate` scales errors).
pub fn scales(runs: &[&Run], lever_arm_mm: f64) -> [f64; 6] {
    let peak = runs.iter().flat_map(|r| r.rows.iter()).map(|r| r.wrench[1].abs()).fold(0.0, f64::max);
    std::array::from_fn(|c| if c < 3 { peak } else { peak * lever_arm_mm })
}

/// RMS error per component of `model` over every depth of `runs`, in % of `scale`.
pub fn rms_pct(runs: &[&Run], scale: [f64; 6], model: impl Fn(Pose64) -> [f64; 6]) -> [f64; 6] {
    let mut s = [0.0f64; 6];
    let mut n = 0usize;
    for r in runs {
        let p = &r.pose;
        for row in &r.rows {
            let w = model([p.x_mm, p.z_mm, p.theta_x_deg, p.theta_z_deg, row.depth_mm]);
            for c in 0..6 {
                s[c] += (w[c] - row.wrench[c]).powi(2);
            }
            n += 1;
        }
    }
    std::array::from_fn(|c| if n == 0 || scale[c] == 0.0 { 0.0 } else { 100.0 * (s[c] / n as f64).sqrt() / scale[c] })
}

/// One candidate of the cross-validation.
#[derive(Debug, Clone, PartialEq)]
pub struct CvScore {
    /// The candidate.
    pub form: CrossForm,
    /// Cross-validated RMS error per component, % of the scale ([`scales`]); `None`
    /// when a fold could not be fitted (the reason in `failure`).
    pub rms_pct: Option<[f64; 6]>,
    /// Why a fold could not be fitted.
    pub failure: Option<String>,
}

impl CvScore {
    /// The worst component's cross-validated RMS, % (infinite when it failed).
    pub fn worst(&self) -> f64 {
        self.rms_pct.map_or(f64::INFINITY, |e| e.iter().copied().fold(0.0, f64::max))
    }
}

/// Number of folds of the cross-validation (fewer when there are fewer runs).
pub const FOLDS: usize = 8;

/// k-fold cross-validation of `form`: training run `i` is in fold `i % k`; each fold is
/// predicted by the cross terms fitted on the others; errors pooled over every held-out
/// depth.
pub fn cross_validate(paper: &Model, runs: &[&Run], form: CrossForm, scale: [f64; 6]) -> CvScore {
    let k = FOLDS.min(runs.len());
    let mut s = [0.0f64; 6];
    let mut n = 0usize;
    for fold in 0..k {
        let train: Vec<&Run> = runs.iter().enumerate().filter(|(i, _)| i % k != fold).map(|(_, r)| *r).collect();
        let held: Vec<&Run> = runs.iter().enumerate().filter(|(i, _)| i % k == fold).map(|(_, r)| *r).collect();
        let t = match fit(paper, &train, form) {
            Ok(t) => t,
            Err(e) => return CvScore { form, rms_pct: None, failure: Some(format!("fold {}: {e:#}", fold + 1)) },
        };
        for r in &held {
            let p = &r.pose;
            for row in &r.rows {
                let w = eval(paper, &t, [p.x_mm, p.z_mm, p.theta_x_deg, p.theta_z_deg, row.depth_mm]).0;
                for c in 0..6 {
                    s[c] += (w[c] - row.wrench[c]).powi(2);
                }
                n += 1;
            }
        }
    }
    let rms = std::array::from_fn(|c| if n == 0 || scale[c] == 0.0 { 0.0 } else { 100.0 * (s[c] / n as f64).sqrt() / scale[c] });
    CvScore { form, rms_pct: Some(rms), failure: None }
}

/// Cross-validate every candidate and pick the one with the smallest worst-component
/// error (ties: the fewer coefficients, i.e. the earlier candidate).
///
/// # Errors
/// No candidate could be fitted (too few training runs).
pub fn select(paper: &Model, runs: &[&Run], scale: [f64; 6]) -> Result<(CrossForm, Vec<CvScore>)> {
    if runs.len() < 2 {
        bail!("the coupled form needs training runs (role train): {} found", runs.len());
    }
    let scores: Vec<CvScore> = CANDIDATES.iter().map(|&f| cross_validate(paper, runs, f, scale)).collect();
    let best = scores
        .iter()
        .filter(|s| s.rms_pct.is_some())
        .min_by(|a, b| a.worst().total_cmp(&b.worst()))
        .map(|s| s.form);
    match best {
        Some(f) => Ok((f, scores)),
        None => bail!(
            "no coupled form could be fitted on {} training runs: {}",
            runs.len(),
            scores.iter().filter_map(|s| s.failure.clone()).collect::<Vec<_>>().join("; ")
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every monomial flips exactly like its component under both mirrors.
    #[test]
    fn monomials_keep_the_mirror_symmetries() {
        let n = [0.3, -0.7, 0.45, 0.9];
        let mx = [-n[0], n[1], n[2], -n[3]];
        let mz = [n[0], -n[1], -n[2], n[3]];
        for c in 0..6 {
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
