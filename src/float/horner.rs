//! Horner evaluation of a quartic, in the contract's exact operation order, starting at
//! the highest coefficient that can change the result.
//!
//! **Trimming.** With `w` finite (as `u` and `t` always are), the steps of
//! `(((p4*w + p3)*w + p2)*w + p1)*w + p0` above the highest coefficient `p_k` that is
//! not known to be `+0.0` change nothing: a `+0.0` accumulator times `w` is `±0.0`, and
//! `±0.0 + (+0.0) = +0.0`, so the accumulator is `+0.0` down to index `k`, where
//! `±0.0 + p_k = p_k` for every `p_k` except `-0.0` (that sum's sign would follow `w`'s).
//! The rate of [`horner_with_rate_from`] takes the same steps and stays `+0.0` with the
//! value. So evaluation may start at `p_k` when `p_k` cannot be `-0.0`; otherwise every
//! step is done. The result has the contract's bits either way.
//!
//! The starts are computed at compile time from the generated tables
//! ([`matrix_starts`], [`start`] in const items), so no coefficient is tested at run
//! time. Measured side by side with `needle firmware bench` on the coupled default model
//! fitted on 21 training runs (docs/measurement-notebook.md, "Horner trimming"): the M4F's wrench
//! 541.1 -> 481.1 instructions, with the stiffness 973.0 -> 874.1; soft-float M3
//! 37,014 -> 29,312, M0 61,588 -> 50,786.
use needle_contract::TERMS;

/// The bit pattern of `-0.0`.
pub(crate) const MINUS_ZERO: u32 = 0x8000_0000;

/// Where a Horner evaluation starts: the index of its first coefficient, so `4` (the
/// contract's degree) is every step. One byte, so that the tables of starts cost little
/// flash (`float::eval::STARTS`: 7 B per matrix).
pub(crate) type Start = u8;

/// Every step: the start at the top coefficient (index `DEGREE`, 4).
#[allow(clippy::cast_possible_truncation)] // DEGREE is 4
const EVERY_STEP: Start = needle_contract::DEGREE as Start;

/// Where Horner may start: the highest index whose entry of `nonzero` is `true` (0 when
/// none is), or [`EVERY_STEP`] when that entry's coefficient may be `-0.0`
/// (`minus_zero[k]`).
const fn start_at(nonzero: [bool; TERMS], minus_zero: [bool; TERMS]) -> Start {
    let [n0, n1, n2, n3, n4] = nonzero;
    let [z0, z1, z2, z3, z4] = minus_zero;
    let (top, minus) = if n4 {
        (4, z4)
    } else if n3 {
        (3, z3)
    } else if n2 {
        (2, z2)
    } else if n1 {
        (1, z1)
    } else {
        (0, z0 && n0)
    };
    if minus {
        EVERY_STEP
    } else {
        top
    }
}

/// The start of a polynomial with known coefficients `p` (see the module docs).
pub(crate) const fn start(p: &[f32; TERMS]) -> Start {
    let [c0, c1, c2, c3, c4] = *p;
    let [b0, b1, b2, b3, b4] = [c0.to_bits(), c1.to_bits(), c2.to_bits(), c3.to_bits(), c4.to_bits()];
    start_at(
        [b0 != 0, b1 != 0, b2 != 0, b3 != 0, b4 != 0],
        [b0 == MINUS_ZERO, b1 == MINUS_ZERO, b2 == MINUS_ZERO, b3 == MINUS_ZERO, b4 == MINUS_ZERO],
    )
}

/// Whether row `row` of a matrix is `+0.0` from index `lowest` (0 or 1) on, and whether
/// its coefficient at `lowest` is `-0.0`.
const fn row_at(row: &[f32; TERMS], lowest: usize) -> (bool, bool) {
    let [c0, c1, c2, c3, c4] = *row;
    let upper = c1.to_bits() | c2.to_bits() | c3.to_bits() | c4.to_bits();
    if lowest == 0 {
        (c0.to_bits() | upper != 0, c0.to_bits() == MINUS_ZERO)
    } else {
        (upper != 0, c1.to_bits() == MINUS_ZERO)
    }
}

/// The start of the outer Horner in `u` over the rows' values `r_i = h(m_i, t)` of the
/// matrix `m`, decided from `m` alone: a row of `+0.0` gives `r_i = +0.0` exactly, and
/// `r_i` can only be `-0.0` when its last addition adds a `-0.0`, i.e. when `m_i[0]` is
/// `-0.0` (`lowest = 0`). With `lowest = 1`, the same for the rows' t-rates `h'(m_i, t)`,
/// whose last addition adds the value after the `m_i[1]` step: `-0.0` only when
/// `m_i[1]` is `-0.0` (a row whose only nonzero coefficient is `m_i[0]` has the rate
/// `+0.0`).
const fn start_rows(m: &[[f32; TERMS]; TERMS], lowest: usize) -> Start {
    let [r0, r1, r2, r3, r4] = m;
    let rows = [row_at(r0, lowest), row_at(r1, lowest), row_at(r2, lowest), row_at(r3, lowest), row_at(r4, lowest)];
    let [(n0, z0), (n1, z1), (n2, z2), (n3, z3), (n4, z4)] = rows;
    start_at([n0, n1, n2, n3, n4], [z0, z1, z2, z3, z4])
}

/// Where each Horner evaluation of one deviation matrix starts (computed at compile
/// time from the tables).
#[derive(Clone, Copy)]
pub(crate) struct MatrixStarts {
    /// Each row's Horner in `t`.
    pub(crate) rows: [Start; TERMS],
    /// The Horner in `u` over the rows' values.
    pub(crate) outer: Start,
    /// The Horner in `u` over the rows' t-rates (the stiffness by x and z).
    pub(crate) outer_rate: Start,
}

/// The starts of matrix `m` (const evaluation).
pub(crate) const fn matrix_starts(m: &[[f32; TERMS]; TERMS]) -> MatrixStarts {
    let [r0, r1, r2, r3, r4] = m;
    MatrixStarts { rows: [start(r0), start(r1), start(r2), start(r3), start(r4)], outer: start_rows(m, 0), outer_rate: start_rows(m, 1) }
}

/// `h(p, w) = (((p4*w + p3)*w + p2)*w + p1)*w + p0` (for the contract's degree 4) from
/// a start decided by the caller ([`Start`]; 4 or more: every step): every multiply and add rounded
/// on its own (Rust never fuses them into an FMA), highest power first, starting from
/// the highest coefficient itself (not `0*w + p4`, which would turn a `-0.0` into
/// `+0.0`); trimmed (module docs).
#[inline(always)]
pub(crate) fn horner_from(p: &[f32; TERMS], w: f32, start: Start) -> f32 {
    let [p0, p1, p2, p3, p4] = *p;
    match start {
        0 => p0,
        1 => p1 * w + p0,
        2 => (p2 * w + p1) * w + p0,
        3 => ((p3 * w + p2) * w + p1) * w + p0,
        _ => (((p4 * w + p3) * w + p2) * w + p1) * w + p0,
    }
}

/// `h(p, w)` and `h'(p, w)` together (coeffs/README.md, "Stiffness"), from a start
/// decided by the caller ([`Start`]; 4 or more: every step): the value by the operations of
/// [`horner_from`] (the same bits), the derivative accumulated alongside, `d = p4`, then
/// `d = d*w + b` after each of the value's steps for `p3`, `p2`, `p1` (`b` the value so
/// far), 3 multiplies and 3 adds more, no further coefficient loads. Trimmed (module
/// docs): from `p_k`, `b = d = p_k` (for `k = 0`: `b = p0`, `d = +0.0`).
#[inline(always)]
pub(crate) fn horner_with_rate_from(p: &[f32; TERMS], w: f32, start: Start) -> (f32, f32) {
    let [p0, p1, p2, p3, p4] = *p;
    // one step of both: (b, d) -> (b*w + c, d*w + (b*w + c))
    let step = |(b, d): (f32, f32), c: f32| {
        let b = b * w + c;
        (b, d * w + b)
    };
    let (b, d) = match start {
        0 => return (p0, 0.0),
        1 => (p1, p1),
        2 => step((p2, p2), p1),
        3 => step(step((p3, p3), p2), p1),
        _ => step(step(step((p4, p4), p3), p2), p1),
    };
    (b * w + p0, d)
}

/// [`horner_from`] for the passivity guard's depth rates (`float::depth_rate`, through
/// `float::eval_stiffness::component::<true>`): inlined on hard-float cores (their starts
/// constants there), one out-of-line copy on soft-float cores, where each of its
/// operations is a call into the float runtime anyway (flash per image, issue 64; the
/// wrench and `wrench_and_stiffness` keep [`horner_from`] inline).
#[cfg_attr(target_abi = "eabihf", inline(always))]
#[cfg_attr(not(target_abi = "eabihf"), inline(never))]
pub(crate) fn horner_from_shared(p: &[f32; TERMS], w: f32, start: Start) -> f32 {
    horner_from(p, w, start)
}

/// [`horner_with_rate_from`] as [`horner_from_shared`].
#[cfg_attr(target_abi = "eabihf", inline(always))]
#[cfg_attr(not(target_abi = "eabihf"), inline(never))]
pub(crate) fn horner_with_rate_from_shared(p: &[f32; TERMS], w: f32, start: Start) -> (f32, f32) {
    horner_with_rate_from(p, w, start)
}
