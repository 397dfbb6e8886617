//! Horner evaluation of a quartic, in the contract's exact operation order.

/// `h(p, w) = (((p4*w + p3)*w + p2)*w + p1)*w + p0`: every multiply and add rounded on
/// its own (Rust never fuses them into an FMA), highest power first.
#[inline(always)]
pub(crate) fn horner(p: &[f32; 5], w: f32) -> f32 {
    let [p0, p1, p2, p3, p4] = *p;
    (((p4 * w + p3) * w + p2) * w + p1) * w + p0
}
