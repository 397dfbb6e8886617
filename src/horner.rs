//! Horner evaluation of a quartic, in the contract's exact operation order.
use needle_contract::TERMS;

/// `h(p, w) = (((p4*w + p3)*w + p2)*w + p1)*w + p0` (for the contract's degree 4):
/// every multiply and add rounded on its own (Rust never fuses them into an FMA),
/// highest power first, starting from the highest coefficient itself (not `0*w + p4`,
/// which would turn a `-0.0` into `+0.0`).
#[inline(always)]
pub(crate) fn horner(p: &[f32; TERMS], w: f32) -> f32 {
    let [lower @ .., top] = p;
    lower.iter().rev().fold(*top, |acc, &c| acc * w + c)
}

/// `h(p, w)` and `h'(p, w)` together (coeffs/README.md, "Stiffness"): the value by the
/// operations of [`horner`] (the same bits), the derivative accumulated alongside,
/// `d = p4`, then `d = d*w + b` after each of the value's steps for `p3`, `p2`, `p1`
/// (`b` the value so far), 3 multiplies and 3 adds more, no further coefficient loads.
#[inline(always)]
pub(crate) fn horner_with_rate(p: &[f32; TERMS], w: f32) -> (f32, f32) {
    let [p0, middle @ .., top] = p;
    // (b, d): the value and the derivative so far, both starting at the top coefficient
    let (b, d) = middle.iter().rev().fold((*top, *top), |(b, d), &c| {
        let b = b * w + c;
        (b, d * w + b)
    });
    (b * w + p0, d)
}
