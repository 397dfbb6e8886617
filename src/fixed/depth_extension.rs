//! [`extended_wrench`]: the fixed-point surrogate past the model's depth domain (6 mm),
//! the integer form of [`crate::extended_wrench`]'s law (coeffs/README.md, "Depth
//! extension").
//!
//! The law: `w(pose, d) = w(pose, 6 mm) R(d)` for `6 < d <= DEPTH_MAX_MM`, with
//! `v = (d - 6) / (DEPTH_MAX_MM - 6)` and `R = 1 + v (c1 + v (c2 + v (c3 + v c4)))`. Here
//! `v` and `R` are Q30 integers (`i64`): the constants below are the f32 tables'
//! values converted once, at compile time (`const` evaluation on the build host: the
//! same integers for every target), and every product is `floor(a b / 2^30)`. Each
//! component is `round(w_c(pose, 6) R / 2^30)` µN or µN·mm, saturated to `i32`. At
//! `d <= 6` it is [`wrench`] itself; past `DEPTH_MAX_MM` the depth is clamped and
//! `SAT_DEPTH` set; a set without the extension saturates at 6 mm as [`wrench`] does.
//!
//! Against the f32 law the integer one differs by the fixed-point model's error bound at
//! 6 mm times `R` plus the rounding of `R` (below 2^-28 relative): the accuracy test in
//! `host-tests/tests/insertion_fixed.rs` bounds the whole insertion.
use super::arith::sat_mul;
use super::{wrench, Evaluation, Pose, Wrench};
use crate::float::depth_extension::tables as f32_tables;
use crate::Status;

const Q30: f64 = (1u64 << 30) as f64;

/// `x` rounded to the nearest integer (ties away from zero), in `const` evaluation.
pub(crate) const fn round_i64(x: f64) -> i64 {
    if x >= 0.0 {
        (x + 0.5) as i64
    } else {
        (x - 0.5) as i64
    }
}

/// The model's depth domain, 6 mm in Q16.16 (the fixed tables').
const MODEL_DEPTH_MAX_Q16: i32 = super::tables::DEPTH_MAX_MM_Q16;

/// Deepest depth of the extension, mm in Q16.16.
pub const DEPTH_MAX_MM_Q16: i32 = round_i64(f32_tables::DEPTH_MAX_MM as f64 * 65536.0) as i32;

/// `1 / (DEPTH_MAX_MM - 6)`, 1/mm in Q30.
const INV_SPAN_Q30: i64 = round_i64(f32_tables::INV_SPAN_PER_MM as f64 * Q30);

/// `c_1 .. c_4` in Q30.
const COEFFS_Q30: [i64; 4] = {
    let [c1, c2, c3, c4] = f32_tables::COEFFS;
    [round_i64(c1 as f64 * Q30), round_i64(c2 as f64 * Q30), round_i64(c3 as f64 * Q30), round_i64(c4 as f64 * Q30)]
};

/// `floor(a b / 2^30)`.
#[inline(always)]
fn mul_q30(a: i64, b: i64) -> i64 {
    sat_mul(a, b) >> 30
}

/// `R(v)` in Q30 for `v` in Q30 (`0 <= v <= 2^30`).
fn ratio_q30(v: i64) -> i64 {
    let [c1, c2, c3, c4] = COEFFS_Q30;
    (1 << 30) + mul_q30(v, c1 + mul_q30(v, c2 + mul_q30(v, c3 + mul_q30(v, c4))))
}

/// The fixed-point wrench at `pose`, extended in depth past the model's domain (the
/// module's law). Never panics.
#[must_use]
pub fn extended_wrench(pose: &Pose) -> Evaluation {
    let d = pose.depth_mm_q16;
    if !f32_tables::FITTED || d <= MODEL_DEPTH_MAX_Q16 {
        return wrench(pose);
    }
    let (depth, clamped) = if d > DEPTH_MAX_MM_Q16 { (DEPTH_MAX_MM_Q16, true) } else { (d, false) };
    let at6 = wrench(&Pose { depth_mm_q16: MODEL_DEPTH_MAX_Q16, ..*pose });
    if at6.status.is_error() {
        return at6;
    }
    // depth - 6 mm in Q16 times 1/mm in Q30, over 2^16: v in Q30
    let v = sat_mul(i64::from(depth) - i64::from(MODEL_DEPTH_MAX_Q16), INV_SPAN_Q30) >> 16;
    let r = ratio_q30(v);
    let w = at6.wrench.to_array().map(|c| round_shr_i32(sat_mul(i64::from(c), r), 30));
    let status = if clamped { at6.status | Status::SAT_DEPTH } else { at6.status };
    Evaluation { wrench: Wrench::from_array(w), status }
}

/// `v` saturated to the `i32` range. Written on the two 32-bit words (`v` fits when its
/// high word is its low word's sign extension; else `i32::MAX` or `i32::MIN` by the high
/// word's sign): no 64-bit comparison, which Armv6-M has no instruction for (the
/// two-comparison form took about 65 B a use there).
#[inline(always)]
pub(crate) fn saturate_i32(v: i64) -> i32 {
    let (hi, lo) = ((v >> 32) as i32, v as i32);
    if hi == lo >> 31 {
        lo
    } else {
        (hi >> 31) ^ i32::MAX
    }
}

/// `floor(v / 2^s + 1/2)` saturated to the `i32` range, for `1 <= s <= 62`: the value of
/// `saturate_i32(v.saturating_add(1 << (s - 1)) >> s)` for every `v`, the rounding bit
/// added after the shift (no 64-bit saturating sum). Out of line on the Arm cores (one
/// call per component instead of the 64-bit comparisons: with the ramp's loops over the
/// terms in use, the fixed-point insertion image with the filter on the M0 went from
/// 24,974 to 24,562 B).
#[cfg_attr(target_arch = "arm", inline(never))]
#[cfg_attr(not(target_arch = "arm"), inline(always))]
pub(crate) fn round_shr_i32(v: i64, s: u32) -> i32 {
    saturate_i32((v >> s) + ((v >> (s - 1)) & 1))
}
