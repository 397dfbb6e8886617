//! `unsolved.toml` (coeffs/README.md, "The unsolved region"): checked and rendered into
//! the library's `unsolved.rs` (the balls in f32 and in integers, and the prefilter's bin
//! masks) and into `needle_coeffs.h`. A set without the file has no region: no pose is
//! flagged `FE_UNSOLVED`.
use crate::error::CodegenError;
use crate::literal::f32_literal;
use needle_contract::{DEPTH_MAX_MM, UNSOLVED_FORMAT, UNSOLVED_MAX_BALLS};
use serde::Deserialize;
use std::fmt::Write as _;
use std::path::Path;
use toml::Spanned;

/// The file's name inside a set folder (beside `model.toml`).
pub const FILE: &str = "unsolved.toml";
/// File name of the generated code in the output folder.
pub const RUST_FILE: &str = "unsolved.rs";
/// Q15: a normalised coordinate `n = v / V_k` is the integer `round(n * 2^15)`.
pub const Q15: i64 = 1 << 15;
/// Q16.16: a depth in mm is the integer `round(d * 2^16)`.
pub const Q16: i64 = 1 << 16;
/// Bins of the prefilter per input, over the normalised `[-1, 1]` (width 1/8).
pub const BINS: usize = 16;
/// How far the prefilter widens each ball's extent (normalised): far more than the f32
/// rounding of `n` and of the bin index (about 2^-22), so the filter never drops a ball
/// that holds the pose.
pub const BIN_MARGIN: f64 = 1.0 / 4096.0;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Raw {
    format: Spanned<i64>,
    set: String,
    #[serde(default)]
    failed: Vec<RawFailed>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)] // the record's fields are read by people; the build checks the numbers
struct RawFailed {
    pose: String,
    source: String,
    x_mm: f64,
    z_mm: f64,
    theta_x_deg: f64,
    theta_z_deg: f64,
    reached_depth_mm: Option<f64>,
    cause: String,
    nearest_solved: String,
    nearest_solved_distance: f64,
    radius_q15: Spanned<i64>,
    depth_q16: Spanned<i64>,
    centres_q15: Spanned<Vec<[i64; 4]>>,
}

/// One ball: centre (Q15, normalised), radius (Q15) and depth threshold (Q16.16 mm).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Ball {
    /// `C_k`, each in `[-(2^15 - 1), 2^15 - 1]` (an `i16`).
    pub centre_q15: [i64; 4],
    /// `R`, in `0..=2^15`.
    pub radius_q15: i64,
    /// `Dq`, in `0..=6 * 2^16`.
    pub depth_q16: i64,
    /// The failed pose it comes from.
    pub pose: usize,
}

/// The checked region: the failed poses' names and every ball, in file order.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Region {
    /// Names of the failed poses.
    pub poses: Vec<String>,
    /// The balls.
    pub balls: Vec<Ball>,
}

impl Ball {
    /// The f32 constants: centre `C / 2^15` (exact), the squared radius (the f32 nearest
    /// `R^2 / 2^30`) and the depth threshold `Dq / 2^16` mm (exact). (The library
    /// converts the integers at run time: the same bits.)
    #[allow(clippy::cast_possible_truncation, clippy::cast_precision_loss)]
    #[must_use]
    pub fn f32_constants(&self) -> ([f32; 4], f32, f32) {
        let c = self.centre_q15.map(|v| (v as f64 / Q15 as f64) as f32);
        let r2 = ((self.radius_q15 * self.radius_q15) as f64 / (Q15 * Q15) as f64) as f32;
        let d = (self.depth_q16 as f64 / Q16 as f64) as f32;
        (c, r2, d)
    }
}

/// Reads and checks `path`.
///
/// # Errors
/// Unreadable, invalid TOML, unknown or missing fields, `format` not the contract's,
/// a radius outside `0..=2^15`, a depth threshold outside `0..=6 * 2^16`, a centre
/// coordinate outside `[-(2^15 - 1), 2^15 - 1]`, a failed pose without a centre or with more than
/// four, more than `UNSOLVED_MAX_BALLS` balls; each with its line.
pub fn parse(path: &Path) -> Result<Region, CodegenError> {
    let text = std::fs::read_to_string(path).map_err(|e| CodegenError::file(path, format!("cannot read: {e}")))?;
    parse_str(&text, path)
}

/// [`parse`] on the file's text (`path` for messages).
///
/// # Errors
/// As [`parse`].
pub fn parse_str(text: &str, path: &Path) -> Result<Region, CodegenError> {
    let raw: Raw = toml::from_str(text).map_err(|e| {
        let offset = e.span().map_or(text.trim_end().len(), |s| s.start);
        CodegenError::at(path, text, offset, e.message().trim_end())
    })?;
    let at = |span: std::ops::Range<usize>, m: String| CodegenError::at(path, text, span.start, m);
    if *raw.format.get_ref() != UNSOLVED_FORMAT {
        return Err(at(
            raw.format.span(),
            format!("format = {}: this build reads unsolved format {UNSOLVED_FORMAT}", raw.format.get_ref()),
        ));
    }
    let _ = &raw.set;
    let depth_max = (DEPTH_MAX_MM as i64) * Q16;
    let mut region = Region::default();
    for (i, f) in raw.failed.iter().enumerate() {
        let r = *f.radius_q15.get_ref();
        if !(0..=Q15).contains(&r) {
            return Err(at(f.radius_q15.span(), format!("radius_q15 = {r}: must be in 0 ..= {Q15}")));
        }
        let d = *f.depth_q16.get_ref();
        if !(0..=depth_max).contains(&d) {
            return Err(at(f.depth_q16.span(), format!("depth_q16 = {d}: must be in 0 ..= {depth_max} (0 .. 6 mm)")));
        }
        let centres = f.centres_q15.get_ref();
        if centres.is_empty() || centres.len() > 4 {
            return Err(at(
                f.centres_q15.span(),
                format!("centres_q15: {} centres, expected 1 to 4 (the pose and its mirror images)", centres.len()),
            ));
        }
        for c in centres {
            if c.iter().any(|v| !(-(Q15 - 1)..=Q15 - 1).contains(v)) {
                return Err(at(
                    f.centres_q15.span(),
                    format!("centres_q15: {c:?}: every coordinate must be in -{} ..= {}", Q15 - 1, Q15 - 1),
                ));
            }
            region.balls.push(Ball { centre_q15: *c, radius_q15: r, depth_q16: d, pose: i });
        }
        region.poses.push(f.pose.clone());
        if region.balls.len() > UNSOLVED_MAX_BALLS {
            return Err(at(
                f.centres_q15.span(),
                format!("{} balls so far: an unsolved region may have at most {UNSOLVED_MAX_BALLS}", region.balls.len()),
            ));
        }
    }
    Ok(region)
}

/// `BIN_MASKS[k][b]`: bit `i` set when ball `i`'s extent along input `k`, `C_k ± R`
/// widened by [`BIN_MARGIN`], meets bin `b` (`[b/8 - 1, (b+1)/8 - 1]`, the first and the
/// last bin open outwards).
#[must_use]
pub fn bin_masks(r: &Region) -> [[u64; BINS]; 4] {
    let mut masks = [[0u64; BINS]; 4];
    for (i, ball) in r.balls.iter().enumerate() {
        let radius = ball.radius_q15 as f64 / Q15 as f64;
        for (k, row) in masks.iter_mut().enumerate() {
            let c = ball.centre_q15[k] as f64 / Q15 as f64;
            let (lo, hi) = (c - radius - BIN_MARGIN, c + radius + BIN_MARGIN);
            for (b, m) in row.iter_mut().enumerate() {
                let b_lo = if b == 0 { f64::NEG_INFINITY } else { b as f64 / 8.0 - 1.0 };
                let b_hi = if b == BINS - 1 { f64::INFINITY } else { (b + 1) as f64 / 8.0 - 1.0 };
                if lo <= b_hi && hi >= b_lo {
                    *m |= 1u64 << i;
                }
            }
        }
    }
    masks
}

/// The Rust source of `unsolved.rs`: `COUNT`, the mask type and its `ALL`, `BIN_MASKS`,
/// and the balls' integers (`BALLS`, of the including module's `Ball`).
#[must_use]
pub fn render(r: &Region) -> String {
    let mut s = String::from("// Generated by needle-codegen from the set's unsolved.toml: do not edit.\n");
    let n = r.balls.len();
    let mask = if n > 32 { "u64" } else { "u32" };
    let all: u64 = if n == 64 { u64::MAX } else { (1u64 << n) - 1 };
    let _ = writeln!(s, "/// Balls of the region (every failed pose and its mirror images).");
    let _ = writeln!(s, "pub const COUNT: usize = {n};");
    let _ = writeln!(s, "/// One bit per ball.");
    let _ = writeln!(s, "pub type Mask = {mask};");
    let _ = writeln!(s, "/// Every ball's bit.");
    let _ = writeln!(s, "pub const ALL: Mask = {all:#x};");
    let _ = writeln!(s, "/// Bins of the prefilter per input over the normalised [-1, 1] (width 1/8).");
    let _ = writeln!(s, "pub const BINS: usize = {BINS};");
    let _ = writeln!(s, "/// `BIN_MASKS[k][b]`: the balls whose extent along input k (centre +- radius, widened by");
    let _ = writeln!(s, "/// 2^-12) meets bin b, `[b/8 - 1, (b+1)/8 - 1]` (the first and last open outwards).");
    let _ = writeln!(s, "pub const BIN_MASKS: [[Mask; BINS]; 4] = [");
    for row in bin_masks(r) {
        let list: Vec<String> = row.iter().map(|m| format!("{m:#x}")).collect();
        let _ = writeln!(s, "    [{}],", list.join(", "));
    }
    let _ = writeln!(s, "];");
    let _ = writeln!(s, "/// The balls: centre `C` (Q15, normalised x/12, z/12, theta_x/15, theta_z/15), radius `R`");
    let _ = writeln!(s, "/// (Q15), depth threshold `Dq` (Q16.16 mm); in f32 `C / 2^15`, the f32 nearest `R^2 / 2^30`");
    let _ = writeln!(s, "/// and `Dq / 2^16` (exact conversions of these integers).");
    let _ = writeln!(s, "pub const BALLS: [super::Ball; COUNT] = [");
    for b in &r.balls {
        let [c0, c1, c2, c3] = b.centre_q15;
        let _ = writeln!(
            s,
            "    super::Ball {{ centre_q15: [{c0}, {c1}, {c2}, {c3}], radius_q15: {}, depth_q16: {} }}, // {}",
            b.radius_q15,
            b.depth_q16,
            r.poses.get(b.pose).map_or("", String::as_str)
        );
    }
    let _ = writeln!(s, "];");
    s
}

/// The region's part of `needle_coeffs.h`: the test in words, `NEEDLE_UNSOLVED_COUNT`
/// and, when there are balls, their f32 constants.
#[must_use]
pub fn render_c(r: &Region) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "/* The unsolved region (unsolved.toml): status NEEDLE_STATUS_FE_UNSOLVED when, with the");
    let _ = writeln!(s, " * clamped inputs, n_k = v_k * (the f32 nearest 1/12, 1/12, 1/15, 1/15) and some ball i");
    let _ = writeln!(s, " * has depth > NEEDLE_UNSOLVED_DEPTH_MM[i] and, with q_k = n_k - NEEDLE_UNSOLVED_CENTRE[i][k],");
    let _ = writeln!(s, " * ((q0*q0 + q1*q1) + q2*q2) + q3*q3 < NEEDLE_UNSOLVED_RADIUS2[i]. The wrench is not changed. */");
    let _ = writeln!(s, "#define NEEDLE_UNSOLVED_COUNT {}", r.balls.len());
    if r.balls.is_empty() {
        return s;
    }
    let _ = writeln!(s, "static const float NEEDLE_UNSOLVED_CENTRE[{}][4] = {{", r.balls.len());
    for b in &r.balls {
        let (c, _, _) = b.f32_constants();
        let list: Vec<String> = c.iter().map(|v| format!("{}f", f32_literal(*v))).collect();
        let _ = writeln!(s, "    {{{}}}, /* {} */", list.join(", "), r.poses.get(b.pose).map_or("", String::as_str));
    }
    let _ = writeln!(s, "}};");
    let list: Vec<String> = r.balls.iter().map(|b| format!("{}f", f32_literal(b.f32_constants().1))).collect();
    let _ = writeln!(s, "static const float NEEDLE_UNSOLVED_RADIUS2[{}] = {{{}}};", r.balls.len(), list.join(", "));
    let list: Vec<String> = r.balls.iter().map(|b| format!("{}f", f32_literal(b.f32_constants().2))).collect();
    let _ = writeln!(s, "static const float NEEDLE_UNSOLVED_DEPTH_MM[{}] = {{{}}};", r.balls.len(), list.join(", "));
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    const ONE: &str = "format = 1\nset = \"s\"\n\n[[failed]]\npose = \"tx+15\"\nsource = \"campaign.fit_without\"\nx_mm = 0.0\nz_mm = 0.0\ntheta_x_deg = 15.0\ntheta_z_deg = 0.0\ncause = \"c\"\nnearest_solved = \"tx+12\"\nnearest_solved_distance = 0.2\nradius_q15 = 3276\ndepth_q16 = 0\ncentres_q15 = [[0, 0, 32767, 0], [0, 0, -32767, 0]]\n";

    fn err(text: &str) -> String {
        parse_str(text, Path::new("unsolved.toml")).expect_err("must be refused").to_string()
    }

    #[test]
    fn a_region_is_read_and_a_bad_one_refused_with_its_line() {
        let r = parse_str(ONE, Path::new("unsolved.toml")).expect("good file");
        assert_eq!(r.balls.len(), 2);
        assert_eq!(r.balls[1], Ball { centre_q15: [0, 0, -32767, 0], radius_q15: 3276, depth_q16: 0, pose: 0 });
        assert_eq!(err(&ONE.replace("format = 1", "format = 2")), "unsolved.toml:1: format = 2: this build reads unsolved format 1");
        assert_eq!(
            err(&ONE.replace("radius_q15 = 3276", "radius_q15 = 40000")),
            "unsolved.toml:14: radius_q15 = 40000: must be in 0 ..= 32768"
        );
        assert_eq!(
            err(&ONE.replace("depth_q16 = 0", "depth_q16 = -1")),
            "unsolved.toml:15: depth_q16 = -1: must be in 0 ..= 393216 (0 .. 6 mm)"
        );
        assert!(err(&ONE.replace("32767, 0], [0", "32768, 0], [0")).starts_with("unsolved.toml:16: centres_q15: [0, 0, 32768, 0]"));
        assert!(err(&ONE.replace("cause = \"c\"\n", "")).contains("missing field `cause`"));
        assert!(err(&ONE.replace("cause = ", "why = ")).starts_with("unsolved.toml:"));
        let many = format!("format = 1\nset = \"s\"\n{}", ONE.split_once("\n\n").map_or("", |(_, f)| f).repeat(33));
        assert!(err(&format!("\n{many}")).contains("at most 64"), "{}", err(&many));
        let none = parse_str("format = 1\nset = \"s\"\n", Path::new("unsolved.toml")).expect("no failed pose");
        assert!(none.balls.is_empty());
        assert!(render(&none).contains("pub const COUNT: usize = 0;"));
        assert_eq!(render_c(&none).lines().last(), Some("#define NEEDLE_UNSOLVED_COUNT 0"));
    }

    /// The prefilter keeps every ball that holds a pose: for poses on a fine grid along
    /// each input, a ball whose extent contains the coordinate has its bit in the bin.
    #[test]
    fn the_bin_masks_cover_each_balls_extent() {
        let r = parse_str(ONE, Path::new("unsolved.toml")).expect("good file");
        let masks = bin_masks(&r);
        for (i, ball) in r.balls.iter().enumerate() {
            for (k, (row, &ck)) in masks.iter().zip(&ball.centre_q15).enumerate() {
                let c = ck as f64 / Q15 as f64;
                let rad = ball.radius_q15 as f64 / Q15 as f64;
                for step in 0..=2000 {
                    let n = -1.0 + f64::from(step) / 1000.0;
                    if (n - c).abs() <= rad {
                        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
                        let b = (((n + 1.0) * 8.0) as usize).min(BINS - 1);
                        assert!(row[b] & (1 << i) != 0, "ball {i}, input {k}, n = {n}: bin {b} lacks it");
                    }
                }
            }
        }
        // tx+15's balls are near theta_x = +-1 only
        assert_eq!(masks[2][0], 0b10);
        assert_eq!(masks[2][BINS - 1], 0b01);
        assert_eq!(masks[2][8], 0);
    }
}
