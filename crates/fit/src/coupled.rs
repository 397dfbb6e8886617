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
//! them). The size is chosen *per component* by k-fold cross-validation over the
//! training runs ([`select`]): each component takes the candidate `(max_degree,
//! depth_degree)` with the smallest cross-validated error, or no cross terms at all when
//! the paper form alone does better on the training runs (its error there is out of
//! sample too: the paper part is fitted on the sweeps). The file keeps one form for all
//! components (the largest chosen degrees); a component's terms outside its own choice
//! are written as zeros ([`fit_chosen`]).

use super::contract::{Pose64, COMPONENTS};
use super::cross_terms::{mono, monomials, normalised, CrossForm, CrossTerms, Exponents, CANDIDATES};
use super::data::Run;
use super::eval_f64::{eval_paper, eval_with_cross};
use super::lsq::lstsq;
use super::model::{Coupled, Model};
use crate::contract::COMPONENT_COUNT;
use anyhow::{bail, Context, Result};
use nalgebra::{DMatrix, DVector};

/// Fit the cross terms of size `form` to `FE - paper` over every depth of `runs`.
///
/// # Errors
/// Fewer equations than unknowns or a rank-deficient design (too few training runs for
/// the form); the message names the component.
pub fn fit(paper: &Model, runs: &[&Run], form: CrossForm) -> Result<CrossTerms> {
    let mut terms: [Vec<(Exponents, Vec<f64>)>; COMPONENT_COUNT] = Default::default();
    let nd = usize::from(form.depth_degree) + 1;
    for (c, out) in terms.iter_mut().enumerate() {
        let ms = monomials(c, form.max_degree);
        if ms.is_empty() {
            // No monomial of this degree has the component's mirror parities (fx, mz at
            // degree 2): it gets no cross terms in this form, the others are still fitted.
            continue;
        }
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
pub fn scales(runs: &[&Run], lever_arm_mm: f64) -> [f64; COMPONENT_COUNT] {
    needle_contract::error_scales(needle_fe::results::peak_fy_n(runs.iter().flat_map(|r| r.rows.iter())), lever_arm_mm)
}

/// RMS error per component of `model` over every depth of `runs`, in % of `scale`.
pub fn rms_pct(runs: &[&Run], scale: [f64; COMPONENT_COUNT], model: impl Fn(Pose64) -> [f64; COMPONENT_COUNT]) -> [f64; COMPONENT_COUNT] {
    let mut s = [0.0f64; COMPONENT_COUNT];
    let mut n = 0usize;
    for r in runs {
        let p = &r.pose;
        for row in &r.rows {
            let w = model([p.x_mm, p.z_mm, p.theta_x_deg, p.theta_z_deg, row.depth_mm]);
            for c in 0..COMPONENT_COUNT {
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
    pub rms_pct: Option<[f64; COMPONENT_COUNT]>,
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
pub fn cross_validate(paper: &Model, runs: &[&Run], form: CrossForm, scale: [f64; COMPONENT_COUNT]) -> CvScore {
    let k = FOLDS.min(runs.len());
    let mut s = [0.0f64; COMPONENT_COUNT];
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
                for c in 0..COMPONENT_COUNT {
                    s[c] += (w[c] - row.wrench[c]).powi(2);
                }
                n += 1;
            }
        }
    }
    let rms = std::array::from_fn(|c| if n == 0 || scale[c] == 0.0 { 0.0 } else { 100.0 * (s[c] / n as f64).sqrt() / scale[c] });
    CvScore { form, rms_pct: Some(rms), failure: None }
}

/// What cross-validation chose for each component: a candidate, or `None` for no cross
/// terms (the paper form alone).
pub type Choices = [Option<CrossForm>; COMPONENT_COUNT];

/// The outcome of [`select`]: the choice and score of each component, every
/// candidate's cross-validation and the paper form's error on the training runs.
#[derive(Debug, Clone, PartialEq)]
pub struct Selection {
    /// Per component: the chosen candidate, or `None` (no cross terms).
    pub choices: Choices,
    /// Per component: the chosen candidate's cross-validated RMS (or the paper form's
    /// error), % of the scale.
    pub rms_pct: [f64; COMPONENT_COUNT],
    /// Every candidate's cross-validation.
    pub cv: Vec<CvScore>,
    /// The paper form's RMS on the training runs per component, % of the scale.
    pub paper_rms_pct: [f64; COMPONENT_COUNT],
}

/// Cross-validate every candidate and choose per component (module docs): the candidate
/// with the smallest cross-validated RMS of that component, if it is below the paper
/// form's error on the training runs; ties go to the fewer coefficients (the earlier
/// candidate) and to no cross terms.
///
/// # Errors
/// Fewer than 2 training runs, or no candidate could be fitted (too few training runs).
pub fn select(paper: &Model, runs: &[&Run], scale: [f64; COMPONENT_COUNT]) -> Result<Selection> {
    if runs.len() < 2 {
        bail!("the coupled form needs training runs (role train): {} found", runs.len());
    }
    let cv: Vec<CvScore> = CANDIDATES.iter().map(|&f| cross_validate(paper, runs, f, scale)).collect();
    if cv.iter().all(|s| s.rms_pct.is_none()) {
        bail!(
            "no coupled form could be fitted on {} training runs: {}",
            runs.len(),
            cv.iter().filter_map(|s| s.failure.clone()).collect::<Vec<_>>().join("; ")
        );
    }
    let paper_rms_pct = rms_pct(runs, scale, |p| eval_paper(paper, p).0);
    let mut choices: Choices = [None; COMPONENT_COUNT];
    let mut chosen_rms = paper_rms_pct;
    for c in 0..COMPONENT_COUNT {
        for score in &cv {
            // A form without monomials for this component adds nothing to it.
            if monomials(c, score.form.max_degree).is_empty() {
                continue;
            }
            if let Some(e) = score.rms_pct {
                if e[c] < chosen_rms[c] {
                    chosen_rms[c] = e[c];
                    choices[c] = Some(score.form);
                }
            }
        }
    }
    Ok(Selection { choices, rms_pct: chosen_rms, cv, paper_rms_pct })
}

/// The form the file holds for `choices`: the largest chosen degrees (the smallest
/// candidate when no component has cross terms).
pub fn file_form(choices: &Choices) -> CrossForm {
    let chosen = choices.iter().flatten();
    match (chosen.clone().map(|f| f.max_degree).max(), chosen.map(|f| f.depth_degree).max()) {
        (Some(max_degree), Some(depth_degree)) => CrossForm { max_degree, depth_degree },
        _ => CANDIDATES[0],
    }
}

/// The cross terms of `choices` fitted on `runs`: each component's terms fitted in its
/// chosen form ([`fit`]), written in [`file_form`] with zeros for the monomials and
/// depth powers outside its choice (all zeros for a component without cross terms).
///
/// # Errors
/// As [`fit`].
pub fn fit_chosen(paper: &Model, runs: &[&Run], choices: &Choices) -> Result<CrossTerms> {
    let form = file_form(choices);
    let nd = usize::from(form.depth_degree) + 1;
    // Each chosen form fitted once (a `CrossTerms` knows its form).
    let mut fitted: Vec<CrossTerms> = Vec::new();
    for &f in choices.iter().flatten() {
        if !fitted.iter().any(|t| t.form == f) {
            fitted.push(fit(paper, runs, f)?);
        }
    }
    let mut terms: [Vec<(Exponents, Vec<f64>)>; COMPONENT_COUNT] = Default::default();
    for (c, out) in terms.iter_mut().enumerate() {
        let own: &[(Exponents, Vec<f64>)] =
            choices[c].and_then(|f| fitted.iter().find(|t| t.form == f)).map_or(&[], |t| t.terms[c].as_slice());
        *out = monomials(c, form.max_degree)
            .into_iter()
            .map(|e| {
                let mut p = vec![0.0; nd];
                if let Some((_, q)) = own.iter().find(|(m, _)| *m == e) {
                    for (dst, v) in p.iter_mut().zip(q) {
                        *dst = *v;
                    }
                }
                (e, p)
            })
            .collect();
    }
    Ok(CrossTerms { form, terms })
}

/// [`select`] on `runs`, then [`fit_chosen`] on all of them.
///
/// # Errors
/// As [`select`] and [`fit`].
pub fn select_and_fit(paper: &Model, runs: &[&Run], scale: [f64; COMPONENT_COUNT]) -> Result<(Selection, CrossTerms)> {
    let selection = select(paper, runs, scale)?;
    let terms = fit_chosen(paper, runs, &selection.choices)?;
    Ok((selection, terms))
}

/// The coupled form's part of the model: the sizes chosen by [`select`] on `train`, the
/// cross terms fitted on all of `train` ([`fit_chosen`]) and each component's
/// cross-validated error (the paper form's, for a component without cross terms).
///
/// # Errors
/// Fewer than 2 training runs, or no candidate can be fitted on them.
pub fn fit_coupled(paper: &Model, train: &[Run], lever_arm_mm: f64) -> Result<Coupled> {
    let runs: Vec<&Run> = train.iter().collect();
    let scale = scales(&runs, lever_arm_mm);
    let (selection, terms) = select_and_fit(paper, &runs, scale)?;
    Ok(Coupled { terms, training_runs: runs.len(), cv_rms_pct: selection.rms_pct, scale })
}
