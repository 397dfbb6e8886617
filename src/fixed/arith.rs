//! The integer primitives of the fixed-point contract: the Q15 product and the
//! normalisation, the saturating `i64` product of the insertion and the depth extension,
//! and the 64-bit division (on the M0 a bitwise one of its own). All are exact (the same
//! integer on every core); only how they are computed differs, for speed or flash.
use needle_contract::TERMS;

/// `a b` saturated to the `i64` range (the insertion's and the depth extension's
/// products with a value of the stack or the model).
///
/// Out of line on every Arm core (one call instead of the product and its overflow test
/// at each use), inline on the host. Armv6-M has no 64-bit multiply: there it is several
/// library multiplies wherever it is inlined. Measured on the M0
/// (`no_panic_fixed_insertion`, elastic build, model flash as `needle firmware size`
/// counts it): 25,578 B with every product inlined, 24,086 B with the insertion's
/// `mul_shr` calling this, 23,394 B with the deflection's gains too, 22,638 B with the
/// depth extension's products too. On the M3 and M4F, with the insertion's split
/// products out of line as well (`insertion::track`): 22,838 -> 20,150 B and 22,798 ->
/// 20,184 B (with the `viscoelastic` feature 25,824 -> 22,924 B and 25,984 -> 22,968 B),
/// for about 3 % more instructions per surface tick (docs/insertion.md, "Cost").
///
/// Two factors within `i32` (a wrench component in µN and a gain, a depth and an
/// inverse) take one widening product, which cannot saturate; only the others take the
/// saturating one, which on the M0 is four library multiplies and its overflow tests
/// (about 220 instructions): the M0's fixed-point step deflecting rig_skin's surface
/// 20,125 -> 15,145 instructions with this and `mul_q30_wide`'s fast path (issue 64).
#[cfg_attr(target_arch = "arm", inline(never))]
#[cfg_attr(not(target_arch = "arm"), inline(always))]
pub(crate) fn sat_mul(a: i64, b: i64) -> i64 {
    match (i32::try_from(a), i32::try_from(b)) {
        // both within `i32`: `|a b| <= 2^62` never saturates, one widening product
        (Ok(a), Ok(b)) => i64::from(a).wrapping_mul(i64::from(b)),
        _ => a.saturating_mul(b),
    }
}

/// `x g / 2^30` (floor of each part) for `|x| < 2^60` and `0 <= g <= 2^31`: `x` split at
/// bit 30, `(x >> 30) g + ((x mod 2^30) g >> 30)`, each product below `2^61` (a wrench
/// component of any size times a Q30 ratio such as the material family's `g` or a
/// softening factor, where [`sat_mul`] would saturate and `insertion::track`'s `mul_q30`
/// (`|x| < 2^47`) could wrap). Saturating for any `x` and `g`; where neither product can
/// (`x >> 30` within `i32`, `0 <= g <= 2^31`), two widening products without the tests.
#[cfg_attr(target_arch = "arm", inline(never))]
#[cfg_attr(not(target_arch = "arm"), inline(always))]
pub(crate) fn mul_q30_wide(x: i64, g: i64) -> i64 {
    let (hi, lo) = (x >> 30, x & ((1 << 30) - 1));
    if let (Ok(hi), Ok(g), Ok(lo)) = (i32::try_from(hi), u32::try_from(g), u32::try_from(lo)) {
        if g <= 1 << 31 {
            // |hi g| <= 2^62 and lo g < 2^61: neither the product nor the sum saturates
            let low = (u64::from(lo) * u64::from(g)) >> 30;
            return (i64::from(hi) * i64::from(g)).wrapping_add(low as i64);
        }
    }
    // lo < 2^30 and g <= 2^31: lo g < 2^61 never wraps; `sat_mul` is `hi g` saturated
    // (its own copy of the saturating product: flash)
    sat_mul(hi, g).saturating_add(lo.wrapping_mul(g) >> 30)
}

/// Each of the six components of a wrench (µN Q16, any size) times the Q30 ratio `g`
/// (`0 <= g <= 2^31`: the material family's `g`, a softening factor): [`mul_q30_wide`]
/// per component. Out of line on every Arm core: one copy for the insertion's three
/// uses (flash, issue 64; only the `tissue-shape` feature's insertion calls it).
#[cfg_attr(target_arch = "arm", inline(never))]
#[cfg_attr(not(target_arch = "arm"), inline(always))]
#[cfg_attr(not(feature = "tissue-shape"), allow(dead_code))]
pub(crate) fn scale_q30(w: &mut [i64; 6], g: i64) {
    for x in w.iter_mut() {
        *x = mul_q30_wide(*x, g);
    }
}

/// `n / d` rounded down, `None` for `d = 0`: the value of `u64::checked_div`. On Armv6-M
/// ([`mul_q15`]'s `cfg`: no divide instruction) [`div_u64_bitwise`], so the compiler
/// runtime's 64-bit division (about 1.1 KiB with its signed and unsigned entry points) is
/// not linked into a fixed-point image (issue 64's flash per image); elsewhere the
/// operator.
#[cfg(not(all(target_arch = "arm", not(target_has_atomic = "32"))))]
#[inline(always)]
pub(crate) fn div_u64(n: u64, d: u64) -> Option<u64> {
    n.checked_div(d)
}

/// `n / d` rounded down, `None` for `d = 0` (Armv6-M: [`div_u64_bitwise`]).
#[cfg(all(target_arch = "arm", not(target_has_atomic = "32")))]
#[inline(always)]
pub(crate) fn div_u64(n: u64, d: u64) -> Option<u64> {
    div_u64_bitwise(n, d)
}

/// `n / d` rounded down, `None` for `d = 0`, one quotient bit per step (restoring
/// division: the remainder shifted left by one bit of `n` and `d` subtracted when it
/// fits): 228 bytes of Thumb code, about 1,080 instructions on the M0 for a divisor below
/// 2^31 (the insertion's per tick, `2^60 / a_y`; the runtime's division took about 500)
/// and 1,900 above. Exact: the same integer as `u64::checked_div` (tested against it on
/// the host).
#[cfg_attr(all(target_arch = "arm", not(target_has_atomic = "32")), inline(never))]
#[cfg_attr(not(all(target_arch = "arm", not(target_has_atomic = "32"))), allow(dead_code))]
pub(crate) fn div_u64_bitwise(n: u64, d: u64) -> Option<u64> {
    if d == 0 {
        return None;
    }
    if d >> 63 != 0 {
        // a divisor of 2^63 or more: the quotient is 0 or 1 (and the remainder below
        // would need a 65th bit)
        return Some(u64::from(n >= d));
    }
    if let Some(d) = u32::try_from(d).ok().filter(|&d| d < 1 << 31) {
        // a divisor below 2^31 (the insertion's per-tick one): 32-bit words only (`2 r + 1
        // < 2 d <= 2^32`), `n`'s high word then its low word (quotient bits replace the
        // word's bits as they leave): a third of the loop below's instructions
        let mut r = 0_u32;
        let mut word = |mut x: u32| {
            for _ in 0..32 {
                r = (r << 1) | (x >> 31);
                x <<= 1;
                if r >= d {
                    r -= d;
                    x |= 1;
                }
                // as below
                core::hint::black_box(());
            }
            x
        };
        let hi = word((n >> 32) as u32);
        let lo = word(n as u32);
        return Some((u64::from(hi) << 32) | u64::from(lo));
    }
    // `n`'s bits leave at the top as the quotient's enter at the bottom; `r < d < 2^63`
    let (mut q, mut r) = (n, 0_u64);
    for _ in 0..64 {
        r = (r << 1) | (q >> 63);
        q <<= 1;
        if r >= d {
            r -= d;
            q |= 1;
        }
        // an empty barrier (a store and a load of nothing): the Arm backend does not
        // unroll a loop with one (four copies of the step took 368 bytes on the M0; the
        // loop above unrolled, 588 bytes for 250 instructions less)
        core::hint::black_box(());
    }
    Some(q)
}

/// `n / d` rounded toward zero, `None` for `d = 0` and for `i64::MIN / -1`: the value of
/// `i64::checked_div` (Armv6-M: [`div_i64_bitwise`]).
#[cfg(not(all(target_arch = "arm", not(target_has_atomic = "32"))))]
#[inline(always)]
pub(crate) fn div_i64(n: i64, d: i64) -> Option<i64> {
    n.checked_div(d)
}

/// `n / d` rounded toward zero, `None` for `d = 0` and for `i64::MIN / -1`.
#[cfg(all(target_arch = "arm", not(target_has_atomic = "32")))]
#[inline(always)]
pub(crate) fn div_i64(n: i64, d: i64) -> Option<i64> {
    div_i64_bitwise(n, d)
}

/// `i64::checked_div` through [`div_u64_bitwise`] on the magnitudes.
#[inline(always)]
#[cfg_attr(not(all(target_arch = "arm", not(target_has_atomic = "32"))), allow(dead_code))]
pub(crate) fn div_i64_bitwise(n: i64, d: i64) -> Option<i64> {
    if n == i64::MIN && d == -1 {
        return None;
    }
    // |n| / |d| <= 2^63, and 2^63 only for n = i64::MIN, d = 1: `as` gives i64::MIN
    let q = div_u64_bitwise(n.unsigned_abs(), d.unsigned_abs())? as i64;
    Some(if (n < 0) != (d < 0) { q.wrapping_neg() } else { q })
}

/// `floor(a * w / 2^15)`, for `|a| <= 2^30` and `|w| <= 2^15` (the generator proves both
/// for every call): the Q15 product of a Horner step.
///
/// Cores with a 32 x 32 -> 64-bit multiply (Armv7-M `smull`, every host) take the 64-bit
/// product and shift it.
#[cfg(not(all(target_arch = "arm", not(target_has_atomic = "32"))))]
#[inline(always)]
pub(crate) fn mul_q15(a: i32, w: i32) -> i32 {
    ((i64::from(a) * i64::from(w)) >> 15) as i32
}

/// `floor(a * w / 2^15)`, for `|a| <= 2^30` and `|w| <= 2^15`.
///
/// Armv6-M (Cortex-M0/M0+, the only Arm M-profile without 32-bit atomics, which is how
/// `cfg` tells it apart: rustc has no architecture-version `cfg` for these targets) has
/// no 64-bit multiply, and `i64 * i64` would be a library call. With
/// `a = hi * 2^16 + lo` (`0 <= lo < 2^16`):
/// `floor(a w / 2^15) = 2 hi w + floor(lo w / 2^15)` exactly, from two 32-bit `muls`.
/// No overflow: `|lo w| < 2^16 * 2^15 = 2^31`, `|hi| <= 2^14` so `|2 hi w| <= 2^30`.
#[cfg(all(target_arch = "arm", not(target_has_atomic = "32")))]
#[inline(always)]
pub(crate) fn mul_q15(a: i32, w: i32) -> i32 {
    let hi = a >> 16;
    let lo = a & 0xffff;
    hi.wrapping_mul(w).wrapping_shl(1).wrapping_add(lo.wrapping_mul(w) >> 15)
}

/// `(n + divisor / 2) / divisor - 32768`: a clamped Q16.16 magnitude (`n <= 6 * 2^16`,
/// `12 * 2^16` or `15 * 2^16`) to its normalised Q15 value in `[-32768, 32768]`, rounded
/// to nearest.
#[inline(always)]
pub(crate) fn normalise(n: u32, divisor: u32) -> i32 {
    // `divisor` is one of the generated constants 6, 12, 15: never zero. `checked_div`
    // keeps the no-panic guarantee without relying on that.
    match n.wrapping_add(divisor >> 1).checked_div(divisor) {
        Some(q) => (q as i32).wrapping_sub(32768),
        None => 0,
    }
}

/// `v` clamped to `lo..=hi`, and whether it changed.
#[inline(always)]
pub(crate) fn clamp(v: i32, lo: i32, hi: i32) -> (i32, bool) {
    if v < lo {
        (lo, true)
    } else if v > hi {
        (hi, true)
    } else {
        (v, false)
    }
}

/// Where the integer Horner of `p` may start: the index of its highest nonzero
/// coefficient (0 when none is). The steps above it change nothing: the accumulator is 0
/// there, `floor(0 * w / 2^15) = 0` and `0 + 0 = 0` (an integer has one zero, so unlike
/// the f32 Horner there is no sign to keep). For the generated tables, in const items.
pub(crate) const fn start(p: &[i32; TERMS]) -> u8 {
    let mut rest: &[i32] = p;
    let (mut index, mut top) = (0_u8, 0_u8);
    while let [first, tail @ ..] = rest {
        if *first != 0 {
            top = index;
        }
        index += 1;
        rest = tail;
    }
    top
}

/// [`horner`] from the coefficient at `start` ([`start`]; 4 or more: every step): the
/// same integer. Cores with a 64-bit multiply (measured on the coupled default model,
/// `needle firmware bench` and `size`: fixed-point wrench M4F 4,702.0 -> 4,070.9
/// instructions for +184 B of flash, M3 4,603.0 -> 4,068.1 for +268 B).
#[cfg(not(all(target_arch = "arm", not(target_has_atomic = "32"))))]
#[inline(always)]
pub(crate) fn horner_from(p: &[i32; TERMS], w: i32, start: u8) -> i32 {
    let [p0, p1, p2, p3, _] = *p;
    match start {
        0 => p0,
        1 => mul_q15(p1, w).wrapping_add(p0),
        2 => mul_q15(mul_q15(p2, w).wrapping_add(p1), w).wrapping_add(p0),
        3 => horner3(&[p0, p1, p2, p3], w),
        _ => horner(p, w),
    }
}

/// [`horner`], every step, on Armv6-M: there a copy of the step per start cost
/// 1,386 B of flash (13,898 -> 15,284 B, 1.1 KiB below the 16 KiB goal) for 9 % of the
/// fixed-point wrench's instructions (8,105.0 -> 7,368.9), and one loop over the steps
/// left cost more of both (10,239.0 instructions, 17,282 B).
#[cfg(all(target_arch = "arm", not(target_has_atomic = "32")))]
#[inline(always)]
pub(crate) fn horner_from(p: &[i32; TERMS], w: i32, _start: u8) -> i32 {
    horner(p, w)
}

/// `h(p, w) = (((p4 w + p3) w + p2) w + p1) w + p0` with every product [`mul_q15`]:
/// the contract's Horner step in Q15.
#[inline(always)]
pub(crate) fn horner(p: &[i32; TERMS], w: i32) -> i32 {
    let [p0, p1, p2, p3, p4] = *p;
    let a = mul_q15(p4, w).wrapping_add(p3);
    let a = mul_q15(a, w).wrapping_add(p2);
    let a = mul_q15(a, w).wrapping_add(p1);
    mul_q15(a, w).wrapping_add(p0)
}

/// `h3(p, w) = ((p3 w + p2) w + p1) w + p0` with every product [`mul_q15`]: the Horner
/// of a cubic (a quartic's derivative) in Q15.
#[inline(always)]
pub(crate) fn horner3(p: &[i32; 4], w: i32) -> i32 {
    let [p0, p1, p2, p3] = *p;
    let a = mul_q15(p3, w).wrapping_add(p2);
    let a = mul_q15(a, w).wrapping_add(p1);
    mul_q15(a, w).wrapping_add(p0)
}

/// `floor((n + (d >> 1)) / d)`: `n / d` rounded to nearest (ties up for an even `d`), for
/// the rate divisors `3 * 2^(G-R)` and `6 * 2^(G-R)` (never zero); `0` for `d = 0`.
#[inline(always)]
pub(crate) fn div_round(n: i32, d: i32) -> i32 {
    // `checked_div_euclid` keeps the no-panic guarantee (zero divisor, `MIN / -1`)
    // without relying on the generated divisors.
    n.wrapping_add(d >> 1).checked_div_euclid(d).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Values around the edges of 64-bit division: powers of two and their neighbours,
    /// the extremes, and a few odd numbers.
    fn edges() -> impl Iterator<Item = u64> + Clone {
        let powers = (0..64).flat_map(|e| {
            let p = 1_u64 << e;
            [p - 1, p, p.wrapping_add(1), p.wrapping_add(p >> 1)]
        });
        [0, 3, 7, 15_625, 1_000_000 << 16, 0x9e37_79b9_7f4a_7c15, u64::MAX - 1, u64::MAX].into_iter().chain(powers)
    }

    /// The bitwise division (the M0's) is `u64::checked_div`, and the signed one
    /// `i64::checked_div`, on every pair of edge values and their signs.
    #[test]
    fn the_bitwise_division_is_the_operators() {
        for n in edges() {
            for d in edges() {
                assert_eq!(div_u64_bitwise(n, d), n.checked_div(d), "{n} / {d}");
                assert_eq!(div_u64(n, d), n.checked_div(d), "{n} / {d}");
                for (a, b) in [(n as i64, d as i64), (n as i64, (d as i64).wrapping_neg())] {
                    assert_eq!(div_i64_bitwise(a, b), a.checked_div(b), "{a} / {b}");
                    assert_eq!(div_i64(a, b), a.checked_div(b), "{a} / {b}");
                }
            }
        }
    }

    /// The products with one widening multiply where they cannot saturate are the
    /// saturating products' integers, at and around the fast paths' edges.
    #[test]
    fn the_fast_products_are_the_saturating_ones() {
        let values = || edges().flat_map(|v| [v as i64, (v as i64).wrapping_neg()]);
        for a in values() {
            for b in values() {
                assert_eq!(sat_mul(a, b), a.saturating_mul(b), "{a} * {b}");
            }
            for g in [0, 1, 3, (1 << 30) - 1, 1 << 30, (1 << 31) - 1, 1 << 31] {
                let (hi, lo) = (a >> 30, a & ((1 << 30) - 1));
                let want = hi.saturating_mul(g).saturating_add(lo.wrapping_mul(g) >> 30);
                assert_eq!(mul_q30_wide(a, g), want, "{a} * {g} / 2^30");
            }
        }
    }
}
