//! The fit of the paper model (coeffs/README.md, "The model"): per sweep and component,
//! a 4th-order polynomial in depth for every sweep value, then each depth coefficient as
//! a 4th-order polynomial in the swept value; then the deviation shift; and the baseline.

use super::contract::{u_of, Sweep, COMPONENTS, DEGREE, NCOEF};
use super::cross_terms::CrossTerms;
use super::data::{FitData, Run, SweepPoint};
use super::lsq::polyfit;
use super::poly::{deviation, horner};
use crate::contract::COMPONENT_COUNT;
use anyhow::{Context, Result};

/// The centre run's polynomial in depth for one component.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Baseline {
    /// `coeffs[i]` multiplies `u^i`, `u = d / 3 - 1` (d in mm); unit of the component.
    pub coeffs: [f64; NCOEF],
    /// RMS of (baseline - centre run) over the centre run's depths, N or N·mm.
    pub residual_rms: f64,
    /// Largest |baseline - centre run|, N or N·mm.
    pub residual_max: f64,
}

/// One deviation matrix `D_kc(t, u)` (zero at t = -1: [`shift`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Deviation {
    /// `rows[i][j]` multiplies `u^i * t^j`; unit of the component.
    pub rows: [[f64; NCOEF]; NCOEF],
    /// RMS of (baseline + deviation) - FE over every depth and value of the sweep's runs
    /// (centre included), N or N·mm.
    pub residual_rms: f64,
    /// Largest |(baseline + deviation) - FE| over the same points, N or N·mm.
    pub residual_max: f64,
}

/// The fitted model in f64, as model.toml stores it (the f32 values are derived by
/// rounding each coefficient to the nearest f32).
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    /// Name of the set (`[set] name` of the campaign).
    pub set: String,
    /// SHA-256 of the FE files fitted (coeffs/README.md).
    pub fe_sha256: String,
    /// Baselines in component order.
    pub baseline: [Baseline; COMPONENT_COUNT],
    /// Deviation matrices, `matrices[k][c]` for sweep k and component c.
    pub matrices: [[Deviation; COMPONENT_COUNT]; 4],
    /// The cross terms of the coupled form (`form = "coupled"`); `None`: the paper form.
    pub cross: Option<Coupled>,
}

/// The coupled form's part of a model: its cross terms and their stated accuracy.
#[derive(Debug, Clone, PartialEq)]
pub struct Coupled {
    /// The cross terms (their size chosen by cross-validation).
    pub terms: CrossTerms,
    /// Training runs they were fitted on.
    pub training_runs: usize,
    /// Cross-validated RMS error of the coupled form per component over the training
    /// runs, % of `scale` ([`super::coupled::cross_validate`]).
    pub cv_rms_pct: [f64; COMPONENT_COUNT],
    /// What the percentages refer to, per component: the training runs' peak |Fy| (N),
    /// times the lever arm for the moments (N*mm).
    pub scale: [f64; COMPONENT_COUNT],
}

/// `+0.0` for a zero of either sign, else `v`: the files never carry `-0.0`.
pub fn no_neg_zero(v: f64) -> f64 {
    if v == 0.0 {
        0.0
    } else {
        v
    }
}

/// RMS and max |e| of a list of errors (0 for an empty list).
pub fn rms_max(errors: impl IntoIterator<Item = f64>) -> (f64, f64) {
    let (mut s, mut n, mut m) = (0.0f64, 0usize, 0.0f64);
    for e in errors {
        s += e * e;
        n += 1;
        m = m.max(e.abs());
    }
    if n == 0 {
        (0.0, 0.0)
    } else {
        ((s / n as f64).sqrt(), m)
    }
}

/// 4th-order fit in u of one component of one run, over all its depth rows.
fn depth_fit(run: &Run, c: usize) -> Result<[f64; NCOEF]> {
    let u: Vec<f64> = run.rows.iter().map(|r| u_of(r.depth_mm)).collect();
    let y: Vec<f64> = run.rows.iter().map(|r| r.wrench[c]).collect();
    let p = polyfit(&u, &y, DEGREE).with_context(|| format!("depth fit of {} in {}", COMPONENTS[c], run.file_name))?;
    Ok(to_array(&p))
}

fn to_array(p: &[f64]) -> [f64; NCOEF] {
    let mut a = [0.0; NCOEF];
    for (d, s) in a.iter_mut().zip(p) {
        *d = *s;
    }
    a
}

/// Fit one deviation matrix: sweep `k`, component `c`, from the sweep's points (centre
/// run at value 0 included). Residuals against `base` + the deviation.
///
/// # Errors
/// A least-squares problem is rank deficient (too few distinct depths or sweep values).
pub fn fit_deviation(k: Sweep, c: usize, points: &[SweepPoint], base: &[f64; NCOEF]) -> Result<Deviation> {
    let mut depth_coeffs = Vec::with_capacity(points.len());
    for p in points {
        depth_coeffs.push(depth_fit(&p.run, c)?);
    }
    let t: Vec<f64> = points.iter().map(|p| k.t_of(p.value)).collect();
    let mut rows = [[0.0; NCOEF]; NCOEF];
    for (i, row) in rows.iter_mut().enumerate() {
        let a_i: Vec<f64> = depth_coeffs.iter().map(|a| a[i]).collect();
        let q = polyfit(&t, &a_i, DEGREE)
            .with_context(|| format!("sweep {}, {}: fit of depth coefficient {i} over the sweep values", k.name(), COMPONENTS[c]))?;
        *row = to_array(&q);
    }
    shift(&mut rows);
    Ok(deviation_of(c, points, base, rows, k))
}

/// The deviation shift (coeffs/README.md, "The model"), so that `D(-1, u) = 0` (sweep
/// value 0) exactly in the contract's f32 evaluation, for every `u`:
///
/// 1. in f64, `rows[i][0] -= sum_j rows[i][j] * (-1)^j` (j = 0..=4 in that order);
/// 2. then `rows[i][0] = -q` with `q` the f32 Horner of the row's other coefficients (their
///    nearest f32) at `t = -1` up to and including the last product,
///    `(((p4*(-1) + p3)*(-1) + p2)*(-1) + p1)*(-1)` ([`f32_row_tail_at_minus_one`]), as
///    step 4 of the f32 evaluation computes it: then `q + p0 = +0.0` in f32, every
///    `r_i(-1)` is `+0.0` and so is `D(-1, u)`. The f64 value is that f32 exactly, so
///    the f64 evaluators and the f32 tables hold the same constant; in f64 the row is
///    then zero at `t = -1` only up to the f32 rounding of its coefficients (step 1 left
///    it within f64 rounding of zero, step 2 moves `rows[i][0]` by less than
///    `2^-21 * sum_j |rows[i][j]|`, the bound `needle-codegen` checks). The fixed-point
///    tables do not use `rows[i][0]`: their `P0` is derived from the other integers.
///
/// A zero of either sign is then written `+0.0`.
pub fn shift(rows: &mut [[f64; NCOEF]; NCOEF]) {
    for row in rows.iter_mut() {
        let mut s = 0.0f64;
        let mut sign = 1.0f64;
        for v in row.iter() {
            s += v * sign;
            sign = -sign;
        }
        row[0] -= s;
        for v in row.iter_mut() {
            *v = no_neg_zero(*v);
        }
        row[0] = no_neg_zero(f64::from(-f32_row_tail_at_minus_one(row)));
    }
}

/// `(((p4*(-1) + p3)*(-1) + p2)*(-1) + p1)*(-1)` in f32 with `p_j` the nearest f32 of
/// `row[j]`, every operation rounded on its own: the contract's f32 Horner of the row at
/// `t = -1` (coeffs/README.md, step 4) before its last addition of `p0`.
pub fn f32_row_tail_at_minus_one(row: &[f64; NCOEF]) -> f32 {
    let p = row.map(|v| v as f32);
    let t = -1.0f32;
    let mut acc = p[4];
    for j in (1..NCOEF - 1).rev() {
        acc = acc * t + p[j];
    }
    acc * t
}

/// The deviation matrix `rows` of sweep `k`, component `c`, with its residuals: (`base`
/// + the deviation) against every depth of the sweep's `points` (centre run included).
pub fn deviation_of(c: usize, points: &[SweepPoint], base: &[f64; NCOEF], rows: [[f64; NCOEF]; NCOEF], k: Sweep) -> Deviation {
    let errors = points.iter().flat_map(|p| {
        let tp = k.t_of(p.value);
        p.run.rows.iter().map(move |r| {
            let u = u_of(r.depth_mm);
            horner(base, u) + deviation(&rows, tp, u) - r.wrench[c]
        })
    });
    let (residual_rms, residual_max) = rms_max(errors);
    Deviation { rows, residual_rms, residual_max }
}

/// Fit the baseline of component `c` to the centre run.
///
/// # Errors
/// The depth fit is rank deficient.
pub fn fit_baseline(centre: &Run, c: usize) -> Result<Baseline> {
    Ok(baseline_of(centre, c, depth_fit(centre, c)?))
}

/// The baseline `coeffs` of component `c` (a zero of either sign written `+0.0`) with its
/// residuals against the centre run.
pub fn baseline_of(centre: &Run, c: usize, mut coeffs: [f64; NCOEF]) -> Baseline {
    for v in coeffs.iter_mut() {
        *v = no_neg_zero(*v);
    }
    let (residual_rms, residual_max) = rms_max(centre.rows.iter().map(|r| horner(&coeffs, u_of(r.depth_mm)) - r.wrench[c]));
    Baseline { coeffs, residual_rms, residual_max }
}

/// Fit the whole model: 6 baselines and 24 deviation matrices.
///
/// # Errors
/// A least-squares problem is rank deficient (the message names sweep, component and
/// stage).
pub fn fit(data: &FitData) -> Result<Model> {
    let mut baseline = [Baseline::default(); COMPONENT_COUNT];
    for (c, b) in baseline.iter_mut().enumerate() {
        *b = fit_baseline(&data.centre, c)?;
    }
    let mut matrices = [[Deviation::default(); COMPONENT_COUNT]; 4];
    for k in Sweep::ALL {
        for c in 0..COMPONENT_COUNT {
            matrices[k.index()][c] = fit_deviation(k, c, &data.sweeps[k.index()], &baseline[c].coeffs)?;
        }
    }
    Ok(Model { set: data.campaign.set.name.clone(), fe_sha256: data.fe_sha256.clone(), baseline, matrices, cross: None })
}
