//! The wrench and its stiffness in f32: the evaluation algorithm of `coeffs/README.md`
//! ("Stiffness") bit for bit, sharing the wrench's operations.
use crate::cross_f32::{add_cross, add_cross_rates, COUPLED, CROSS_SCALES};
use crate::horner::{horner, horner_rate, rate_coeffs};
use crate::model_f32::{baseline, clamp_to_domain, is_plus_zero_matrix, sweep_t, ODD, ONE_THIRD, SWEEP_SCALES, ZERO_BASELINE};
use crate::stiffness::{Stiffness, StiffnessEvaluation, WrenchRate};
use crate::tables::{BASELINE, DEVIATION, FITTED};
use crate::{Pose, Status, Wrench};

/// `BASELINE_RATE[c]`: the coefficients of `B_c'(u)` ([`rate_coeffs`]).
const BASELINE_RATE: [[f32; 4]; 6] = {
    let [b0, b1, b2, b3, b4, b5] = &BASELINE;
    [rate_coeffs(b0), rate_coeffs(b1), rate_coeffs(b2), rate_coeffs(b3), rate_coeffs(b4), rate_coeffs(b5)]
};

/// The t-derivative coefficients of the five rows of one deviation matrix.
const fn row_rates(m: &[[f32; 5]; 5]) -> [[f32; 4]; 5] {
    let [r0, r1, r2, r3, r4] = m;
    [rate_coeffs(r0), rate_coeffs(r1), rate_coeffs(r2), rate_coeffs(r3), rate_coeffs(r4)]
}

/// The t-derivative coefficients of one sweep's six matrices (`[c][i]`: row i of `D_c`).
type RowRates = [[[f32; 4]; 5]; 6];

/// `ROW_RATE[k][c][i]`: the coefficients of `d r_i / d t` of `D_kc` for the sweeps x
/// (`k = 0`) and z (`k = 1`), the inputs the stiffness is taken along.
const ROW_RATE: [RowRates; 2] = {
    let [dx, dz, _, _] = &DEVIATION;
    let [x0, x1, x2, x3, x4, x5] = dx;
    let [z0, z1, z2, z3, z4, z5] = dz;
    [
        [row_rates(x0), row_rates(x1), row_rates(x2), row_rates(x3), row_rates(x4), row_rates(x5)],
        [row_rates(z0), row_rates(z1), row_rates(z2), row_rates(z3), row_rates(z4), row_rates(z5)],
    ]
};

/// Whether neither `B(u)` nor `B'(u)` of the baseline `b` can be `-0.0`: their last
/// additions add `b0` and `b1`, and a rounded sum is `-0.0` only when both addends are.
const fn rates_not_neg_zero(b: &[f32; 5]) -> bool {
    let [b0, b1, ..] = *b;
    b0.to_bits() != 0x8000_0000 && b1.to_bits() != 0x8000_0000
}

/// One sweep's row of [`SKIP`].
const fn skip_sweep(mats: &[[[f32; 5]; 5]; 6]) -> [bool; 6] {
    let [m0, m1, m2, m3, m4, m5] = mats;
    let [b0, b1, b2, b3, b4, b5] = &BASELINE;
    [
        is_plus_zero_matrix(m0) && rates_not_neg_zero(b0),
        is_plus_zero_matrix(m1) && rates_not_neg_zero(b1),
        is_plus_zero_matrix(m2) && rates_not_neg_zero(b2),
        is_plus_zero_matrix(m3) && rates_not_neg_zero(b3),
        is_plus_zero_matrix(m4) && rates_not_neg_zero(b4),
        is_plus_zero_matrix(m5) && rates_not_neg_zero(b5),
    ]
}

/// `SKIP[k][c]`: `D_kc` and all its derivatives are `+0.0` and adding them changes no
/// accumulator, so they are left out exactly: the matrix is all `+0.0` (see
/// `model_f32::skip_sweep`), and neither `B_c(u)` nor `B_c'(u)` can be `-0.0`
/// ([`rates_not_neg_zero`]). The x and z rates of a skipped matrix start from `+0.0` and
/// stay `+0.0` (`+0 - +0 = +0`).
const SKIP: [[bool; 6]; 4] = {
    let [d0, d1, d2, d3] = &DEVIATION;
    [skip_sweep(d0), skip_sweep(d1), skip_sweep(d2), skip_sweep(d3)]
};

/// The wrench of [`wrench`](crate::wrench) (the same bits) and its exact partial
/// derivatives by depth, x and z, at `pose`, for a haptic loop that needs the stiffness
/// it renders (the passivity guard of [`control`](crate::control)).
///
/// Implements the contract's "Stiffness" section of `coeffs/README.md`; the golden file
/// `golden-stiffness-f32.csv` holds its bits for every golden pose:
///
/// - `u = depth/3 - 1`, `t_k = |v_k| * (2/V_k) - 1` as for the wrench;
/// - by depth: `a_c = B_c'(u) ± dD_kc/du` over the four sweeps (the wrench's signs),
///   then `a_c * (1/3)`;
/// - by x (and likewise z): `g_c = +0 ± dD_xc/dt`, minus when `x < 0` and component c is
///   *even* under the x mirror (the chain rule through `|x|`), then `g_c * (2/12)`;
/// - coupled form: each cross term `m * P(u)` adds `(m * P'(u)) * (1/3)` by depth and
///   `((e_x * m/xi) * P(u)) * (1/12)` by x;
/// - a rate along an input that was clamped (its `SAT_*` flag) is `+0.0`: the rendered
///   force does not change when the hand moves further outside the domain.
///
/// At `x = 0` (either sign of zero) the rate by x is the one for `x -> 0+` (the model
/// is a polynomial in `|x|`, so a component even under the mirror may have a kink there,
/// with the opposite rate for `x -> 0-`); likewise for z.
///
/// Constant work like [`wrench`](crate::wrench): no allocation, no input-dependent loop.
///
/// # Panics
/// Never (no indexing, no division, no unwrap).
#[must_use]
pub fn wrench_and_stiffness(pose: &Pose) -> StiffnessEvaluation {
    let error = |status| StiffnessEvaluation { wrench: Wrench::ZERO, stiffness: Stiffness::ZERO, status };
    if !FITTED {
        return error(Status::NO_MODEL | Status::ERROR);
    }
    let Some((clamped, status)) = clamp_to_domain(pose) else {
        return error(Status::ERROR);
    };
    let Pose { x_mm: x, z_mm: z, theta_x_deg: tx, theta_z_deg: tz, depth_mm: d } = clamped;
    let u = d * ONE_THIRD - 1.0;
    let mut w = [0.0_f32; 6];
    let mut a = [0.0_f32; 6];
    for ((((wc, ac), b), br), &zero) in
        w.iter_mut().zip(a.iter_mut()).zip(BASELINE.iter()).zip(BASELINE_RATE.iter()).zip(ZERO_BASELINE.iter())
    {
        *wc = baseline(b, zero, u);
        *ac = if zero { 0.0 } else { horner_rate(br, u) };
    }
    let mut gx = [0.0_f32; 6];
    let mut gz = [0.0_f32; 6];
    let [sx, sz, stx, stz] = SWEEP_SCALES;
    let [dx, dz, dtx, dtz] = &DEVIATION;
    let [ox, oz, otx, otz] = &ODD;
    let [kx, kz, ktx, ktz] = &SKIP;
    let [rx, rz] = &ROW_RATE;
    let mut acc = Accumulators { w: &mut w, a: &mut a };
    add_sweep(&mut acc, Some((&mut gx, rx)), dx, ox, kx, x, sx, u);
    add_sweep(&mut acc, Some((&mut gz, rz)), dz, oz, kz, z, sz, u);
    add_sweep(&mut acc, None, dtx, otx, ktx, tx, stx, u);
    add_sweep(&mut acc, None, dtz, otz, ktz, tz, stz, u);
    let mut by_depth = a.map(|ac| ac * ONE_THIRD);
    let mut by_x = gx.map(|gc| gc * sx);
    let mut by_z = gz.map(|gc| gc * sz);
    if COUPLED {
        let [cx, cz, ctx, ctz] = CROSS_SCALES;
        let n = [x * cx, z * cz, tx * ctx, tz * ctz];
        add_cross(n, u, &mut w);
        add_cross_rates(n, u, &mut by_depth, &mut by_x, &mut by_z);
    }
    let along = |flag: Status, r: [f32; 6]| if status.contains(flag) { WrenchRate::ZERO } else { WrenchRate::from_array(r) };
    StiffnessEvaluation {
        wrench: Wrench::from_array(w),
        stiffness: Stiffness {
            by_depth: along(Status::SAT_DEPTH, by_depth),
            by_x: along(Status::SAT_X, by_x),
            by_z: along(Status::SAT_Z, by_z),
        },
        status,
    }
}

/// The wrench and depth-rate accumulators of the six components.
struct Accumulators<'a> {
    /// `w_c`.
    w: &'a mut [f32; 6],
    /// `a_c`, the rate by `u`.
    a: &'a mut [f32; 6],
}

/// Adds one sweep's six deviations and their rates by `u` to `acc`, and when `along` is
/// given (sweeps x and z: the accumulator `g` and the row-rate tables of that sweep) the
/// rates by `t` with the sign of the chain rule through `|v|`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn add_sweep(
    acc: &mut Accumulators<'_>,
    along: Option<(&mut [f32; 6], &RowRates)>,
    mats: &[[[f32; 5]; 5]; 6],
    odd: &[bool; 6],
    skip: &[bool; 6],
    v: f32,
    s: f32,
    u: f32,
) {
    let t = sweep_t(v, s);
    let negative = v < 0.0;
    let (mut g, rates) = match along {
        Some((g, rates)) => (Some(g.iter_mut()), Some(rates.iter())),
        None => (None, None),
    };
    let components = acc.w.iter_mut().zip(acc.a.iter_mut()).zip(mats.iter()).zip(odd.iter()).zip(skip.iter());
    let mut rates = rates;
    for ((((wc, ac), m), &o), &skip) in components {
        let gc = g.as_mut().and_then(Iterator::next);
        let rr = rates.as_mut().and_then(Iterator::next);
        if skip {
            continue;
        }
        let [m0, m1, m2, m3, m4] = m;
        let r = [horner(m0, t), horner(m1, t), horner(m2, t), horner(m3, t), horner(m4, t)];
        let dev = horner(&r, u);
        let du = horner_rate(&rate_coeffs(&r), u);
        let minus = negative && o;
        *wc = if minus { *wc - dev } else { *wc + dev };
        *ac = if minus { *ac - du } else { *ac + du };
        if let (Some(gc), Some([q0, q1, q2, q3, q4])) = (gc, rr) {
            let dt = horner(&[horner_rate(q0, t), horner_rate(q1, t), horner_rate(q2, t), horner_rate(q3, t), horner_rate(q4, t)], u);
            *gc = if negative && !o { *gc - dt } else { *gc + dt };
        }
    }
}
