//! [`ratio`]: the material family's law in integers, the fixed-point form of
//! [`crate::float::family::ratio`] (coeffs/README.md, "The material family").
//!
//! The law's constants are the f32 tables' values converted once, in `const` evaluation
//! on the build host (the same integers for every target): the coefficients `a_jk` to
//! Q30, the multipliers of at most 1 in magnitude (a member's `w`, `1 - w`, `sqrt(w)`
//! ([`FamilyMember::from_f32`]), `u = d / DEPTH_MAX_MM`) to Q24, so that a Q30 value up to
//! 2^9 = 512 times a Q24 multiplier stays inside `i64` (saturating beyond). Every product
//! is `floor(a m / 2^24)`, in the f32 law's order: rows `c_j = (a_j2 t + a_j1) t + a_j0`,
//! then Horner in `u`, then `g = 2^30 + (1 - w) p` (Q30). The depth is clamped to
//! `0 ..= DEPTH_MAX_MM` (the rate is then 0); a set without the law and the paper's weight
//! give exactly `2^30`.
use super::arith::sat_mul;
use super::depth_extension::round_i64;
use crate::float::family::{tables as f32_tables, FamilyMember as FamilyMember32};

const Q30: f64 = (1u64 << 30) as f64;
const Q24: f64 = (1u64 << 24) as f64;
const ONE_Q30: i64 = 1 << 30;
const ONE_Q24: i64 = 1 << 24;

/// Deepest depth of the law, mm in Q16.16.
const DEPTH_MAX_MM_Q16: i32 = round_i64(f32_tables::DEPTH_MAX_MM as f64 * 65536.0) as i32;

/// `1 / DEPTH_MAX_MM`, 1/mm in Q30 (for `u`) and in Q24 (the rate's multiplier).
const INV_DEPTH_MAX_Q30: i64 = round_i64(f32_tables::INV_DEPTH_MAX_PER_MM as f64 * Q30);
const INV_DEPTH_MAX_Q24: i64 = round_i64(f32_tables::INV_DEPTH_MAX_PER_MM as f64 * Q24);

/// `a_jk` in Q30.
const COEFFS_Q30: [[i64; 3]; 5] = {
    const fn row(r: [f32; 3]) -> [i64; 3] {
        let [a0, a1, a2] = r;
        [round_i64(a0 as f64 * Q30), round_i64(a1 as f64 * Q30), round_i64(a2 as f64 * Q30)]
    }
    let [r0, r1, r2, r3, r4] = f32_tables::COEFFS;
    [row(r0), row(r1), row(r2), row(r3), row(r4)]
};

/// A member of the family in integers: `w` and `sqrt(w)` in Q24 (8 bytes: a compiled-in
/// stack holds one per layer slot).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FamilyMember {
    weight_q24: i32,
    sqrt_weight_q24: i32,
}

impl Default for FamilyMember {
    /// The paper's own tissue.
    fn default() -> Self {
        Self::PAPER
    }
}

impl FamilyMember {
    /// The paper's own tissue (`w = 1`).
    pub const PAPER: Self = Self { weight_q24: ONE_Q24 as i32, sqrt_weight_q24: ONE_Q24 as i32 };

    /// The f32 member's values rounded to Q24 (`const`: compiled-in stacks convert on the
    /// build host). A weight and its root are within `0 ..= 1` (`float::family::FamilyMember`),
    /// so both fit `i32`; anything else is refused as out of range (`weight_q24` -1).
    #[must_use]
    pub const fn from_f32(m: &FamilyMember32) -> Self {
        let (w, t) = (round_i64(m.weight() as f64 * Q24), round_i64(m.sqrt_weight() as f64 * Q24));
        if w < 0 || w > ONE_Q24 || t < 0 || t > ONE_Q24 {
            return Self { weight_q24: -1, sqrt_weight_q24: 0 };
        }
        Self { weight_q24: w as i32, sqrt_weight_q24: t as i32 }
    }

    /// `w` in Q24.
    #[must_use]
    pub const fn weight_q24(&self) -> i64 {
        self.weight_q24 as i64
    }
}

/// `floor(a m / 2^24)` of a Q30 value `a` and a Q24 multiplier `m`, saturating: the
/// product of [`sat_mul`], with one widening product where it cannot saturate (`|a| <
/// 2^37` and `0 <= m < 2^25`, as every multiplier of the law is: `|a m| < 2^63`), so the
/// same integers on every core. Out of line on the Arm cores (one copy for the law's 15
/// products: flash).
#[cfg_attr(target_arch = "arm", inline(never))]
#[cfg_attr(not(target_arch = "arm"), inline(always))]
fn mul_m(a: i64, m: i64) -> i64 {
    match (i32::try_from(a >> 6), u32::try_from(m)) {
        (Ok(_), Ok(m32)) if m32 < 1 << 25 => a.wrapping_mul(i64::from(m32)) >> 24,
        _ => sat_mul(a, m) >> 24,
    }
}

/// `g(d, w)` in Q30 and its rate by depth, 1/mm in Q30, at `depth_mm_q16` (the module's
/// law). Never panics.
#[must_use]
pub fn ratio(depth_mm_q16: i32, member: &FamilyMember) -> (i64, i64) {
    if !f32_tables::FITTED {
        return (ONE_Q30, 0);
    }
    let law = Law { depth_max_mm_q16: DEPTH_MAX_MM_Q16, inv_depth_max_q30: INV_DEPTH_MAX_Q30, inv_depth_max_q24: INV_DEPTH_MAX_Q24 };
    ratio_of(&law, depth_mm_q16, member, &COEFFS_Q30)
}

/// Bytes of the law's constants in integers (the coefficients, the depth and its two
/// inverses): the fixed-point family's tables, at most what they put in flash (issue 64's
/// goal for the family's tables, f32 and integer together: <= 1 KiB;
/// host-tests/tests/firmware_no_panic.rs).
pub const TABLE_BYTES: usize =
    bytes_of(&COEFFS_Q30) + bytes_of(&DEPTH_MAX_MM_Q16) + bytes_of(&INV_DEPTH_MAX_Q30) + bytes_of(&INV_DEPTH_MAX_Q24);

/// The size of `value`'s type, bytes (`size_of_val` in a `const` needs a newer Rust than
/// the crate's MSRV).
const fn bytes_of<T>(_value: &T) -> usize {
    core::mem::size_of::<T>()
}

/// A law's depth constants in integers (the generated ones, or a test's).
struct Law {
    depth_max_mm_q16: i32,
    inv_depth_max_q30: i64,
    inv_depth_max_q24: i64,
}

/// [`ratio`] of `law`, whose coefficients `a_jk` are `coeffs_q30`.
fn ratio_of(law: &Law, depth_mm_q16: i32, member: &FamilyMember, coeffs_q30: &[[i64; 3]; 5]) -> (i64, i64) {
    let (w, t) = (i64::from(member.weight_q24), i64::from(member.sqrt_weight_q24));
    if w >= ONE_Q24 {
        return (ONE_Q30, 0);
    }
    let (d, clamped) = if depth_mm_q16 <= 0 {
        (0, true)
    } else if depth_mm_q16 >= law.depth_max_mm_q16 {
        (law.depth_max_mm_q16, true)
    } else {
        (depth_mm_q16, false)
    };
    // mm in Q16 times 1/mm in Q30 is Q46; over 2^22: u in Q24
    let u = sat_mul(i64::from(d), law.inv_depth_max_q30) >> 22;
    // the rows at the member: the integers of `rows_of`
    let [c0, c1, c2, c3, c4] = coeffs_q30.map(|[a0, a1, a2]| mul_m(mul_m(a2, t).saturating_add(a1), t).saturating_add(a0));
    let p = mul_m(mul_m(mul_m(mul_m(c4, u).saturating_add(c3), u).saturating_add(c2), u).saturating_add(c1), u).saturating_add(c0);
    let dp = mul_m(mul_m(mul_m(sat_mul(4, c4), u).saturating_add(sat_mul(3, c3)), u).saturating_add(sat_mul(2, c2)), u).saturating_add(c1);
    let soft = ONE_Q24 - w;
    let rate = if clamped { 0 } else { mul_m(mul_m(dp, soft), law.inv_depth_max_q24) };
    (ONE_Q30.saturating_add(mul_m(p, soft)), rate)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::float::family as f32_family;

    /// The integer law against the f32 law with the same constants: within 2e-6 (the Q24
    /// multipliers round at 6e-8 relative, times coefficients up to about 2 summed over 15
    /// products; f32 rounds at 6e-8).
    #[test]
    fn the_integer_law_follows_the_f32_law() {
        let coeffs: [[f32; 3]; 5] = core::array::from_fn(|j| core::array::from_fn(|k| 0.37 * (j as f32 - 2.0) + 0.21 * k as f32 - 0.05));
        let inv = (1.0 / 16.2f64) as f32;
        let law32 = f32_family::Law { depth_max_mm: 16.2, inv_depth_max_per_mm: inv, coeffs };
        let law = Law {
            depth_max_mm_q16: round_i64(16.2f32 as f64 * 65536.0) as i32,
            inv_depth_max_q30: round_i64(inv as f64 * Q30),
            inv_depth_max_q24: round_i64(inv as f64 * Q24),
        };
        let coeffs_q30 = coeffs.map(|row| row.map(|a| round_i64(a as f64 * Q30)));
        let weights = [0.0f32, 0.002, 0.05, 0.3, 0.9, 1.0];
        let members = weights.map(f32_family::FamilyMember::new);
        assert!(members.iter().all(Option::is_some), "every weight in 0..=1 makes a member");
        for (&w, m32) in weights.iter().zip(members.iter().flatten()) {
            let m = FamilyMember::from_f32(m32);
            for d in [0.0f32, 0.1, 1.0, 4.5, 9.0, 16.0, 17.0] {
                let (g32, r32) = f32_family::ratio_of(&law32, d, m32);
                let (g, r) = ratio_of(&law, round_i64(d as f64 * 65536.0) as i32, &m, &coeffs_q30);
                let (g, r) = (g as f64 / Q30, r as f64 / Q30);
                assert!((g - g32 as f64).abs() <= 2e-6, "w {w} d {d}: {g} vs {g32}");
                assert!((r - r32 as f64).abs() <= 2e-6, "w {w} d {d}: rate {r} vs {r32}; g {g} vs {g32}");
            }
        }
        assert_eq!(ratio_of(&law, 5 << 16, &FamilyMember::PAPER, &coeffs_q30), (ONE_Q30, 0));
    }

    /// The law's product with one widening multiply where it cannot saturate is the
    /// saturating product's integer (issue 64's M0 cost), at and around its fast path's
    /// edges: `|a|` near 2^37, `m` near 2^25, and the signs.
    #[test]
    fn the_laws_product_is_the_saturating_product() {
        let edges = [24_u32, 25, 30, 31, 32, 36, 37, 38, 40, 62].map(|e| [(1_i64 << e) - 1, 1 << e, (1 << e) + 1]);
        let special = [0_i64, 1, 3, i64::MAX, i64::MIN, i64::MAX / 3];
        let values = || special.into_iter().chain(edges.into_iter().flatten()).flat_map(|v| [v, v.wrapping_neg()]);
        for a in values() {
            for m in values() {
                assert_eq!(mul_m(a, m), a.saturating_mul(m) >> 24, "a {a} m {m}");
            }
        }
        let member = f32_family::FamilyMember::new(0.3);
        assert!(member.is_some(), "a member");
        let t = member.map_or(0, |m| i64::from(FamilyMember::from_f32(&m).sqrt_weight_q24));
        assert!(t > 0 && t < ONE_Q24, "sqrt(0.3) in Q24: {t}");
    }
}
