//! The contract's evaluation algorithm (coeffs/README.md) in f64 on the f64 coefficients:
//! the reference for validation and for the f32 evaluator's error.

use crate::contract::COMPONENT_COUNT;
use crate::contract::{
    u_of, Sweep, DEPTH_MAX_MM, NCOEF, STATUS_ERROR, STATUS_SAT_DEPTH, STATUS_SAT_THETA_X, STATUS_SAT_THETA_Z, STATUS_SAT_X, STATUS_SAT_Z,
};
use crate::cross_terms::{cross_value, CrossTerms};
use crate::model::Model;

pub use crate::poly::{deviation, horner};

pub use crate::contract::Pose64;

/// Evaluate the model at `pose`, in its form: the paper part ([`eval_paper`]) plus, for
/// the coupled form, its cross terms ([`eval_with_cross`]).
pub fn eval(model: &Model, pose: Pose64) -> ([f64; COMPONENT_COUNT], u8) {
    match &model.cross {
        Some(c) => eval_with_cross(model, &c.terms, pose),
        None => eval_paper(model, pose),
    }
}

/// The paper part of `paper` at `pose` plus the cross terms `t` ([`cross_value`]), unless
/// the status is an error.
pub fn eval_with_cross(paper: &Model, t: &CrossTerms, pose: Pose64) -> ([f64; COMPONENT_COUNT], u8) {
    let (mut w, status) = eval_paper(paper, pose);
    if status & STATUS_ERROR == 0 {
        for (a, b) in w.iter_mut().zip(cross_value(t, pose)) {
            *a += b;
        }
    }
    (w, status)
}

/// Evaluate the paper part of the model at `pose` (all of it for the paper form): the wrench `[fx_n, fy_n, fz_n, mx_nmm, my_nmm, mz_nmm]`
/// (N, N·mm) and the contract's status byte. NaN or infinite input gives the zero wrench
/// and status 0x80; inputs outside the domain are clamped and flagged.
pub fn eval_paper(model: &Model, pose: Pose64) -> ([f64; COMPONENT_COUNT], u8) {
    if pose.iter().any(|v| !v.is_finite()) {
        return ([0.0; COMPONENT_COUNT], STATUS_ERROR);
    }
    let mut status = 0u8;
    let mut clamped = [0.0f64; 4];
    let bits = [STATUS_SAT_X, STATUS_SAT_Z, STATUS_SAT_THETA_X, STATUS_SAT_THETA_Z];
    for k in Sweep::ALL {
        let i = k.index();
        let m = k.half_range();
        let v = pose[i].clamp(-m, m);
        if v != pose[i] {
            status |= bits[i];
        }
        clamped[i] = v;
    }
    let d = pose[4].clamp(0.0, DEPTH_MAX_MM);
    if d != pose[4] {
        status |= STATUS_SAT_DEPTH;
    }
    let u = u_of(d);
    let w = std::array::from_fn(|c| {
        let rows = std::array::from_fn(|k| &model.matrices[k][c].rows);
        paper_component(&model.baseline[c].coeffs, rows, c, clamped, u)
    });
    (w, status)
}

/// Component `c` of the paper form from its baseline and its four deviation matrices (sweep
/// order), at the clamped inputs `clamped` and `u`: `B(u)`, then each sweep's `± D(t, u)` in
/// sweep order (minus for a negative input of a sweep `c` is odd under).
pub fn paper_component(baseline: &[f64; NCOEF], rows: [&[[f64; NCOEF]; NCOEF]; 4], c: usize, clamped: [f64; 4], u: f64) -> f64 {
    let mut acc = horner(baseline, u);
    for k in Sweep::ALL {
        let v = clamped[k.index()];
        let dev = deviation(rows[k.index()], k.t_of(v), u);
        if v < 0.0 && k.is_odd(c) {
            acc -= dev;
        } else {
            acc += dev;
        }
    }
    acc
}
