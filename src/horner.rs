//! Horner evaluation of a quartic, in the contract's exact operation order.

/// `h(p, w) = (((p4*w + p3)*w + p2)*w + p1)*w + p0`: every multiply and add rounded on
/// its own (Rust never fuses them into an FMA), highest power first.
#[inline(always)]
pub(crate) fn horner(p: &[f32; 5], w: f32) -> f32 {
    let [p0, p1, p2, p3, p4] = *p;
    (((p4 * w + p3) * w + p2) * w + p1) * w + p0
}

/// `g(q, w) = ((q3*w + q2)*w + q1)*w + q0`: the derivative of a quartic `p` when
/// `q = [p1, 2*p2, 3*p3, 4*p4]` (each product rounded to f32, see [`rate_coeffs`]).
#[inline(always)]
pub(crate) fn horner_rate(q: &[f32; 4], w: f32) -> f32 {
    let [q0, q1, q2, q3] = *q;
    ((q3 * w + q2) * w + q1) * w + q0
}

/// The coefficients of `d p / d w` for the quartic `p`: `[p1, 2*p2, 3*p3, 4*p4]`, each
/// product an f32 multiply rounded to nearest (the same bits in const evaluation as at
/// run time).
#[inline(always)]
pub(crate) const fn rate_coeffs(p: &[f32; 5]) -> [f32; 4] {
    let [_, p1, p2, p3, p4] = *p;
    [p1, 2.0 * p2, 3.0 * p3, 4.0 * p4]
}
