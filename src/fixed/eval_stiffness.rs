//! The fixed-point wrench and its stiffness: the integer algorithm of `coeffs/README.md`
//! ("Fixed-point stiffness"), bit-exact, sharing the wrench's steps.
use super::arith::{div_round, horner, horner3};
use super::cross::{add_cross_rates_x, add_cross_rates_z};
use super::eval::{accumulators, output, Inputs};
use super::stiffness::{Stiffness, StiffnessEvaluation, WrenchRate};
use super::tables::{FRAC_BITS, ODD, RATE_ROWS, RATE_SHIFTS, SHIFTS};
use super::{Pose, Wrench};
use crate::float::tables::FITTED;
use crate::Status;
use needle_contract::COMPONENT_COUNT;
use needle_contract::{DEGREE, TERMS};

/// The wrench of [`wrench`](super::wrench) (the same integers) and its partial
/// derivatives by depth, x and z in µN/mm and µN·mm/mm, in integer arithmetic only: the
/// stiffness a haptic loop on a core without an FPU needs for its passivity guard.
///
/// Implements "Fixed-point stiffness" of `coeffs/README.md` exactly, so the result has
/// the same bits as the fitter's independent implementation
/// (`golden-stiffness-fixed.csv`) on every core. With the wrench's `A_i` (Q(G)), `U`,
/// `T_k`:
///
/// - by depth: with `R = min(3, G)` ([`RATE_SHIFTS`](super::tables::RATE_SHIFTS)),
///   `E_i = (i + 1) * (A_(i+1) >> R)`, `D = h3(E, U)` (Q(G-R) per unit of u), rate
///   `round(D / (3 * 2^(G-R)))` (u = depth/3 - 1);
/// - by x (z likewise): per row `i` of the x sweep, `h3(RATE_ROWS, T_x) >> SHIFTS`, added to
///   `gx_i`, subtracted when `x < 0` and the component is *even* under the x mirror (the
///   chain rule through `|x|`); the cross terms add their rates (generated code); rate
///   `round(h(gx, U) / (6 * 2^(G-R)))` (t = |x|/6 - 1);
/// - `round(n / d)` is `floor((n + (d >> 1)) / d)`; a rate along a clamped input (its `SAT_*` flag) is 0.
///
/// At `x = 0` the rate by x is the one for `x -> 0+`, as in
/// [`crate::wrench_and_stiffness`]. The rates approximate the f64 model's derivatives
/// (the formats lose up to 3 bits and round; the wrench's error bound does not cover
/// them).
///
/// No intermediate can overflow: the code generator bounds the rates' Horner
/// intermediates by 2^30 over the whole domain, or refuses the model.
///
/// # Panics
/// Never (no indexing, checked division, wrapping arithmetic that the generator's
/// bounds keep from wrapping).
#[must_use]
pub fn wrench_and_stiffness(pose: &Pose) -> StiffnessEvaluation {
    if !FITTED {
        return StiffnessEvaluation { wrench: Wrench::ZERO, stiffness: Stiffness::ZERO, status: Status::NO_MODEL | Status::ERROR };
    }
    // Each child takes the pose and computes the inputs itself (a few integer divisions
    // again), so this frame holds only the result (measured stack on the M0: 520 B with
    // the inputs kept here).
    let mut e = StiffnessEvaluation { wrench: Wrench::ZERO, stiffness: Stiffness::ZERO, status: Status::OK };
    wrench_and_depth_rates(pose, &mut e);
    along::<0>(pose, &mut e.stiffness.by_x);
    along::<1>(pose, &mut e.stiffness.by_z);
    e
}

/// The wrench, the status and the rates by depth (left zero when the depth was clamped)
/// into `e`, from the accumulators `A_i`: `E_i = (i + 1) * (A_(i+1) >> R)`,
/// `D = h3(E, U)`, rate `round(D / (3 * 2^(G-R)))`. Not inlined: each input's rates get
/// their own stack frame, so the accumulators of one are dead while the next are
/// computed (measured stack, M0: 704 B with all three sets of accumulators live).
#[inline(never)]
fn wrench_and_depth_rates(pose: &Pose, e: &mut StiffnessEvaluation) {
    let at = &mut Inputs::of(pose);
    let a = accumulators(at, pose);
    let mut by_depth = [0_i32; COMPONENT_COUNT];
    for (((r, ac), &g), &rs) in by_depth.iter_mut().zip(a.iter()).zip(FRAC_BITS.iter()).zip(RATE_SHIFTS.iter()) {
        // E_i = (i + 1) * (A_(i+1) >> R), written out: the loop form costs the M0 14
        // instructions per call (11,486.1 -> 11,500.0, needle firmware bench)
        let [_, a1, a2, a3, a4] = *ac;
        let coeffs = [a1 >> rs, (a2 >> rs).wrapping_mul(2), (a3 >> rs).wrapping_mul(3), (a4 >> rs).wrapping_mul(4)];
        *r = div_round(horner3(&coeffs, at.u), 3_i32.wrapping_shl(g.wrapping_sub(rs)));
    }
    if !at.status.contains(Status::SAT_DEPTH) {
        e.stiffness.by_depth = WrenchRate::from_array(by_depth);
    }
    // the wrench after the rates: its array and `by_depth` are not live together (the
    // stack, measured on the M0 with `needle firmware bench`: 496 B, 512 B with the
    // wrench first)
    e.wrench = Wrench::from_array(output(&a, at.u));
    e.status = at.status;
}

/// The rates by x (`K = 0`) or z (`K = 1`): per component `g_i` from the sweep's row
/// rates (signed by the chain rule through `|v|`) and the cross terms' rates, then
/// `round(h(g, U) / (6 * 2^(G-R)))`, into `out` unless that input was clamped (then
/// `out` stays zero).
#[inline(never)]
fn along<const K: usize>(pose: &Pose, out: &mut WrenchRate) {
    let at = &Inputs::of(pose);
    let [tx, tz, _, _] = at.t;
    let [neg_x, neg_z, _, _] = at.negative;
    let (t, negative) = if K == 0 { (tx, neg_x) } else { (tz, neg_z) };
    let mut g = [[0_i32; TERMS]; COMPONENT_COUNT];
    let tables = RATE_ROWS.iter().zip(SHIFTS.iter()).zip(ODD.iter());
    for (gc, ((rate_rows, shifts), odd)) in g.iter_mut().zip(tables) {
        let [rows_x, rows_z] = rate_rows;
        let [shifts_x, shifts_z, _, _] = shifts;
        let [odd_x, odd_z, _, _] = *odd;
        if K == 0 {
            add_row_rates(gc, rows_x, shifts_x, t, negative && !odd_x);
        } else {
            add_row_rates(gc, rows_z, shifts_z, t, negative && !odd_z);
        }
    }
    if K == 0 {
        add_cross_rates_x(at.cross_inputs(), &mut g);
    } else {
        add_cross_rates_z(at.cross_inputs(), &mut g);
    }
    let mut rates = [0_i32; COMPONENT_COUNT];
    for (((r, gc), &bits), &rs) in rates.iter_mut().zip(g.iter()).zip(FRAC_BITS.iter()).zip(RATE_SHIFTS.iter()) {
        *r = div_round(horner(gc, at.u), 6_i32.wrapping_shl(bits.wrapping_sub(rs)));
    }
    if !at.status.contains(if K == 0 { Status::SAT_X } else { Status::SAT_Z }) {
        *out = WrenchRate::from_array(rates);
    }
}

/// One sweep's row rates into `g`: `g_i = g_i ± (h3(rows[i], t) >> shifts[i])`, minus
/// when `minus` (negative input, component even under the mirror).
#[inline(always)]
fn add_row_rates(g: &mut [i32; TERMS], rows: &[[i32; DEGREE]; TERMS], shifts: &[u32; TERMS], t: i32, minus: bool) {
    for ((gi, row), &s) in g.iter_mut().zip(rows.iter()).zip(shifts.iter()) {
        let r = horner3(row, t).wrapping_shr(s);
        *gi = if minus { gi.wrapping_sub(r) } else { gi.wrapping_add(r) };
    }
}
