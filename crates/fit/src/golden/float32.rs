//! `golden-f32.csv` (coeffs/README.md, "Golden vectors"): the poses, and the expected f32
//! wrench and status of each from this crate's own evaluator ([`crate::eval::float32`]).
//!
//! The pose list is fixed in code and reproducible: a 5^5 grid over the domain, 1,000
//! ChaCha8 random poses from [`GOLDEN_SEED`], the domain's bounds (on, one ulp inside, one
//! ulp outside) and corners, out-of-domain values on each input and on all together,
//! negative zeros, NaNs (quiet, with payload, negative, signalling), infinities and
//! subnormals in each input, and poses in and around the set's unsolved region (its
//! balls' centres, depths either side of their thresholds, offsets of half and twice the
//! radius).

use crate::contract::COMPONENT_COUNT;
use crate::eval::float32::{eval, Tables32};
use crate::golden::GoldenCsvError;
use crate::model_file::{hex32, parse_hex32};
use anyhow::Result;
use rand::RngCore;
use rand::SeedableRng;
use std::fmt::Write as _;
use std::path::Path;

/// Header line of golden-f32.csv.
pub fn header() -> String {
    needle_contract::GOLDEN_COLUMNS.join(",")
}

/// Seed of the random golden poses (ChaCha8).
pub const GOLDEN_SEED: u64 = 0x6e65_6564_6c65_0001;

/// Number of random golden poses.
pub const RANDOM_POSES: usize = 1000;

/// Upper bound of each input's range: x, z (mm), theta_x, theta_z (deg), depth (mm).
const MAX: [f32; 5] = {
    let [x, z, tx, tz] = needle_contract::HALF_RANGES;
    [x as f32, z as f32, tx as f32, tz as f32, needle_contract::DEPTH_MAX_MM as f32]
};
/// Lower bound of each input's range (depth from 0).
const MIN: [f32; 5] = {
    let [x, z, tx, tz, _] = MAX;
    [-x, -z, -tx, -tz, 0.0]
};
/// An interior pose, all inputs nonzero and not on a grid line.
const INTERIOR: [f32; 5] = [3.5, -2.25, 4.75, -9.5, 2.7];

fn next_up(v: f32) -> f32 {
    let b = v.to_bits();
    if v == 0.0 {
        f32::from_bits(1)
    } else if v > 0.0 {
        f32::from_bits(b + 1)
    } else {
        f32::from_bits(b - 1)
    }
}

fn next_down(v: f32) -> f32 {
    -next_up(-v)
}

/// Uniform f64 in [0, 1) from 53 random bits.
fn unit(rng: &mut rand_chacha::ChaCha8Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

fn with(i: usize, v: f32) -> [f32; 5] {
    let mut p = INTERIOR;
    p[i] = v;
    p
}

/// Every golden pose `[x_mm, z_mm, theta_x_deg, theta_z_deg, depth_mm]`, in file order,
/// for a set whose unsolved region has the balls `unsolved` (section 8: poses in and
/// around each ball, [`crate::unsolved::golden_poses_f32`]).
pub fn poses(unsolved: &[crate::unsolved::Entry]) -> Vec<[f32; 5]> {
    let mut out = Vec::with_capacity(4500);
    // 1. grid 5 x 5 x 5 x 5 x 5 with the edges
    let lin = |i: usize| -> [f32; 5] {
        let (lo, hi) = (MIN[i], MAX[i]);
        [lo, lo + (hi - lo) * 0.25, lo + (hi - lo) * 0.5, lo + (hi - lo) * 0.75, hi]
    };
    let g: Vec<[f32; 5]> = (0..5).map(lin).collect();
    out.extend(crate::golden::grid(&g));
    // 2. random poses, uniform over the domain
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(GOLDEN_SEED);
    for _ in 0..RANDOM_POSES {
        let mut p = [0.0f32; 5];
        for (i, v) in p.iter_mut().enumerate() {
            let (lo, hi) = (f64::from(MIN[i]), f64::from(MAX[i]));
            *v = (lo + (hi - lo) * unit(&mut rng)) as f32;
        }
        out.push(p);
    }
    // 3. the bounds of each input: one ulp outside, on, one ulp inside
    for i in 0..5 {
        for b in [MIN[i], MAX[i]] {
            for v in [next_down(b), b, next_up(b)] {
                out.push(with(i, v));
            }
        }
    }
    //    corners of the 5-D box, and just outside every corner
    for m in 0..32u32 {
        let corner: [f32; 5] = std::array::from_fn(|i| if m & (1 << i) != 0 { MAX[i] } else { MIN[i] });
        out.push(corner);
        out.push(std::array::from_fn(|i| if m & (1 << i) != 0 { next_up(MAX[i]) } else { next_down(MIN[i]) }));
    }
    // 4. out of the domain, on each input alone, then on all together
    for i in 0..5 {
        for v in [-f32::MAX, -1e30, -100.0, MIN[i] - 1.0, MAX[i] + 1.0, 100.0, 1e30, f32::MAX] {
            out.push(with(i, v));
        }
    }
    for s in [-1.0f32, 1.0] {
        out.push([13.0 * s, 13.0 * s, 16.0 * s, 16.0 * s, 3.0 + 4.0 * s]);
        out.push([1e30 * s, 1e30 * s, 1e30 * s, 1e30 * s, 1e30 * s]);
        out.push([20.0 * s, -20.0 * s, 20.0 * s, -20.0 * s, 7.0]);
    }
    // 5. negative zeros: each input, then all
    for i in 0..5 {
        out.push(with(i, -0.0));
    }
    out.push([-0.0; 5]);
    out.push([0.0; 5]);
    // 6. NaN (quiet, quiet with payload, negative, signalling) and infinities in each input;
    //    a NaN together with out-of-domain values still gives status ERROR alone
    let specials = [
        f32::from_bits(0x7fc0_0000),
        f32::from_bits(0x7fc1_2345),
        f32::from_bits(0xffc0_0000),
        f32::from_bits(0xffc0_0001),
        f32::from_bits(0x7fa0_0000),
        f32::INFINITY,
        f32::NEG_INFINITY,
    ];
    for i in 0..5 {
        for v in specials {
            out.push(with(i, v));
        }
    }
    out.push([f32::from_bits(0x7fc0_0000); 5]);
    out.push([100.0, 100.0, 100.0, 100.0, f32::from_bits(0x7fc0_0000)]);
    out.push([f32::INFINITY, -100.0, 100.0, -0.0, -1.0]);
    // 7. subnormals in each input (smallest, largest, negative smallest)
    for i in 0..5 {
        for b in [0x0000_0001u32, 0x007f_ffff, 0x8000_0001] {
            out.push(with(i, f32::from_bits(b)));
        }
    }
    out.push([f32::from_bits(1); 5]);
    // 8. in and around the unsolved region
    out.extend(crate::unsolved::golden_poses_f32(unsolved));
    out
}

/// The text of golden-f32.csv for the f32 tables `t`.
pub fn to_csv(t: &Tables32) -> String {
    let poses = poses(&t.unsolved);
    let mut s = String::with_capacity(128 * (poses.len() + 1));
    s.push_str(&header());
    s.push('\n');
    for p in poses {
        let (w, status) = eval(t, p);
        for v in p {
            let _ = write!(s, "{},", hex32(v));
        }
        let _ = write!(s, "0x{status:02x}");
        for v in w {
            let _ = write!(s, ",{}", hex32(v));
        }
        s.push('\n');
    }
    s
}

/// One golden row: the pose, the status and the wrench, all as stored bits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GoldenRow {
    /// `[x_mm, z_mm, theta_x_deg, theta_z_deg, depth_mm]`.
    pub pose: [f32; 5],
    /// Status byte.
    pub status: u8,
    /// `[fx_n, fy_n, fz_n, mx_nmm, my_nmm, mz_nmm]` (N, N·mm).
    pub wrench: [f32; COMPONENT_COUNT],
}

/// Parse golden-f32.csv text; `path` is only used in messages.
///
/// # Errors
/// Wrong header, a row without `6 + COMPONENT_COUNT` fields, a malformed hex field (`path:line` in the
/// message).
pub fn parse_csv(text: &str, path: &Path) -> Result<Vec<GoldenRow>, GoldenCsvError> {
    crate::golden::parse_rows(text, path, &header(), |field, at| {
        let value = |s: &str| parse_hex32(s).ok_or_else(|| GoldenCsvError::hex32(at, s));
        let (mut pose, mut wrench) = ([0.0f32; 5], [0.0f32; COMPONENT_COUNT]);
        for (j, dst) in pose.iter_mut().chain(wrench.iter_mut()).enumerate() {
            // field 5 is the status, read by parse_rows
            *dst = value(if j < 5 { field[j] } else { field[j + 1] })?;
        }
        Ok((pose, wrench))
    })
    .map(|rows| rows.into_iter().map(|(pose, status, wrench)| GoldenRow { pose, status, wrench }).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> GoldenCsvError {
        parse_csv(text, Path::new("g.csv")).expect_err("must be refused")
    }

    #[test]
    fn malformed_golden_files_name_the_line() {
        let one = "0x3f800000";
        let row = |status: &str, last: &str| {
            let mut f = vec![one; 5];
            f.push(status);
            f.extend([one; 5]);
            f.push(last);
            f.join(",")
        };
        let good = format!("{}\n{}\n", header(), row("0x01", one));
        let rows = parse_csv(&good, Path::new("g.csv")).expect("good file");
        assert_eq!(rows, [GoldenRow { pose: [1.0; 5], status: 1, wrench: [1.0; COMPONENT_COUNT] }]);
        let e = err("x\n");
        assert_eq!(e, GoldenCsvError::Header { path: "g.csv".into(), expected: header() });
        assert!(e.to_string().starts_with("g.csv:1: "), "file:line first: {e}");
        let e = err(&format!("{}\n{}\n0x1\n", header(), row("0x00", one)));
        assert_eq!(e, GoldenCsvError::FieldCount { at: "g.csv:3".into(), found: 1, expected: 12 });
        let e = err(&format!("{}\n{}\n", header(), row("0x1", one)));
        assert_eq!(e, GoldenCsvError::Status { at: "g.csv:2".into(), value: "0x1".into() });
        let e = err(&format!("{}\n{}\n", header(), row("0x00", "1.0")));
        assert!(matches!(&e, GoldenCsvError::Value { at, value, .. } if at == "g.csv:2" && value == "1.0"), "{e:?}");
    }
}
