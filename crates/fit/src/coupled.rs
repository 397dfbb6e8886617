//! The coupled model form (coeffs/README.md, "The coupled form"): the paper's additive
//! superposition plus cross terms, all fitted together on the centre, sweep and
//! combined-pose training runs.
//!
//! `W_c(pose) = B_c(u) + sum_k ±D_kc(t_k, u) + sum_m m(xi, zeta, alpha, beta) * P_cm(u)`:
//! the paper form's baseline and deviation matrices (same file format, same evaluators),
//! with each deviation a polynomial of degree `sweep_degree` (1..=4) in `t_k` instead of
//! the paper's 4, plus the cross monomials `m` of [`super::cross_terms`] (products of
//! powers of at least two of `xi = x / 12 mm`, `zeta = z / 12 mm`,
//! `alpha = theta_x / 15 deg`, `beta = theta_z / 15 deg`, total degree 2 ..= `max_degree`,
//! mirror parities of `c`) times polynomials `P_cm` of degree `depth_degree` in `u`.
//!
//! **Why one joint fit**: the paper form fits each sweep's deviation through that sweep's
//! own runs, a degree-4 polynomial through five or seven values, so the single-run noise
//! of the FE data (`coeffs/default/README.md`) is interpolated and, where a sweep run is
//! missing (theta_x = 15 deg), extrapolated; the cross terms fitted afterwards to what it
//! leaves on the training runs mostly fitted that error back (measured: coeffs/README.md).
//! Here every coefficient is one linear least-squares problem per component (Householder
//! QR, [`lstsq`]) over every depth of every fitted run; a deviation is written in the
//! basis `t^j - (-1)^j` (j >= 1), so it is zero at `t = -1` (sweep value 0) and the
//! paper's shift gives `rows[i][0]` ([`super::model::shift`]: exactly zero there in the
//! f32 evaluation too). The block's mirror symmetries stay exact: a component has a
//! baseline or a deviation only where its parities allow one ([`allowed`]), and cross
//! monomials only of its parities.
//!
//! **The size per component** ([`select`]): k-fold cross-validation over the sweep and
//! training runs (the centre run, the baseline's anchor, is fitted in every fold): the
//! [`Candidate`] with the smallest pooled RMS of that component, ties to the earlier (the
//! smaller) candidate. The file keeps one cross form for all components (the largest
//! chosen degrees); a component's terms outside its own choice are zeros, and its
//! deviation columns above its sweep degree are zeros.

use super::contract::{u_of, Pose64, Sweep, COMPONENTS, DEGREE, DEPTH_MAX_MM, NCOEF};
use super::cross_terms::{mono, monomials, normalised, poly, CrossForm, CrossTerms, Exponents};
use super::data::{FitData, Run};
use super::lsq::lstsq;
use super::model::{baseline_of, deviation_of, shift, Coupled, Model};
use crate::contract::COMPONENT_COUNT;
use crate::eval::float64::{eval_paper, paper_component};
use anyhow::{bail, Context, Result};
use nalgebra::{DMatrix, DVector};

/// One size of the coupled form for one component.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Candidate {
    /// Degree of every deviation in its swept value `t` (1..=4; the paper form's is 4).
    pub sweep_degree: u8,
    /// The cross terms' size, or none.
    pub cross: Option<CrossForm>,
}

impl Candidate {
    /// `sweep/cross/depth` degrees, `-` for no cross terms: `2/-`, `2/3/2`.
    pub fn label(&self) -> String {
        match self.cross {
            Some(f) => format!("{}/{}/{}", self.sweep_degree, f.max_degree, f.depth_degree),
            None => format!("{}/-", self.sweep_degree),
        }
    }
}

/// Cross-term sizes tried: total degree 2..=3 in the pose, 2..=3 in depth. Degree 4 (31
/// monomials for fz and mx) is rank deficient on the training runs a campaign can afford
/// (measured with 17 training runs of the default set) and is left out.
pub const CROSS_FORMS: [CrossForm; 4] = [
    CrossForm { max_degree: 2, depth_degree: 2 },
    CrossForm { max_degree: 2, depth_degree: 3 },
    CrossForm { max_degree: 3, depth_degree: 2 },
    CrossForm { max_degree: 3, depth_degree: 3 },
];

/// Every candidate, smallest first within a sweep degree: sweep degree 1..=4, each
/// without cross terms, then with each of [`CROSS_FORMS`].
pub fn candidates() -> Vec<Candidate> {
    (1..=DEGREE as u8)
        .flat_map(|sweep_degree| {
            std::iter::once(Candidate { sweep_degree, cross: None })
                .chain(CROSS_FORMS.iter().map(move |&f| Candidate { sweep_degree, cross: Some(f) }))
        })
        .collect()
}

/// One component fitted in one candidate's form.
#[derive(Debug, Clone, PartialEq)]
pub struct ComponentFit {
    /// Baseline polynomial in `u`.
    pub baseline: [f64; NCOEF],
    /// Deviation matrix of each sweep (`rows[i][j]` multiplies `u^i t^j`, shifted).
    pub rows: [[[f64; NCOEF]; NCOEF]; 4],
    /// Cross monomials and their polynomials in `u` (empty without cross terms).
    pub cross: Vec<(Exponents, Vec<f64>)>,
}

/// Whether component `c` may have a baseline (`None`) or a deviation along sweep `k`
/// under the block's mirror symmetries. The mirror `x -> -x` flips x and theta_z, the
/// mirror `z -> -z` flips z and theta_x; a deviation along `k` is unchanged by the other
/// mirror, so it is allowed only when `c` is even under that one, and the baseline only
/// when `c` is even under both. The paper form gets these zeros from the FE data (a
/// symmetric run gives exactly 0 there); the joint fit, whose training runs have every
/// component nonzero, must leave the columns out to keep the symmetries exact.
pub fn allowed(c: usize, k: Option<Sweep>) -> bool {
    let odd_x = Sweep::X.is_odd(c);
    let odd_z = Sweep::Z.is_odd(c);
    match k {
        None => !odd_x && !odd_z,
        Some(Sweep::X | Sweep::ThetaZ) => !odd_z,
        Some(Sweep::Z | Sweep::ThetaX) => !odd_x,
    }
}

/// The design row of component `c` at `pose` (module docs): baseline, deviations, cross,
/// each only where [`allowed`].
fn design_row(pose: Pose64, c: usize, cand: Candidate, ms: &[Exponents], out: &mut Vec<f64>) {
    out.clear();
    let u = u_of(pose[4].clamp(0.0, DEPTH_MAX_MM));
    let up: Vec<f64> = (0..NCOEF).map(|i| u.powi(i as i32)).collect();
    if allowed(c, None) {
        out.extend_from_slice(&up);
    }
    for k in Sweep::ALL.into_iter().filter(|&k| allowed(c, Some(k))) {
        let v = pose[k.index()].clamp(-k.half_range(), k.half_range());
        let t = k.t_of(v);
        let s = if v < 0.0 && k.is_odd(c) { -1.0 } else { 1.0 };
        for j in 1..=i32::from(cand.sweep_degree) {
            let b = s * (t.powi(j) - (-1.0f64).powi(j));
            out.extend(up.iter().map(|p| b * p));
        }
    }
    if let Some(f) = cand.cross {
        let (n, u) = normalised(pose);
        for e in ms {
            let m = mono(*e, &n);
            out.extend((0..=i32::from(f.depth_degree)).map(|i| m * u.powi(i)));
        }
    }
}

fn monomials_of(c: usize, cand: Candidate) -> Vec<Exponents> {
    cand.cross.map_or_else(Vec::new, |f| monomials(c, f.max_degree))
}

/// Fit component `c` in the form `cand` by least squares over every depth of `runs`.
///
/// # Errors
/// Fewer equations than unknowns or a rank-deficient design (too few runs for the form);
/// the message names the component and the candidate.
pub fn fit_component(runs: &[&Run], c: usize, cand: Candidate) -> Result<ComponentFit> {
    let ms = monomials_of(c, cand);
    let mut rows: Vec<f64> = Vec::new();
    let mut b: Vec<f64> = Vec::new();
    let mut row = Vec::new();
    for r in runs {
        for fe in &r.rows {
            design_row(r.pose_at(fe.depth_mm), c, cand, &ms, &mut row);
            rows.extend_from_slice(&row);
            b.push(fe.wrench[c]);
        }
    }
    let cols = row.len();
    if cols == 0 {
        // my (odd under both mirrors) without cross terms: zero everywhere.
        return Ok(ComponentFit { baseline: [0.0; NCOEF], rows: [[[0.0; NCOEF]; NCOEF]; 4], cross: Vec::new() });
    }
    let a = DMatrix::from_row_slice(b.len(), cols, &rows);
    let x = lstsq(&a, &DVector::from_vec(b))
        .with_context(|| format!("coupled form {} of {}: {} runs", cand.label(), COMPONENTS[c], runs.len()))?;
    let x = x.as_slice();
    let mut baseline = [0.0; NCOEF];
    let mut at = 0;
    if allowed(c, None) {
        baseline.copy_from_slice(&x[..NCOEF]);
        at = NCOEF;
    }
    let mut dev = [[[0.0; NCOEF]; NCOEF]; 4];
    for (k, rows_k) in Sweep::ALL.into_iter().zip(dev.iter_mut()) {
        if !allowed(c, Some(k)) {
            continue;
        }
        for j in 1..=usize::from(cand.sweep_degree) {
            for (i, r) in rows_k.iter_mut().enumerate() {
                r[j] = x[at + i];
            }
            at += NCOEF;
        }
        shift(rows_k);
    }
    let nd = cand.cross.map_or(0, |f| usize::from(f.depth_degree) + 1);
    let cross = ms.iter().enumerate().map(|(m, e)| (*e, x[at + m * nd..at + (m + 1) * nd].to_vec())).collect();
    Ok(ComponentFit { baseline, rows: dev, cross })
}

/// Component `c` of `f` at `pose` (f64, the contract's algorithm).
pub fn eval_component(f: &ComponentFit, c: usize, pose: Pose64) -> f64 {
    let (n, u) = normalised(pose);
    let clamped = std::array::from_fn(|k| pose[k].clamp(-Sweep::ALL[k].half_range(), Sweep::ALL[k].half_range()));
    let rows = std::array::from_fn(|k| &f.rows[k]);
    paper_component(&f.baseline, rows, c, clamped, u) + f.cross.iter().map(|(e, p)| mono(*e, &n) * poly(p, u)).sum::<f64>()
}

/// Per-component error scales of a set of runs: the largest |Fy| over them (N) for the
/// forces, times `lever_arm_mm` for the moments (as `needle validate` scales errors).
pub fn scales(runs: &[&Run], lever_arm_mm: f64) -> [f64; COMPONENT_COUNT] {
    needle_contract::error_scales(needle_set::results::peak_fy_n(runs.iter().flat_map(|r| r.rows.iter())), lever_arm_mm)
}

/// RMS error per component of `model` over every depth of `runs`, in % of `scale`.
pub fn rms_pct(runs: &[&Run], scale: [f64; COMPONENT_COUNT], model: impl Fn(Pose64) -> [f64; COMPONENT_COUNT]) -> [f64; COMPONENT_COUNT] {
    let mut s = [0.0f64; COMPONENT_COUNT];
    let mut n = 0usize;
    for r in runs {
        for row in &r.rows {
            let w = model(r.pose_at(row.depth_mm));
            for c in 0..COMPONENT_COUNT {
                s[c] += (w[c] - row.wrench[c]).powi(2);
            }
            n += 1;
        }
    }
    std::array::from_fn(|c| if n == 0 || scale[c] == 0.0 { 0.0 } else { 100.0 * (s[c] / n as f64).sqrt() / scale[c] })
}

/// The runs of a fit: the centre run (in every fold) and the pool the folds split.
#[derive(Debug, Clone)]
pub struct FitRuns<'a> {
    /// The centre run.
    pub centre: &'a Run,
    /// The sweep runs (in sweep order, values ascending), then the training runs.
    pub pool: Vec<&'a Run>,
}

impl<'a> FitRuns<'a> {
    /// The centre and sweep runs of `data` and the training runs `train`.
    pub fn new(data: &'a FitData, train: &[&'a Run]) -> Self {
        let sweeps = data.sweeps.iter().flat_map(|pts| pts.iter().filter(|p| p.value != 0.0).map(|p| &p.run));
        FitRuns { centre: &data.centre, pool: sweeps.chain(train.iter().copied()).collect() }
    }

    fn all(&self) -> Vec<&'a Run> {
        std::iter::once(self.centre).chain(self.pool.iter().copied()).collect()
    }
}

/// One candidate of the cross-validation.
#[derive(Debug, Clone, PartialEq)]
pub struct CvScore {
    /// The candidate.
    pub candidate: Candidate,
    /// Cross-validated RMS error per component, % of the scale ([`scales`]); `None` for a
    /// component whose fit failed in some fold (the first reason in `failure`).
    pub rms_pct: [Option<f64>; COMPONENT_COUNT],
    /// Why a fold could not be fitted.
    pub failure: Option<String>,
}

/// Number of folds of the cross-validation (fewer when there are fewer runs).
pub const FOLDS: usize = 8;

/// k-fold cross-validation of `cand`: pool run `i` is in fold `i % k`; each fold is
/// predicted by the form fitted on the centre run and the other folds; errors pooled over
/// every held-out depth.
pub fn cross_validate(runs: &FitRuns, cand: Candidate, scale: [f64; COMPONENT_COUNT]) -> CvScore {
    let k = FOLDS.min(runs.pool.len()).max(1);
    let mut rms_pct = [None; COMPONENT_COUNT];
    let mut failure = None;
    for (c, out) in rms_pct.iter_mut().enumerate() {
        let (mut s, mut n) = (0.0f64, 0usize);
        let mut ok = true;
        for fold in 0..k {
            let fit_on: Vec<&Run> =
                std::iter::once(runs.centre).chain(runs.pool.iter().enumerate().filter(|(i, _)| i % k != fold).map(|(_, r)| *r)).collect();
            let f = match fit_component(&fit_on, c, cand) {
                Ok(f) => f,
                Err(e) => {
                    failure.get_or_insert_with(|| format!("fold {}: {e:#}", fold + 1));
                    ok = false;
                    break;
                }
            };
            for r in runs.pool.iter().enumerate().filter(|(i, _)| i % k == fold).map(|(_, r)| *r) {
                for row in &r.rows {
                    s += (eval_component(&f, c, r.pose_at(row.depth_mm)) - row.wrench[c]).powi(2);
                    n += 1;
                }
            }
        }
        if ok && n > 0 && scale[c] > 0.0 {
            *out = Some(100.0 * (s / n as f64).sqrt() / scale[c]);
        }
    }
    CvScore { candidate: cand, rms_pct, failure }
}

/// What cross-validation chose for each component.
pub type Choices = [Candidate; COMPONENT_COUNT];

/// The outcome of [`select`].
#[derive(Debug, Clone, PartialEq)]
pub struct Selection {
    /// Per component: the chosen candidate.
    pub choices: Choices,
    /// Per component: the chosen candidate's cross-validated RMS, % of the scale.
    pub rms_pct: [f64; COMPONENT_COUNT],
    /// Every candidate's cross-validation, in [`candidates`] order.
    pub cv: Vec<CvScore>,
    /// The paper form's RMS on the training runs per component, % of the scale (out of
    /// sample: the paper form is fitted on the sweeps only); a reference, not a candidate.
    pub paper_rms_pct: [f64; COMPONENT_COUNT],
}

/// Cross-validate every candidate and choose per component the one with the smallest
/// error (ties to the earlier, smaller one).
///
/// # Errors
/// Fewer than 2 training runs; no candidate could be fitted for some component.
pub fn select(paper: &Model, runs: &FitRuns, train: &[&Run], scale: [f64; COMPONENT_COUNT]) -> Result<Selection> {
    if train.len() < 2 {
        bail!("the coupled form needs training runs (role train): {} found", train.len());
    }
    let cv: Vec<CvScore> = candidates().into_iter().map(|cand| cross_validate(runs, cand, scale)).collect();
    let mut choices: Choices = [Candidate { sweep_degree: 1, cross: None }; COMPONENT_COUNT];
    let mut rms = [f64::INFINITY; COMPONENT_COUNT];
    for c in 0..COMPONENT_COUNT {
        for score in &cv {
            if let Some(e) = score.rms_pct[c] {
                if e < rms[c] {
                    rms[c] = e;
                    choices[c] = score.candidate;
                }
            }
        }
        if !rms[c].is_finite() {
            bail!(
                "no coupled form of {} could be fitted on {} runs: {}",
                COMPONENTS[c],
                runs.pool.len() + 1,
                cv.iter().filter_map(|s| s.failure.clone()).collect::<Vec<_>>().join("; ")
            );
        }
    }
    let paper_rms_pct = rms_pct(train, scale, |p| eval_paper(paper, p).0);
    Ok(Selection { choices, rms_pct: rms, cv, paper_rms_pct })
}

/// The cross form the file holds for `choices`: the largest chosen degrees (the smallest
/// form when no component has cross terms).
pub fn file_form(choices: &Choices) -> CrossForm {
    let chosen = choices.iter().filter_map(|c| c.cross);
    match (chosen.clone().map(|f| f.max_degree).max(), chosen.map(|f| f.depth_degree).max()) {
        (Some(max_degree), Some(depth_degree)) => CrossForm { max_degree, depth_degree },
        _ => CROSS_FORMS[0],
    }
}

/// The coupled model of `choices` fitted on all of `runs`: baseline and deviations with
/// their residuals (against the centre and sweep runs of `data`, as the paper form's),
/// and the cross terms written in [`file_form`] with zeros outside each component's
/// choice. `set`, `fe_sha256` and the stated accuracy come from the caller.
///
/// # Errors
/// As [`fit_component`].
pub fn fit_chosen(data: &FitData, runs: &FitRuns, choices: &Choices) -> Result<(Model, CrossTerms)> {
    let all = runs.all();
    let form = file_form(choices);
    let nd = usize::from(form.depth_degree) + 1;
    let mut model =
        Model { set: String::new(), fe_sha256: String::new(), baseline: Default::default(), matrices: Default::default(), cross: None };
    let mut terms: [Vec<(Exponents, Vec<f64>)>; COMPONENT_COUNT] = Default::default();
    for c in 0..COMPONENT_COUNT {
        let f = fit_component(&all, c, choices[c])?;
        model.baseline[c] = baseline_of(&data.centre, c, f.baseline);
        for k in Sweep::ALL {
            model.matrices[k.index()][c] = deviation_of(c, &data.sweeps[k.index()], &model.baseline[c].coeffs, f.rows[k.index()], k);
        }
        terms[c] = monomials(c, form.max_degree)
            .into_iter()
            .map(|e| {
                let mut p = vec![0.0; nd];
                if let Some((_, q)) = f.cross.iter().find(|(m, _)| *m == e) {
                    for (dst, v) in p.iter_mut().zip(q) {
                        *dst = super::model::no_neg_zero(*v);
                    }
                }
                (e, p)
            })
            .collect();
    }
    Ok((model, CrossTerms { form, terms }))
}

/// [`select`], then [`fit_chosen`] on all the runs: the model (its `cross` set, stated
/// accuracy = the chosen candidates' cross-validated errors) and the selection.
///
/// # Errors
/// As [`select`] and [`fit_chosen`].
pub fn select_and_fit(paper: &Model, data: &FitData, train: &[&Run], scale: [f64; COMPONENT_COUNT]) -> Result<(Selection, Model)> {
    let runs = FitRuns::new(data, train);
    let selection = select(paper, &runs, train, scale)?;
    let (mut model, terms) = fit_chosen(data, &runs, &selection.choices)?;
    model.set = paper.set.clone();
    model.fe_sha256 = paper.fe_sha256.clone();
    model.cross = Some(Coupled { terms, training_runs: train.len(), cv_rms_pct: selection.rms_pct, scale });
    Ok((selection, model))
}

/// The coupled model of `data` (its training runs all fitted), `paper` being its paper
/// form (for the set's name, the FE hash and the reference row).
///
/// # Errors
/// Fewer than 2 training runs, or no candidate can be fitted on them.
pub fn fit_coupled(data: &FitData, paper: &Model, lever_arm_mm: f64) -> Result<Model> {
    let train: Vec<&Run> = data.train.iter().collect();
    let scale = scales(&train, lever_arm_mm);
    Ok(select_and_fit(paper, data, &train, scale)?.1)
}
