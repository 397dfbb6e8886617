//! The paper model in f32: the evaluation algorithm of `coeffs/README.md`, bit-exact.
use crate::float::cross::{add_cross, COUPLED, CROSS_SCALES};
use crate::float::horner::{horner_from, matrix_starts, start, MatrixStarts, Start, MINUS_ZERO};
use crate::float::tables::{BASELINE, DEPTH_MAX_MM, DEVIATION, FITTED, THETA_MAX_DEG, X_MAX_MM, Z_MAX_MM};
use crate::{Evaluation, Pose, Status, Wrench};
use needle_contract::COMPONENT_COUNT;
use needle_contract::TERMS;

/// The nearest f32 to 1/3 (`u = depth * (1/3) - 1`).
pub(crate) const ONE_THIRD: f32 = needle_contract::ONE_THIRD_F32;

/// The nearest f32 to `2 / V_k` per sweep (x, z, theta_x, theta_z).
pub(crate) const SWEEP_SCALES: [f32; 4] = needle_contract::SWEEP_SCALES_F32;

/// `ODD[k][c]`: component c (fx, fy, fz, mx, my, mz) changes sign under sweep k's mirror
/// (the contract's table, `needle_contract::ODD`).
pub(crate) const ODD: [[bool; COMPONENT_COUNT]; 4] = needle_contract::ODD;

/// The deviation matrices `D_kc` as one `static` (the generated `DEVIATION`'s values): the
/// soft-float wrench's loop and the stiffness's component tables
/// (`float::eval_stiffness::ComponentTables`) read the same copy, so a soft-float image
/// holds them once (issue 64's flash per image).
pub(crate) static DEVIATION_MATS: [[[[f32; TERMS]; TERMS]; COMPONENT_COUNT]; 4] = DEVIATION;

/// `|v|`, exactly (clears the sign bit).
#[inline(always)]
fn abs(v: f32) -> f32 {
    f32::from_bits(v.to_bits() & 0x7fff_ffff)
}

/// Whether every coefficient of `p` is `+0.0` (bit pattern 0; `-0.0` does not count).
const fn is_plus_zero(p: &[f32; TERMS]) -> bool {
    let mut bits = 0;
    let mut rest: &[f32] = p;
    while let [first, tail @ ..] = rest {
        bits |= first.to_bits();
        rest = tail;
    }
    bits == 0
}

/// Whether every coefficient of the matrix `m` is `+0.0`.
pub(crate) const fn is_plus_zero_matrix(m: &[[f32; TERMS]; TERMS]) -> bool {
    let mut rest: &[[f32; TERMS]] = m;
    while let [first, tail @ ..] = rest {
        if !is_plus_zero(first) {
            return false;
        }
        rest = tail;
    }
    true
}

/// `BASELINE_STARTS[c]`: where the Horner of `B_c` starts (`crate::float::horner`, exact;
/// 0 with `p0 = +0.0` for an all-zero baseline, which is then the constant
/// `+0.0`), decided at compile time.
#[allow(clippy::indexing_slicing)] // const evaluation only: an index out of range is a compile error
pub(crate) const BASELINE_STARTS: [Start; COMPONENT_COUNT] = {
    let mut starts = [0; COMPONENT_COUNT];
    let mut c = 0;
    while c < COMPONENT_COUNT {
        starts[c] = start(&BASELINE[c]);
        c += 1;
    }
    starts
};

/// `SKIP_DEVIATION[k][c]`: `D_kc` is skipped (see [`skip_sweep`]).
const SKIP_DEVIATION: [[bool; COMPONENT_COUNT]; 4] = {
    let [d0, d1, d2, d3] = &DEVIATION;
    [skip_sweep(d0, false), skip_sweep(d1, false), skip_sweep(d2, false), skip_sweep(d3, false)]
};

/// Which of one sweep's six deviations `w_c = w_c ± D_kc` may be left out, exactly.
///
/// The shortcut (computed at compile time, no test at run time) is for the matrices
/// whose coefficients are all `+0.0`: the default set has 12 of the 24, and 5 of the 6
/// baselines are zero too, because its FE runs use symmetric half and quarter blocks,
/// so every component that is odd under a kept mirror is exactly zero. It is exact:
///
/// - `t` and `u` are finite (in `[-1, 1]`), so each Horner step of a `+0.0` polynomial
///   is `(±0) + (+0) = +0`: `D_kc = +0.0` (and a zero baseline is `B_c = +0.0`, which
///   [`superpose`] writes as a constant);
/// - `w_c ± (+0.0)` equals `w_c` unless `w_c` is `-0.0`, and `w_c` never is: a rounded
///   sum is `-0.0` only when both addends are `-0.0`, so `w_c` could only become
///   `-0.0` by starting as `-0.0`, from a baseline whose constant coefficient is
///   `-0.0`. For such a component nothing is skipped.
///
/// `with_rates`: the same for an evaluation that also accumulates `B_c'(u)` (the
/// stiffness, `float::eval_stiffness::SKIP`), which must not start at `-0.0` either: its last
/// addition adds `b1` ([`rate_starts_not_neg_zero`]).
#[allow(clippy::indexing_slicing)] // const evaluation only: an index out of range is a compile error
pub(crate) const fn skip_sweep(mats: &[[[f32; TERMS]; TERMS]; COMPONENT_COUNT], with_rates: bool) -> [bool; COMPONENT_COUNT] {
    let mut skip = [false; COMPONENT_COUNT];
    let mut c = 0;
    while c < COMPONENT_COUNT {
        let b = &BASELINE[c];
        skip[c] = is_plus_zero_matrix(&mats[c]) && starts_not_neg_zero(b) && (!with_rates || rate_starts_not_neg_zero(b));
        c += 1;
    }
    skip
}

/// Whether `h'(b, u)` is never `-0.0`: its last addition adds `b[1]` (a rounded sum is
/// `-0.0` only when both addends are).
const fn rate_starts_not_neg_zero(b: &[f32; TERMS]) -> bool {
    let [_, b1, ..] = *b;
    b1.to_bits() != MINUS_ZERO
}

/// Whether `h(b, u)` is never `-0.0`: its last operation adds `b[0]`, and the sum is
/// `-0.0` only when `b[0]` is.
pub(crate) const fn starts_not_neg_zero(b: &[f32; TERMS]) -> bool {
    let [b0, ..] = *b;
    b0.to_bits() != MINUS_ZERO
}

/// `B_c(u)` from its start (`+0.0` without evaluating it when every coefficient is
/// `+0.0`: see [`skip_sweep`] and `crate::float::horner`).
#[inline(always)]
pub(crate) fn baseline(b: &[f32; TERMS], start: Start, u: f32) -> f32 {
    horner_from(b, u, start)
}

/// `STARTS[k][c]`: where each Horner evaluation of `D_kc` starts (`crate::float::horner`,
/// exact), decided at compile time.
#[allow(clippy::indexing_slicing)] // const evaluation only: an index out of range is a compile error
pub(crate) const STARTS: [[MatrixStarts; COMPONENT_COUNT]; 4] = {
    let every = MatrixStarts { rows: [0; TERMS], outer: 0, outer_rate: 0 };
    let mut starts = [[every; COMPONENT_COUNT]; 4];
    let mut k = 0;
    while k < 4 {
        let mut c = 0;
        while c < COMPONENT_COUNT {
            starts[k][c] = matrix_starts(&DEVIATION[k][c]);
            c += 1;
        }
        k += 1;
    }
    starts
};

/// `D_kc(t, u)` of one deviation matrix `m`: Horner in `t` along each row (`r_i`),
/// then Horner in `u` over the `r_i` (step 4 of the contract), each from its start `s`
/// (the steps left out change no bit, `crate::float::horner`).
#[inline(always)]
fn deviation(m: &[[f32; TERMS]; TERMS], s: &MatrixStarts, t: f32, u: f32) -> f32 {
    let [m0, m1, m2, m3, m4] = m;
    let [s0, s1, s2, s3, s4] = s.rows;
    let rows = [horner_from(m0, t, s0), horner_from(m1, t, s1), horner_from(m2, t, s2), horner_from(m3, t, s3), horner_from(m4, t, s4)];
    horner_from(&rows, u, s.outer)
}

/// `t = |v| * s - 1` of one sweep (step 3 of the contract).
#[inline(always)]
pub(crate) fn sweep_t(v: f32, s: f32) -> f32 {
    abs(v) * s - 1.0
}

/// Steps 4 and 5 of the contract, compact form (targets without a hardware FPU, and
/// the host): one loop over the 4 sweeps x 6 components. On soft-float cores every
/// f32 operation is a call into the float runtime, so unrolling saves little and costs
/// flash (measured with the default set: M3 40,335 instead of 40,515 instructions per
/// wrench, 7.7 KiB of model flash instead of 4.5 KiB; M0 69,653 instead of 70,067,
/// 7.5 KiB instead of 4.7 KiB).
#[cfg(not(target_abi = "eabihf"))]
#[inline(always)]
fn superpose(sweeps: [f32; 4], u: f32) -> [f32; COMPONENT_COUNT] {
    let mut w = [0.0_f32; COMPONENT_COUNT];
    for ((wc, b), &start) in w.iter_mut().zip(BASELINE.iter()).zip(BASELINE_STARTS.iter()) {
        *wc = baseline(b, start, u);
    }
    let sweeps =
        sweeps.iter().zip(SWEEP_SCALES.iter()).zip(DEVIATION_MATS.iter()).zip(ODD.iter()).zip(SKIP_DEVIATION.iter()).zip(STARTS.iter());
    for (((((v, s), mats), odd), skip), starts) in sweeps {
        let t = sweep_t(*v, *s);
        let negative = *v < 0.0;
        for ((((wc, m), &o), &skip), st) in w.iter_mut().zip(mats.iter()).zip(odd.iter()).zip(skip.iter()).zip(starts.iter()) {
            if !skip {
                let dev = deviation(m, st, t, u);
                *wc = if negative && o { *wc - dev } else { *wc + dev };
            }
        }
    }
    w
}

/// Steps 4 and 5 of the contract, unrolled (hard-float targets: `thumbv7em-none-eabihf`,
/// the Cortex-M4F, and any other `eabihf` target, whose ABI implies an FPU): the same
/// operations in the same order as the loop above, written out for the 6 baselines and
/// the 24 deviation matrices, so the core runs straight-line `vldr`/`vmla.f32` with no
/// loop counter, address arithmetic or select per matrix.
///
/// The sign of step 5 is applied as `w_c + sign * D_kc` with `sign = -1.0` when the
/// sweep value is negative (only for odd components): `sign * D_kc` is exactly `-D_kc`
/// and `w + (-D)` is by definition `w - D`, so the bits are the contract's; on the FPU
/// it is one `vmla.f32` (multiply rounded, then add rounded: not fused).
#[cfg(target_abi = "eabihf")]
#[inline(always)]
fn superpose(sweeps: [f32; 4], u: f32) -> [f32; COMPONENT_COUNT] {
    let [b0, b1, b2, b3, b4, b5] = &BASELINE;
    let [bs0, bs1, bs2, bs3, bs4, bs5] = BASELINE_STARTS;
    let mut w = [
        baseline(b0, bs0, u),
        baseline(b1, bs1, u),
        baseline(b2, bs2, u),
        baseline(b3, bs3, u),
        baseline(b4, bs4, u),
        baseline(b5, bs5, u),
    ];
    let [v0, v1, v2, v3] = sweeps;
    let [s0, s1, s2, s3] = SWEEP_SCALES;
    let [d0, d1, d2, d3] = &DEVIATION;
    let [o0, o1, o2, o3] = &ODD;
    let [k0, k1, k2, k3] = &SKIP_DEVIATION;
    let [st0, st1, st2, st3] = &STARTS;
    add_sweep(&mut w, d0, o0, k0, st0, v0, s0, u);
    add_sweep(&mut w, d1, o1, k1, st1, v1, s1, u);
    add_sweep(&mut w, d2, o2, k2, st2, v2, s2, u);
    add_sweep(&mut w, d3, o3, k3, st3, v3, s3, u);
    w
}

/// Adds one sweep's six deviations to `w` (unrolled form of the inner loop).
#[cfg(target_abi = "eabihf")]
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn add_sweep(
    w: &mut [f32; COMPONENT_COUNT],
    mats: &[[[f32; TERMS]; TERMS]; COMPONENT_COUNT],
    odd: &[bool; COMPONENT_COUNT],
    skip: &[bool; COMPONENT_COUNT],
    starts: &[MatrixStarts; COMPONENT_COUNT],
    v: f32,
    s: f32,
    u: f32,
) {
    let t = sweep_t(v, s);
    let sign = if v < 0.0 { -1.0_f32 } else { 1.0 };
    let [w0, w1, w2, w3, w4, w5] = w;
    let [m0, m1, m2, m3, m4, m5] = mats;
    let [o0, o1, o2, o3, o4, o5] = *odd;
    let [k0, k1, k2, k3, k4, k5] = *skip;
    let [s0, s1, s2, s3, s4, s5] = starts;
    add_deviation(w0, m0, o0, k0, s0, sign, t, u);
    add_deviation(w1, m1, o1, k1, s1, sign, t, u);
    add_deviation(w2, m2, o2, k2, s2, sign, t, u);
    add_deviation(w3, m3, o3, k3, s3, sign, t, u);
    add_deviation(w4, m4, o4, k4, s4, sign, t, u);
    add_deviation(w5, m5, o5, k5, s5, sign, t, u);
}

/// `w_c = w_c ± D_kc(t, u)` for one component (`odd` is a constant after unrolling).
#[cfg(target_abi = "eabihf")]
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn add_deviation(wc: &mut f32, m: &[[f32; TERMS]; TERMS], odd: bool, skip: bool, starts: &MatrixStarts, sign: f32, t: f32, u: f32) {
    if skip {
        return;
    }
    let dev = deviation(m, starts, t, u);
    *wc = if odd { *wc + sign * dev } else { *wc + dev };
}

/// `|v| <= max` (`max` positive and finite, as the domain maxima are: the codegen checks
/// they are the contract's 12 mm and 15 degrees), on the bit patterns: for f32 values that
/// are not NaN, the order of `|v|` is the order of the bits without the sign, and NaN
/// and the infinities have bits above every finite value, so they fail the test.
#[inline(always)]
fn within(v: f32, max: f32) -> bool {
    v.to_bits() & 0x7fff_ffff <= max.to_bits()
}

/// `+0.0 <= d <= max` (`max` positive and finite), on the bit patterns: a set sign bit
/// (any negative value, and `-0.0`, which the general path handles) fails the test.
#[inline(always)]
fn within_depth(d: f32, max: f32) -> bool {
    d.to_bits() <= max.to_bits()
}

/// Steps 1 and 2 of the contract for a pose outside the fast path of [`wrench`]:
/// `None` when an input is NaN or infinite, else the clamped pose and its status.
/// On the bit patterns, like [`within`], so soft-float cores need no float comparison.
#[cold]
#[inline(never)]
fn saturate(pose: &Pose) -> Option<(Pose, Status)> {
    let Pose { x_mm, z_mm, theta_x_deg, theta_z_deg, depth_mm } = *pose;
    // `|v| <= f32::MAX`: false for the infinities and NaN only.
    let finite = |v: f32| within(v, f32::MAX);
    if !(finite(x_mm) & finite(z_mm) & finite(theta_x_deg) & finite(theta_z_deg) & finite(depth_mm)) {
        return None;
    }
    let (x, sat_x) = clamp_symmetric(x_mm, X_MAX_MM);
    let (z, sat_z) = clamp_symmetric(z_mm, Z_MAX_MM);
    let (tx, sat_tx) = clamp_symmetric(theta_x_deg, THETA_MAX_DEG);
    let (tz, sat_tz) = clamp_symmetric(theta_z_deg, THETA_MAX_DEG);
    let (d, sat_d) = clamp_depth(depth_mm, DEPTH_MAX_MM);
    let flag = |saturated: bool, f: Status| if saturated { f } else { Status::OK };
    let status = flag(sat_x, Status::SAT_X)
        | flag(sat_z, Status::SAT_Z)
        | flag(sat_tx, Status::SAT_THETA_X)
        | flag(sat_tz, Status::SAT_THETA_Z)
        | flag(sat_d, Status::SAT_DEPTH);
    Some((Pose { x_mm: x, z_mm: z, theta_x_deg: tx, theta_z_deg: tz, depth_mm: d }, status))
}

/// `min(max(v, -max), max)` and whether it differs from `v` (`v` finite, `max` positive
/// and finite): `|v| > max` on the bits (see [`within`]) gives `max` with `v`'s sign,
/// else `v` itself (`-0.0` stays `-0.0`, unsaturated).
#[inline(always)]
fn clamp_symmetric(v: f32, max: f32) -> (f32, bool) {
    if within(v, max) {
        (v, false)
    } else {
        (f32::from_bits(max.to_bits() | (v.to_bits() & 0x8000_0000)), true)
    }
}

/// `min(max(d, 0), max)` and whether it differs from `d` (`d` finite, `max` positive and
/// finite): `+0.0` for a negative `d`, `max` above it, else `d` itself; `-0.0` equals
/// `0` and stays `-0.0`, unsaturated.
#[inline(always)]
fn clamp_depth(d: f32, max: f32) -> (f32, bool) {
    let bits = d.to_bits();
    if bits > 0x8000_0000 {
        (0.0, true)
    } else if bits == 0x8000_0000 || bits <= max.to_bits() {
        (d, false)
    } else {
        (max, true)
    }
}

/// Steps 1 and 2 of the contract: `None` when an input is NaN or infinite, else the
/// pose clamped to the domain and its saturation flags.
///
/// Fast path, the usual case in a control loop: every input inside its domain, so no
/// clamp changes anything and no status bit is set. NaN and the infinities fail these
/// tests too and take the general path ([`saturate`]).
#[inline(always)]
pub(crate) fn clamp_to_domain(pose: &Pose) -> Option<(Pose, Status)> {
    let inside = within(pose.x_mm, X_MAX_MM)
        & within(pose.z_mm, Z_MAX_MM)
        & within(pose.theta_x_deg, THETA_MAX_DEG)
        & within(pose.theta_z_deg, THETA_MAX_DEG)
        & within_depth(pose.depth_mm, DEPTH_MAX_MM);
    if inside {
        Some((*pose, Status::OK))
    } else {
        saturate(pose)
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
///    is odd under that sweep's mirror;
/// 5. coupled form only ([`model_info::COUPLED`](crate::model_info::COUPLED)): the cross
///    terms, `w_c = w_c + m * P(u)` per term with `m` a product of the normalised inputs;
/// 6. [`Status::FE_UNSOLVED`] when the clamped pose lies in the set's unsolved region
///    (where its FE campaign could not solve; the wrench is still the model's).
///
/// The wrench is that of the clamped pose; forces in N, moments in N·mm about the
/// needle's reference point (see [`Wrench`]).
///
/// Without a fitted model (the set had no `model.toml` at build time) every pose gives
/// the zero wrench and `Status::NO_MODEL | Status::ERROR`.
///
/// Constant work: no allocation, no loop that depends on the input, at most about 1,250
/// f32 operations (24 deviation polynomials of 5x5 and 6 quartics); polynomials whose
/// coefficients are all `+0.0` are left out at compile time, exactly (12 of the 24
/// and 5 of the 6 in the default set), and every Horner starts at its highest
/// coefficient that is not `+0.0` (`crate::float::horner`: the same bits; the coupled form's
/// sweeps are of degree 1-4 in t). Inputs outside the domain, NaN or infinite take a
/// slower path for steps 1 and 2.
///
/// # Panics
/// Never (no indexing, no division, no unwrap).
#[must_use]
pub fn wrench(pose: &Pose) -> Evaluation {
    if !FITTED {
        return Evaluation { wrench: Wrench::ZERO, status: Status::NO_MODEL | Status::ERROR };
    }
    let Some((clamped, status)) = clamp_to_domain(pose) else {
        return Evaluation { wrench: Wrench::ZERO, status: Status::ERROR };
    };
    let Pose { x_mm: x, z_mm: z, theta_x_deg: tx, theta_z_deg: tz, depth_mm: d } = clamped;

    let status = status | unsolved_flag([x, z, tx, tz], d);
    let u = d * ONE_THIRD - 1.0;
    let mut w = superpose([x, z, tx, tz], u);
    if COUPLED {
        let [rx, rz, rtx, rtz] = CROSS_SCALES;
        add_cross([x * rx, z * rz, tx * rtx, tz * rtz], u, &mut w);
    }
    Evaluation { wrench: Wrench::from_array(w), status }
}

/// Step 7 of the contract: [`Status::FE_UNSOLVED`] when the clamped pose, `v` its x, z,
/// theta_x, theta_z and `d` its depth, lies in the set's unsolved region
/// (`crate::unsolved`), else [`Status::OK`]. The wrench is not changed.
#[inline(always)]
pub(crate) fn unsolved_flag(v: [f32; 4], d: f32) -> Status {
    if crate::unsolved::in_region_f32(v, d) {
        Status::FE_UNSOLVED
    } else {
        Status::OK
    }
}
