//! The paper model in f32: the evaluation algorithm of `coeffs/README.md`, bit-exact.
use crate::horner::horner;
use crate::tables::{BASELINE, DEPTH_MAX_MM, DEVIATION, FITTED, THETA_MAX_DEG, X_MAX_MM, Z_MAX_MM};
use crate::{Evaluation, Pose, Status, Wrench};

/// The nearest f32 to 1/3 (`u = depth * (1/3) - 1`).
pub(crate) const ONE_THIRD: f32 = 1.0 / 3.0;

/// The nearest f32 to `2 / V_k` per sweep (x, z, theta_x, theta_z).
pub(crate) const SWEEP_SCALES: [f32; 4] = [2.0 / 12.0, 2.0 / 12.0, 2.0 / 15.0, 2.0 / 15.0];

/// `ODD[k][c]`: component c (fx, fy, fz, mx, my, mz) changes sign under sweep k's mirror
/// (x -> -x maps (x, theta_z) to (-x, -theta_z); z -> -z maps (z, theta_x) to (-z, -theta_x)).
pub(crate) const ODD: [[bool; 6]; 4] = [
    [true, false, false, false, true, true],
    [false, false, true, true, true, false],
    [false, false, true, true, true, false],
    [true, false, false, false, true, true],
];

/// `|v|`, exactly (clears the sign bit).
#[inline(always)]
fn abs(v: f32) -> f32 {
    f32::from_bits(v.to_bits() & 0x7fff_ffff)
}

/// `v` clamped to `lo..=hi`, and whether it changed (`v` finite; `-0.0 == +0.0`).
#[inline(always)]
fn clamp(v: f32, lo: f32, hi: f32) -> (f32, bool) {
    if v < lo {
        (lo, true)
    } else if v > hi {
        (hi, true)
    } else {
        (v, false)
    }
}

/// The reaction wrench of the compiled-in set's f32 paper model at `pose`.
///
/// Implements the evaluation algorithm of `coeffs/README.md` exactly, so the result has
/// the same bits as the fitter's independent implementation (the golden vectors) on
/// every IEEE-754 target, with or without an FPU:
///
/// 1. any input NaN or infinite: zero wrench, status [`Status::ERROR`];
/// 2. each input is clamped to the domain ([`model_info`](crate::model_info)), with the
///    matching `SAT_*` flag when it changed;
/// 3. `u = depth * (1/3) - 1`, and per sweep `t = |v| * (2/V) - 1`;
/// 4. `w_c = B_c(u)`, then for x, z, theta_x, theta_z in that order
///    `w_c = w_c ± D_c(t, u)`, minus when the sweep value is negative and the component
///    is odd under that sweep's mirror.
///
/// The wrench is that of the clamped pose; forces in N, moments in N·mm about the
/// needle's reference point (see [`Wrench`]).
///
/// Without a fitted model (the set had no `model.toml` at build time) every pose gives
/// the zero wrench and `Status::NO_MODEL | Status::ERROR`.
///
/// Constant work: no allocation, no loop that depends on the input, about 1,200 f32
/// operations (24 deviation polynomials of 5x5 and 6 quartics).
///
/// # Panics
/// Never (no indexing, no division, no unwrap).
#[must_use]
pub fn wrench(pose: &Pose) -> Evaluation {
    if !FITTED {
        return Evaluation { wrench: Wrench::ZERO, status: Status::NO_MODEL | Status::ERROR };
    }
    let Pose { x_mm, z_mm, theta_x_deg, theta_z_deg, depth_mm } = *pose;
    if !(x_mm.is_finite()
        && z_mm.is_finite()
        && theta_x_deg.is_finite()
        && theta_z_deg.is_finite()
        && depth_mm.is_finite())
    {
        return Evaluation { wrench: Wrench::ZERO, status: Status::ERROR };
    }

    let (x, sat_x) = clamp(x_mm, -X_MAX_MM, X_MAX_MM);
    let (z, sat_z) = clamp(z_mm, -Z_MAX_MM, Z_MAX_MM);
    let (tx, sat_tx) = clamp(theta_x_deg, -THETA_MAX_DEG, THETA_MAX_DEG);
    let (tz, sat_tz) = clamp(theta_z_deg, -THETA_MAX_DEG, THETA_MAX_DEG);
    let (d, sat_d) = clamp(depth_mm, 0.0, DEPTH_MAX_MM);
    let status = Status::from_bits(
        u8::from(sat_x)
            | u8::from(sat_z) << 1
            | u8::from(sat_tx) << 2
            | u8::from(sat_tz) << 3
            | u8::from(sat_d) << 4,
    );

    let u = d * ONE_THIRD - 1.0;
    let mut w = [0.0_f32; 6];
    for (wc, b) in w.iter_mut().zip(BASELINE.iter()) {
        *wc = horner(b, u);
    }
    let sweeps = [x, z, tx, tz];
    for (((v, s), mats), odd) in sweeps.iter().zip(SWEEP_SCALES.iter()).zip(DEVIATION.iter()).zip(ODD.iter()) {
        let t = abs(*v) * *s - 1.0;
        let negative = *v < 0.0;
        for ((wc, m), &o) in w.iter_mut().zip(mats.iter()).zip(odd.iter()) {
            let [m0, m1, m2, m3, m4] = m;
            let r = [horner(m0, t), horner(m1, t), horner(m2, t), horner(m3, t), horner(m4, t)];
            let dev = horner(&r, u);
            *wc = if negative && o { *wc - dev } else { *wc + dev };
        }
    }
    Evaluation { wrench: Wrench::from_array(w), status }
}
