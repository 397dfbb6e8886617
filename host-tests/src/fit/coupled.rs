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
//! The monomials and their mirror parities: [`super::cross_terms`].
//!
//! The paper part is the sweep fit as it is ([`super::model::fit`]); the cross terms are
//! fitted by least squares ([`lstsq`], QR) to what it leaves, `FE - paper`, over every
//! depth of the training runs (sweep runs add nothing: every cross monomial is zero on
//! them). `max_degree` and `depth_degree` are chosen by k-fold cross-validation over the
//! training runs ([`select`]).

use super::contract::{Pose64, COMPONENTS};
use super::cross_terms::{mono, monomials, normalised, CrossForm, CrossTerms, Exponents, CANDIDATES};
use super::data::Run;
use super::eval_f64::{eval_paper, eval_with_cross};
use super::lsq::lstsq;
use super::model::{Coupled, Model};
use anyhow::{bail, Context, Result};
use nalgebra::{DMatrix, DVector};

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
                let w = eval_with_cross(paper, &t, [p.x_mm, p.z_mm, p.theta_x_deg, p.theta_z_deg, row.depth_mm]).0;
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
    let best = scores.iter().filter(|s| s.rms_pct.is_some()).min_by(|a, b| a.worst().total_cmp(&b.worst())).map(|s| s.form);
    match best {
        Some(f) => Ok((f, scores)),
        None => bail!(
            "no coupled form could be fitted on {} training runs: {}",
            runs.len(),
            scores.iter().filter_map(|s| s.failure.clone()).collect::<Vec<_>>().join("; ")
        ),
    }
}

/// [`select`] on `runs`, then [`fit`] the chosen form on all of them: the chosen score,
/// every candidate's score and the cross terms.
///
/// # Errors
/// As [`select`] and [`fit`].
pub fn select_and_fit(paper: &Model, runs: &[&Run], scale: [f64; 6]) -> Result<([f64; 6], Vec<CvScore>, CrossTerms)> {
    let (form, cv) = select(paper, runs, scale)?;
    let terms = fit(paper, runs, form)?;
    let chosen = cv.iter().find(|s| s.form == form).and_then(|s| s.rms_pct).context("the chosen form has a score")?;
    Ok((chosen, cv, terms))
}

/// The coupled form's part of the model: the size chosen by [`select`] on `train`, its
/// cross terms fitted on all of `train` ([`fit`]) and its cross-validated error.
///
/// # Errors
/// Fewer than 2 training runs, or no candidate can be fitted on them.
pub fn fit_coupled(paper: &Model, train: &[Run], lever_arm_mm: f64) -> Result<Coupled> {
    let runs: Vec<&Run> = train.iter().collect();
    let scale = scales(&runs, lever_arm_mm);
    let (cv_rms_pct, _, terms) = select_and_fit(paper, &runs, scale)?;
    Ok(Coupled { terms, training_runs: runs.len(), cv_rms_pct, scale })
}
