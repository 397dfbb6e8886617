//! The fixed-point evaluator: the integer algorithm of `coeffs/README.md`, bit-exact.
use super::arith::{clamp, horner, horner_from, normalise, start};
use super::cross::{add_cross, cross_input, CROSS_DIVISORS};
use super::tables::{
    BASELINE, DEPTH_DIVISOR, DEPTH_MAX_MM_Q16, FRAC_BITS, ODD, ROWS, SHIFTS, SWEEP_DIVISORS, THETA_MAX_DEG_Q16, X_MAX_MM_Q16, Z_MAX_MM_Q16,
};
use super::{Evaluation, Pose, Wrench};
use crate::float::tables::FITTED;
use crate::Status;
use needle_contract::COMPONENT_COUNT;
use needle_contract::TERMS;

/// The reaction wrench of the compiled-in set's model at `pose`, in integer arithmetic
/// only (no floating point: fast on cores without an FPU).
///
/// Implements the fixed-point contract of `coeffs/README.md` exactly, so the result has
/// the same bits as the fitter's independent implementation (`golden-fixed.csv`) on
/// every core:
///
/// 1. each Q16.16 input is clamped to the domain, with the matching `SAT_*` flag when it
///    changed (the same flags as [`crate::wrench`]);
/// 2. `U = (depth + 3) / 6 - 32768` and per sweep `T = (|v| + 6) / 12 - 32768` (x, z)
///    or `(|v| + 7) / 15 - 32768` (tilts): u and t in Q15, rounded to nearest;
/// 3. per component c: `A_i = BASELINE[c][i]`, then for each sweep k and row i
///    `A_i ±= h(ROWS[c][k][i], T_k) >> SHIFTS[c][k][i]` (minus when the sweep value is
///    negative and c is odd under that sweep's mirror), with `h` a Horner whose products
///    are `floor(a * w / 2^15)`;
/// 4. coupled form only: `N_k = sign(v_k) * ((|v_k| + V_k) / (2 V_k))` (Q15) and per cross
///    term `A_i += (P[i] * M >> 15) >> shift` with `M` the Q15 monomial (generated code);
/// 5. `W = h(A, U)`, and the result `(W + 2^(G-1)) >> G` in µN or µN·mm
///    ([`tables::FRAC_BITS`](super::tables::FRAC_BITS) = G);
/// 6. [`Status::FE_UNSOLVED`] when the clamped pose lies in the set's unsolved region
///    (integer comparisons on the `N_k` and the depth; the wrench is not changed).
///
/// No intermediate can overflow: the code generator bounds every one of them over the
/// whole domain and chose the formats so that all stay within ±2^30. The result differs
/// from the f64 evaluation of the model by at most
/// [`tables::ERROR_BOUND_MICRO`](super::tables::ERROR_BOUND_MICRO) per component.
///
/// Without a fitted model every pose gives the zero wrench and
/// `Status::NO_MODEL | Status::ERROR`.
///
/// Constant work: 504 Q15 products (6 components × (20 row polynomials of degree 4 +
/// one in u)).
///
/// # Panics
/// Never (no indexing, no unchecked division, wrapping arithmetic that the generator's
/// bounds keep from wrapping).
#[must_use]
pub fn wrench(pose: &Pose) -> Evaluation {
    if !FITTED {
        return Evaluation { wrench: Wrench::ZERO, status: Status::NO_MODEL | Status::ERROR };
    }
    let mut at = Inputs::of(pose);
    let a = accumulators(&mut at, pose);
    Evaluation { wrench: Wrench::from_array(output(&a, at.u)), status: at.status }
}

/// Steps 2 and 3: the clamped inputs, the status, `U`, the `T_k` and the signs.
pub(super) struct Inputs {
    /// The clamped x, z, theta_x, theta_z (Q16.16).
    pub v: [i32; 4],
    /// `T_k` (Q15).
    pub t: [i32; 4],
    /// `V_k < 0`.
    pub negative: [bool; 4],
    /// `U` (Q15).
    pub u: i32,
    /// The saturation flags ([`accumulators`] adds [`Status::FE_UNSOLVED`]).
    pub status: Status,
}

impl Inputs {
    #[inline(always)]
    pub(super) fn of(pose: &Pose) -> Self {
        let (x, sat_x) = clamp(pose.x_mm_q16, -X_MAX_MM_Q16, X_MAX_MM_Q16);
        let (z, sat_z) = clamp(pose.z_mm_q16, -Z_MAX_MM_Q16, Z_MAX_MM_Q16);
        let (tx, sat_tx) = clamp(pose.theta_x_deg_q16, -THETA_MAX_DEG_Q16, THETA_MAX_DEG_Q16);
        let (tz, sat_tz) = clamp(pose.theta_z_deg_q16, -THETA_MAX_DEG_Q16, THETA_MAX_DEG_Q16);
        let (d, sat_d) = clamp(pose.depth_mm_q16, 0, DEPTH_MAX_MM_Q16);
        let status = Status::from_bits(
            u8::from(sat_x) | u8::from(sat_z) << 1 | u8::from(sat_tx) << 2 | u8::from(sat_tz) << 3 | u8::from(sat_d) << 4,
        );
        let [dx, dz, dtx, dtz] = SWEEP_DIVISORS;
        Self {
            v: [x, z, tx, tz],
            t: [
                normalise(x.unsigned_abs(), dx),
                normalise(z.unsigned_abs(), dz),
                normalise(tx.unsigned_abs(), dtx),
                normalise(tz.unsigned_abs(), dtz),
            ],
            negative: [x < 0, z < 0, tx < 0, tz < 0],
            u: normalise(d.unsigned_abs(), DEPTH_DIVISOR),
            status,
        }
    }

    /// Step 6's signed cross-term inputs `N_k` (Q15).
    #[inline(always)]
    pub(super) fn cross_inputs(&self) -> [i32; 4] {
        let [x, z, tx, tz] = self.v;
        let [cx, cz, ctx, ctz] = CROSS_DIVISORS;
        [cross_input(x, cx), cross_input(z, cz), cross_input(tx, ctx), cross_input(tz, ctz)]
    }
}

/// `ROW_STARTS[c][k][i]`: where the Horner of `ROWS[c][k][i]` starts (`arith::start`:
/// the steps above its highest nonzero coefficient change nothing), decided at compile
/// time. The coupled form's sweeps are of degree 1-4 in t, and the matrices its mirror
/// symmetries zero have rows of zeros (start 0: `h = 0`).
#[allow(clippy::indexing_slicing)] // const evaluation only: an index out of range is a compile error
pub(super) const ROW_STARTS: [[[u8; TERMS]; 4]; COMPONENT_COUNT] = {
    let mut starts = [[[0_u8; TERMS]; 4]; COMPONENT_COUNT];
    let mut c = 0;
    while c < COMPONENT_COUNT {
        let mut k = 0;
        while k < 4 {
            let mut i = 0;
            while i < TERMS {
                starts[c][k][i] = start(&ROWS[c][k][i]);
                i += 1;
            }
            k += 1;
        }
        c += 1;
    }
    starts
};

/// Steps 4-6: every component's accumulators `A_i` (baseline, the four sweeps' rows, the
/// cross terms), each in its Q(G).
///
/// The cross terms (step 6) are added first: wrapping `i32` sums give the same bits in
/// any order, and so the clamped inputs and `N_k` are dead before the sweeps' rows are
/// computed (measured with a coupled model, `needle firmware bench`: the fixed-point
/// stiffness's stack 524 -> 492 B on the M4F, 520 -> 504 B on the M0).
///
/// Step 7 here too, on the same `N_k`: [`Status::FE_UNSOLVED`] into `at.status` when the
/// clamped pose lies in the set's unsolved region (`pose` gives the depth, clamped again
/// here rather than kept in [`Inputs`]: the stack).
#[inline(always)]
pub(super) fn accumulators(at: &mut Inputs, pose: &Pose) -> [[i32; TERMS]; COMPONENT_COUNT] {
    let mut a = BASELINE;
    let n = at.cross_inputs();
    add_cross(n, &mut a);
    let (d, _) = clamp(pose.depth_mm_q16, 0, DEPTH_MAX_MM_Q16);
    if crate::unsolved::in_region_fixed(n, d) {
        at.status |= Status::FE_UNSOLVED;
    }
    let tables = ROWS.iter().zip(SHIFTS.iter()).zip(ODD.iter()).zip(ROW_STARTS.iter());
    for (ac, (((rows, shifts), odd), starts)) in a.iter_mut().zip(tables) {
        for (((((rows_k, shifts_k), &tk), &neg), &o), starts_k) in
            rows.iter().zip(shifts.iter()).zip(at.t.iter()).zip(at.negative.iter()).zip(odd.iter()).zip(starts.iter())
        {
            let flip = neg && o;
            for (((ai, row), &s), &st) in ac.iter_mut().zip(rows_k.iter()).zip(shifts_k.iter()).zip(starts_k.iter()) {
                let r = horner_from(row, tk, st).wrapping_shr(s);
                *ai = if flip { ai.wrapping_sub(r) } else { ai.wrapping_add(r) };
            }
        }
    }
    a
}

/// Step 7: `W = h(A, U)` per component, rounded half up to whole µN or µN·mm.
#[inline(always)]
pub(super) fn output(a: &[[i32; TERMS]; COMPONENT_COUNT], u: i32) -> [i32; COMPONENT_COUNT] {
    let mut w = [0_i32; COMPONENT_COUNT];
    for ((wc, ac), &g) in w.iter_mut().zip(a.iter()).zip(FRAC_BITS.iter()) {
        let acc = horner(ac, u);
        *wc = acc.wrapping_add(1_i32.wrapping_shl(g) >> 1).wrapping_shr(g);
    }
    w
}
