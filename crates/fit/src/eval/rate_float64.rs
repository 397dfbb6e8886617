//! The wrench's exact partial derivatives by depth, x and z in f64 on the f64
//! coefficients (coeffs/README.md, "Stiffness"): the reference the f32 stiffness is
//! measured against, itself checked against central differences of
//! [`crate::eval::float64::eval`] (tests below).

use crate::contract::COMPONENT_COUNT;
use crate::contract::{u_of, Sweep, DEPTH_MAX_MM, NCOEF, STATUS_ERROR, STATUS_SAT_DEPTH, STATUS_SAT_X, STATUS_SAT_Z};
use crate::cross_terms::{mono, normalised, poly};
use crate::eval::float64::{eval, horner, Pose64};
use crate::model::Model;

/// `p'(w)` of the polynomial `p` (`p[i]` multiplies `w^i`).
pub fn horner_rate(p: &[f64], w: f64) -> f64 {
    p.iter().enumerate().skip(1).rev().fold(0.0, |acc, (k, c)| acc * w + k as f64 * c)
}

/// The rates `[by_depth, by_x, by_z]` of the model at `pose`, each `[fx, fy, fz, mx, my,
/// mz]` in N/mm and N·mm/mm, and the status byte (as [`eval`]). Zero along a clamped
/// input and for an error; at `x = 0` (`z = 0`) the rate for `x -> 0+`.
pub fn eval_rates(model: &Model, pose: Pose64) -> ([[f64; COMPONENT_COUNT]; 3], u8) {
    let (_, status) = eval(model, pose);
    if status & STATUS_ERROR != 0 {
        return ([[0.0; COMPONENT_COUNT]; 3], status);
    }
    let v: [f64; 4] = std::array::from_fn(|i| pose[i].clamp(-Sweep::ALL[i].half_range(), Sweep::ALL[i].half_range()));
    let u = u_of(pose[4].clamp(0.0, DEPTH_MAX_MM));
    let mut rates = [[0.0f64; COMPONENT_COUNT]; 3];
    for c in 0..COMPONENT_COUNT {
        let mut a = horner_rate(&model.baseline[c].coeffs, u);
        for k in Sweep::ALL {
            let vk = v[k.index()];
            let rows = &model.matrices[k.index()][c].rows;
            let t = k.t_of(vk);
            let r: [f64; NCOEF] = std::array::from_fn(|i| horner(&rows[i], t));
            let mirror = if vk < 0.0 && k.is_odd(c) { -1.0 } else { 1.0 };
            a += mirror * horner_rate(&r, u);
            if let Some(j) = [Sweep::X, Sweep::Z].iter().position(|s| *s == k) {
                let rt: [f64; NCOEF] = std::array::from_fn(|i| horner_rate(&rows[i], t));
                let sign = if vk < 0.0 { -1.0 } else { 1.0 };
                rates[j + 1][c] += mirror * sign * horner(&rt, u) * 2.0 / k.half_range();
            }
        }
        rates[0][c] = a / 3.0;
    }
    if let Some(cross) = &model.cross {
        let (n, u) = normalised(pose);
        for (c, terms) in cross.terms.terms.iter().enumerate() {
            for (e, p) in terms {
                rates[0][c] += mono(*e, &n) * horner_rate(p, u) / 3.0;
                for (j, k) in [Sweep::X, Sweep::Z].into_iter().enumerate() {
                    let i = k.index();
                    if e[i] > 0 {
                        let mut reduced = *e;
                        reduced[i] -= 1;
                        rates[j + 1][c] += f64::from(e[i]) * mono(reduced, &n) * poly(p, u) / k.half_range();
                    }
                }
            }
        }
    }
    for (i, flag) in [STATUS_SAT_DEPTH, STATUS_SAT_X, STATUS_SAT_Z].into_iter().enumerate() {
        if status & flag != 0 {
            rates[i] = [0.0; COMPONENT_COUNT];
        }
    }
    (rates, status)
}
