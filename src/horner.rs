//! Horner evaluation of a quartic, in the contract's exact operation order.
use needle_contract::TERMS;

/// `h(p, w) = (((p4*w + p3)*w + p2)*w + p1)*w + p0`: every multiply and add rounded on
/// its own (Rust never fuses them into an FMA), highest power first.
#[inline(always)]
pub(crate) fn horner(p: &[f32; TERMS], w: f32) -> f32 {
    let [p0, p1, p2, p3, p4] = *p;
    (((p4 * w + p3) * w + p2) * w + p1) * w + p0
}

/// `h(p, w)` and `h'(p, w)` together (coeffs/README.md, "Stiffness"): the value by the
/// operations of [`horner`] (the same bits), the derivative accumulated alongside,
/// `d = p4`, then `d = d*w + b` after each of the value's steps for `p3`, `p2`, `p1`
/// (`b` the value so far), 3 multiplies and 3 adds more, no further coefficient loads.
#[inline(always)]
pub(crate) fn horner_with_rate(p: &[f32; TERMS], w: f32) -> (f32, f32) {
    let [p0, p1, p2, p3, p4] = *p;
    let b3 = p4 * w + p3;
    let d3 = p4 * w + b3;
    let b2 = b3 * w + p2;
    let d2 = d3 * w + b2;
    let b1 = b2 * w + p1;
    let d1 = d2 * w + b1;
    (b1 * w + p0, d1)
}
