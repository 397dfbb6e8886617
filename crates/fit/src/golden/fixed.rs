//! `golden-fixed.csv` (coeffs/README.md, "Golden vectors"): Q16.16 poses and the expected
//! integer wrench and status of each, from this crate's own fixed-point implementation
//! ([`crate::eval::fixed`], tables from [`crate::fixed_formats`]).
//!
//! The pose list is fixed in code: a 5^5 grid over the domain, 1,000 ChaCha8 random poses
//! from [`GOLDEN_FIXED_SEED`], every input on, one unit inside and one unit outside its
//! bounds, the corners and just outside them, inputs far outside (up to `i32::MIN` and
//! `i32::MAX`), zeros, inputs on both sides of the normalisation's rounding points, and
//! poses in and around the set's unsolved region.

use crate::contract::COMPONENT_COUNT;
use crate::eval::fixed::{eval, DEPTH_DIVISOR, DEPTH_MAX_Q16, DIVISORS, HALF_RANGE_Q16, ONE};
use crate::fixed_formats::TablesFixed;
use crate::golden::GoldenCsvError;
use anyhow::{anyhow, Result};
use rand::{RngCore, SeedableRng};
use std::fmt::Write as _;
use std::path::Path;

/// Header line of golden-fixed.csv.
pub fn header() -> String {
    needle_contract::GOLDEN_FIXED_COLUMNS.join(",")
}

/// Seed of the random poses (ChaCha8).
pub const GOLDEN_FIXED_SEED: u64 = 0x6e65_6564_6c65_0002;

/// Number of random poses.
pub const RANDOM_POSES: usize = 1000;

fn bounds() -> ([i64; 5], [i64; 5]) {
    let max = [HALF_RANGE_Q16[0], HALF_RANGE_Q16[1], HALF_RANGE_Q16[2], HALF_RANGE_Q16[3], DEPTH_MAX_Q16];
    let min = [-max[0], -max[1], -max[2], -max[3], 0];
    (min, max)
}

/// An interior pose, every input nonzero and off the grid: 3.5, -2.25, 4.75, -9.5, 2.7.
const INTERIOR: [i32; 5] = [229_376, -147_456, 311_296, -622_592, 176_947];

fn with(i: usize, v: i64) -> [i32; 5] {
    let mut p = INTERIOR;
    p[i] = v.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32;
    p
}

/// Every golden pose `[x, z, theta_x, theta_z, depth]` in Q16.16, in file order, for a
/// set whose unsolved region has the balls `unsolved` (section 8: poses in and around
/// each ball, [`crate::unsolved::golden_poses_fixed`]).
pub fn poses(unsolved: &[crate::unsolved::Entry]) -> Vec<[i32; 5]> {
    let (min, max) = bounds();
    let mut out = Vec::with_capacity(4600);
    // 1. grid 5^5 with the edges (the bounds are multiples of 4)
    let g: Vec<[i32; 5]> = (0..5).map(|i| std::array::from_fn(|n| (min[i] + (max[i] - min[i]) * n as i64 / 4) as i32)).collect();
    out.extend(crate::golden::grid(&g));
    // 2. random poses, uniform over the domain
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(GOLDEN_FIXED_SEED);
    for _ in 0..RANDOM_POSES {
        out.push(std::array::from_fn(|i| {
            let span = (max[i] - min[i] + 1) as u64;
            (min[i] + (rng.next_u64() % span) as i64) as i32
        }));
    }
    // 3. bounds of each input: one unit outside, on, one unit inside
    for i in 0..5 {
        for b in [min[i], max[i]] {
            for v in [b - 1, b, b + 1] {
                out.push(with(i, v));
            }
        }
    }
    //    corners, and one unit outside every corner
    for m in 0..32u32 {
        let pick = |i: usize, outside: i64| if m & (1 << i) != 0 { max[i] + outside } else { min[i] - outside };
        out.push(std::array::from_fn(|i| pick(i, 0) as i32));
        out.push(std::array::from_fn(|i| pick(i, 1) as i32));
    }
    // 4. far outside the domain, on each input alone, then on all together
    for i in 0..5 {
        for v in [
            i64::from(i32::MIN),
            i64::from(i32::MIN) + 1,
            -(1 << 30),
            -100 * ONE,
            min[i] - ONE,
            max[i] + ONE,
            100 * ONE,
            1 << 30,
            i64::from(i32::MAX),
        ] {
            out.push(with(i, v));
        }
    }
    for s in [-1i64, 1] {
        out.push([13 * s, 13 * s, 16 * s, 16 * s, 3 + 4 * s].map(|v| (v * ONE) as i32));
        out.push([i32::MAX; 5].map(|v| (i64::from(v) * s) as i32));
        out.push([20 * s, -20 * s, 20 * s, -20 * s, 7].map(|v| (v * ONE) as i32));
    }
    out.push([i32::MIN; 5]);
    // 5. zeros: each input, then all
    for i in 0..5 {
        out.push(with(i, 0));
    }
    out.push([0; 5]);
    // 6. both sides of the rounding points of the normalisation, (n + d/2) / d, on each
    //    input and both signs
    let divisors = [DIVISORS[0], DIVISORS[1], DIVISORS[2], DIVISORS[3], DEPTH_DIVISOR];
    for (i, d) in divisors.iter().enumerate() {
        for m in [1i64, 4_321, 31_000] {
            let n = m * d - d / 2; // (n + d/2) / d steps from m - 1 to m here
            for v in [n - 1, n] {
                out.push(with(i, v));
                if i < 4 {
                    out.push(with(i, -v));
                }
            }
        }
    }
    // 7. the benchmark's typical pose (3, -2, 5, -7, 4.5)
    out.push([3 * ONE, -2 * ONE, 5 * ONE, -7 * ONE, 9 * ONE / 2].map(|v| v as i32));
    // 8. in and around the unsolved region
    out.extend(crate::unsolved::golden_poses_fixed(unsolved));
    out
}

/// The text of golden-fixed.csv for the tables `t`.
///
/// # Errors
/// An intermediate of a pose leaves the contract's range (the tables are wrong).
pub fn to_csv(t: &TablesFixed) -> Result<String> {
    let poses = poses(&t.unsolved);
    let mut s = String::with_capacity(96 * (poses.len() + 1));
    s.push_str(&header());
    s.push('\n');
    for p in poses {
        let (w, status) = eval(t, p).map_err(|e| anyhow!("fixed-point evaluation at {p:?}: {e}"))?;
        for v in p {
            let _ = write!(s, "{v},");
        }
        let _ = write!(s, "0x{status:02x}");
        for v in w {
            let _ = write!(s, ",{v}");
        }
        s.push('\n');
    }
    Ok(s)
}

/// One golden row.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FixedRow {
    /// `[x, z, theta_x, theta_z, depth]`, Q16.16.
    pub pose: [i32; 5],
    /// Status byte.
    pub status: u8,
    /// `[fx, fy, fz, mx, my, mz]`, µN and µN·mm.
    pub wrench: [i32; COMPONENT_COUNT],
}

/// Parse golden-fixed.csv text; `path` is only used in messages.
///
/// # Errors
/// Wrong header, a row without 12 fields, a malformed field (`path:line` in the message).
pub fn parse_csv(text: &str, path: &Path) -> Result<Vec<FixedRow>, GoldenCsvError> {
    crate::golden::parse_rows(text, path, &header(), |field, at| {
        let int = |s: &str| s.parse::<i32>().map_err(|_| GoldenCsvError::int(at, s));
        let mut pose = [0; 5];
        for (d, s) in pose.iter_mut().zip(&field[..5]) {
            *d = int(s)?;
        }
        let mut wrench = [0; COMPONENT_COUNT];
        for (d, s) in wrench.iter_mut().zip(&field[6..]) {
            *d = int(s)?;
        }
        Ok((pose, wrench))
    })
    .map(|rows| rows.into_iter().map(|(pose, status, wrench)| FixedRow { pose, status, wrench }).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fixed_rows_parse_and_a_bad_integer_names_the_line() {
        let good = format!("{}\n1,2,3,4,5,0x10,-1,-2,-3,-4,-5,-6\n", header());
        let rows = parse_csv(&good, Path::new("f.csv")).expect("good file");
        assert_eq!(rows, [FixedRow { pose: [1, 2, 3, 4, 5], status: 0x10, wrench: [-1, -2, -3, -4, -5, -6] }]);
        let bad = format!("{}\n1,2,3,4,5,0x10,-1,-2,-3,-4,-5,x\n", header());
        let e = format!("{:#}", parse_csv(&bad, Path::new("f.csv")).expect_err("refused"));
        assert_eq!(e, "f.csv:2: \"x\" is not an i32");
    }
}
