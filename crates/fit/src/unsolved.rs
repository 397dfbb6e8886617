//! `unsolved.toml` (coeffs/README.md, "The unsolved region"): where the set's FE
//! campaign could not solve, from its records, and this crate's own evaluation of the
//! `FE_UNSOLVED` status bit in f32 and in fixed point (for the golden vectors; it does not
//! call the library).
//!
//! The failed poses are the campaign's poses without a current result that the set
//! records as unsolved: listed in `campaign.fit_without` (the model is fitted without
//! them because their run cannot be solved) or `campaign.train_replaced` (failed every
//! attempt), or with a partial record of the current spec (`fe/<pose>.partial.toml`,
//! written when every attempt failed; any role). Each failed pose, in normalised pose
//! space `n = (x / 12, z / 12, theta_x / 15, theta_z / 15)`, gives a ball of radius half
//! its distance to the nearest solved run (every run with a current result and the
//! mirror images of each: the block and the model are symmetric), around the pose and its
//! mirror images, over the depths beyond the depth its furthest attempt reached (every
//! depth when no record says how far it got). No solved run lies in the region: a ball
//! reaches at most half way to the nearest one.
use crate::data::{run_path, stale_reason};
use anyhow::{bail, Result};
use needle_contract::{DEPTH_MAX_MM, HALF_RANGES};
use needle_set::set_folder::SetFolder;
use needle_set::spec::{Campaign, PoseSpec};
use std::fmt::Write as _;
use std::path::Path;

/// The file's name inside a set folder (the generator's, which reads it).
pub use needle_codegen::unsolved::FILE;
/// Format version of the file.
pub const FORMAT: i64 = needle_contract::UNSOLVED_FORMAT;
/// Q15 unit: a normalised coordinate `n` is `round(n * Q15)`.
pub const Q15: i64 = 1 << 15;
/// Q16.16 unit of a depth in mm.
pub const Q16: i64 = 1 << 16;
/// Most entries (ball centres, mirror images included) the library's region test takes.
pub const MAX_ENTRIES: usize = needle_contract::UNSOLVED_MAX_BALLS;

/// One failed pose: where it is, how far it got, why, and its balls.
#[derive(Debug, Clone, PartialEq)]
pub struct FailedPose {
    /// Pose name in the campaign.
    pub pose: String,
    /// `[x_mm, z_mm, theta_x_deg, theta_z_deg]`.
    pub at: [f64; 4],
    /// Which record names it: `campaign.fit_without`, `campaign.train_replaced` or
    /// `fe/<pose>.partial.toml`.
    pub source: String,
    /// Depth its furthest attempt reached (its last converged must point), mm; `None`
    /// when no record says.
    pub reached_depth_mm: Option<f64>,
    /// The cause: the attempts' failures by class from the partial record, or what the
    /// campaign says.
    pub cause: String,
    /// The nearest solved run (name, with `mirror of` when it is a mirror image).
    pub nearest_solved: String,
    /// Distance to it in normalised units.
    pub nearest_distance: f64,
    /// The balls' radius, Q15 (`floor(nearest_distance / 2 * 2^15)`).
    pub radius_q15: i64,
    /// The depth threshold, Q16.16 mm (`round(reached * 2^16)`, 0 when unknown).
    pub depth_q16: i64,
    /// The ball centres: the pose and its distinct mirror images, Q15 normalised
    /// (`round(n * 2^15)` within `±(2^15 - 1)`: an `i16`).
    pub centres_q15: Vec<[i64; 4]>,
}

/// The region of a set.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Region {
    /// The failed poses in campaign order.
    pub failed: Vec<FailedPose>,
    /// Every solved run and its mirror images (name, normalised pose), for the report.
    pub solved: Vec<(String, [f64; 4])>,
}

/// One ball of the region, as both evaluators use it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Entry {
    /// Centre, Q15 normalised.
    pub centre_q15: [i64; 4],
    /// Radius, Q15.
    pub radius_q15: i64,
    /// Depth threshold, Q16.16 mm: inside only deeper than this.
    pub depth_q16: i64,
}

impl Region {
    /// Every ball, in file order (failed pose, then its centres).
    pub fn entries(&self) -> Vec<Entry> {
        self.failed
            .iter()
            .flat_map(|f| f.centres_q15.iter().map(|c| Entry { centre_q15: *c, radius_q15: f.radius_q15, depth_q16: f.depth_q16 }))
            .collect()
    }
}

/// Normalised coordinates of a pose (mm, deg).
pub fn normalised(at: [f64; 4]) -> [f64; 4] {
    std::array::from_fn(|k| at[k] / HALF_RANGES[k])
}

/// The pose and its mirror images (x -> -x with theta_z -> -theta_z; z -> -z with
/// theta_x -> -theta_x), in that order: identity, x mirror, z mirror, both.
pub fn mirror_images(n: [f64; 4]) -> [[f64; 4]; 4] {
    let [x, z, tx, tz] = n;
    [[x, z, tx, tz], [-x, z, tx, -tz], [x, -z, -tx, tz], [-x, -z, -tx, -tz]]
}

fn distance(a: [f64; 4], b: [f64; 4]) -> f64 {
    a.iter().zip(&b).map(|(p, q)| (p - q) * (p - q)).sum::<f64>().sqrt()
}

/// `round(v)` ties away from zero, as i64.
fn round_i64(v: f64) -> i64 {
    v.round() as i64
}

/// Whether `pose` has a current result in the set (its CSV and a current manifest entry).
fn solved(set_dir: &Path, manifest: &needle_set::manifest::Manifest, campaign: &Campaign, pose: &PoseSpec) -> bool {
    run_path(set_dir, pose).is_file() && stale_reason(manifest, campaign, pose).is_none()
}

/// A partial record of the current spec: depth reached and the failures by class.
fn partial_record(set_dir: &Path, campaign: &Campaign, pose: &PoseSpec) -> Option<(f64, String)> {
    use needle_set::failures;
    let (_, path) = needle_set::partial::paths(&set_dir.join("fe"), &pose.name);
    let text = std::fs::read_to_string(path).ok()?;
    let r: needle_set::partial::PartialRecord = toml::from_str(&text).ok()?;
    if r.spec_hash != campaign.run_hash(pose, &campaign.campaign.mesh) {
        return None;
    }
    Some((r.reached_depth_mm, failures::summary(&failures::failures_from_record(&r.failure), "mm")))
}

/// The region of the opened set `set`, from its records (module docs).
///
/// # Errors
/// The spec or the manifest cannot be read; no run of the set is solved while a pose
/// failed (no radius); more than [`MAX_ENTRIES`] balls.
pub fn region(set: &SetFolder) -> Result<Region> {
    let (campaign, manifest, set_dir) = (set.campaign(), set.manifest(), set.dir());
    let poses = campaign.poses();
    let mut solved_points: Vec<(String, [f64; 4])> = Vec::new();
    for p in poses.iter().filter(|p| solved(set_dir, manifest, campaign, p)) {
        let n = normalised([p.x_mm, p.z_mm, p.theta_x_deg, p.theta_z_deg]);
        for (i, image) in mirror_images(n).into_iter().enumerate() {
            let name = match i {
                0 => p.name.clone(),
                1 => format!("x mirror of {}", p.name),
                2 => format!("z mirror of {}", p.name),
                _ => format!("x and z mirror of {}", p.name),
            };
            solved_points.push((name, image));
        }
    }
    let mut failed = Vec::new();
    for p in &poses {
        if solved(set_dir, manifest, campaign, p) {
            continue;
        }
        let record = partial_record(set_dir, campaign, p);
        let source = if campaign.campaign.fit_without.contains(&p.name) {
            "campaign.fit_without".to_string()
        } else if campaign.is_replaced(&p.name) {
            "campaign.train_replaced".to_string()
        } else if record.is_some() {
            format!("fe/{}.partial.toml", p.name)
        } else {
            continue;
        };
        let cause = match (&record, campaign.campaign.train_replaced.iter().find(|r| r.pose == p.name)) {
            (Some((_, classes)), _) => classes.clone(),
            (None, Some(r)) => r.why.clone(),
            (None, None) => "no partial record (its failures are not kept)".to_string(),
        };
        let at = [p.x_mm, p.z_mm, p.theta_x_deg, p.theta_z_deg];
        let n = normalised(at);
        let Some((nearest_solved, nearest_distance)) =
            solved_points.iter().map(|(name, s)| (name.clone(), distance(n, *s))).min_by(|a, b| a.1.total_cmp(&b.1))
        else {
            bail!("{}: pose {} failed, but no run of the set is solved: the unsolved region has no radius", set_dir.display(), p.name);
        };
        let radius_q15 = ((nearest_distance / 2.0) * Q15 as f64).floor() as i64;
        let reached_depth_mm = record.as_ref().map(|(d, _)| *d);
        let depth_q16 = round_i64(reached_depth_mm.unwrap_or(0.0).clamp(0.0, DEPTH_MAX_MM) * Q16 as f64);
        let mut centres_q15: Vec<[i64; 4]> = Vec::new();
        for image in mirror_images(n) {
            let c = image.map(|v| round_i64(v * Q15 as f64).clamp(-(Q15 - 1), Q15 - 1));
            if !centres_q15.contains(&c) {
                centres_q15.push(c);
            }
        }
        failed.push(FailedPose {
            pose: p.name.clone(),
            at,
            source,
            reached_depth_mm,
            cause,
            nearest_solved,
            nearest_distance,
            radius_q15: radius_q15.clamp(0, Q15),
            depth_q16,
            centres_q15,
        });
    }
    let region = Region { failed, solved: solved_points };
    let n = region.entries().len();
    if n > MAX_ENTRIES {
        bail!("{}: the unsolved region has {n} balls (mirror images included); the library takes at most {MAX_ENTRIES}", set_dir.display());
    }
    Ok(region)
}

/// `s` as a TOML basic string.
fn quoted(s: &str) -> String {
    let mut out = String::from("\"");
    for ch in s.chars() {
        match ch {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if c.is_control() => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// The text of `unsolved.toml`.
pub fn to_toml(set: &str, r: &Region) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# generated by `needle fit` from the set's FE records; do not edit. Format: coeffs/README.md, \"The unsolved region\"."
    );
    let _ = writeln!(
        s,
        "# A pose is in the region (status FE_UNSOLVED, 0x20) when, clamped to the domain, it is deeper than depth_q16 / 2^16 mm"
    );
    let _ = writeln!(
        s,
        "# and its normalised (x/12, z/12, theta_x/15, theta_z/15) lies within radius_q15 / 2^15 of one of centres_q15 / 2^15."
    );
    let _ = writeln!(s, "format = {FORMAT}");
    let _ = writeln!(s, "set = {}", quoted(set));
    for f in &r.failed {
        let _ = writeln!(s);
        let _ = writeln!(s, "[[failed]]");
        let _ = writeln!(s, "pose = {}", quoted(&f.pose));
        let _ = writeln!(s, "source = {}", quoted(&f.source));
        let [x, z, tx, tz] = f.at;
        let _ = writeln!(s, "x_mm = {x:?}");
        let _ = writeln!(s, "z_mm = {z:?}");
        let _ = writeln!(s, "theta_x_deg = {tx:?}");
        let _ = writeln!(s, "theta_z_deg = {tz:?}");
        match f.reached_depth_mm {
            Some(d) => {
                let _ = writeln!(s, "reached_depth_mm = {d:?}");
            }
            None => {
                let _ = writeln!(s, "# reached_depth_mm: no record says how far it got, so every depth is in the region");
            }
        }
        let _ = writeln!(s, "cause = {}", quoted(&f.cause));
        let _ = writeln!(s, "nearest_solved = {}", quoted(&f.nearest_solved));
        let _ = writeln!(s, "nearest_solved_distance = {:?}", f.nearest_distance);
        let _ = writeln!(s, "radius_q15 = {}", f.radius_q15);
        let _ = writeln!(s, "depth_q16 = {}", f.depth_q16);
        let list: Vec<String> = f.centres_q15.iter().map(|c| format!("[{}, {}, {}, {}]", c[0], c[1], c[2], c[3])).collect();
        let _ = writeln!(s, "centres_q15 = [{}]", list.join(", "));
    }
    s
}

/// The f32 constants of one entry: centre `C / 2^15` (exact), squared radius (the f32
/// nearest `R^2 / 2^30`) and depth threshold `Dq / 2^16` (exact).
pub fn entry_f32(e: &Entry) -> ([f32; 4], f32, f32) {
    let c = e.centre_q15.map(|v| (v as f64 / Q15 as f64) as f32);
    let r2 = ((e.radius_q15 * e.radius_q15) as f64 / (Q15 * Q15) as f64) as f32;
    let d = (e.depth_q16 as f64 / Q16 as f64) as f32;
    (c, r2, d)
}

/// The f32 test (coeffs/README.md): `n` the clamped inputs times the f32 nearest `1 / V_k`
/// (the coupled form's inputs), `depth` the clamped depth.
pub fn inside_f32(entries: &[Entry], n: [f32; 4], depth: f32) -> bool {
    entries.iter().any(|e| {
        let (c, r2, d) = entry_f32(e);
        let q: [f32; 4] = std::array::from_fn(|k| n[k] - c[k]);
        let s = ((q[0] * q[0] + q[1] * q[1]) + q[2] * q[2]) + q[3] * q[3];
        depth > d && s < r2
    })
}

/// The fixed-point test: `n` the coupled form's Q15 inputs `N_k`, `depth` the clamped
/// Q16.16 depth; exact integer arithmetic.
pub fn inside_fixed(entries: &[Entry], n: [i64; 4], depth: i64) -> bool {
    entries.iter().any(|e| {
        let s: i64 = (0..4).map(|k| (n[k] - e.centre_q15[k]) * (n[k] - e.centre_q15[k])).sum();
        depth > e.depth_q16 && s < e.radius_q15 * e.radius_q15
    })
}

/// Golden poses in and around the region (f32, mm and degrees): per ball, its centre at
/// full depth and half way between the depth threshold and full depth, its centre just
/// at the threshold (outside: not deeper), and offsets of half and twice the radius along
/// each input at full depth.
pub fn golden_poses_f32(entries: &[Entry]) -> Vec<[f32; 5]> {
    let mut out = Vec::new();
    let full = DEPTH_MAX_MM as f32;
    for e in entries {
        let at = |off: [f64; 4], depth: f32| -> [f32; 5] {
            let p: [f32; 4] = std::array::from_fn(|k| ((e.centre_q15[k] as f64 + off[k]) / Q15 as f64 * HALF_RANGES[k]) as f32);
            [p[0], p[1], p[2], p[3], depth]
        };
        let d = (e.depth_q16 as f64 / Q16 as f64) as f32;
        out.push(at([0.0; 4], full));
        out.push(at([0.0; 4], (d + full) * 0.5));
        out.push(at([0.0; 4], d));
        for k in 0..4 {
            for m in [0.5, -0.5, 2.0, -2.0] {
                let mut off = [0.0; 4];
                off[k] = m * e.radius_q15 as f64;
                out.push(at(off, full));
            }
        }
    }
    out
}

/// The same poses in Q16.16.
pub fn golden_poses_fixed(entries: &[Entry]) -> Vec<[i32; 5]> {
    golden_poses_f32(entries).into_iter().map(|p| p.map(|v| (f64::from(v) * Q16 as f64).round() as i32)).collect()
}

/// The exact (f64) test of a normalised pose and depth against the balls.
fn inside_exact(entries: &[Entry], n: [f64; 4], depth_mm: f64) -> bool {
    entries.iter().any(|e| {
        let c = e.centre_q15.map(|v| v as f64 / Q15 as f64);
        let r = e.radius_q15 as f64 / Q15 as f64;
        depth_mm * Q16 as f64 > e.depth_q16 as f64 && distance(n, c) < r
    })
}

/// Seed of the random poses that measure the region's share of the domain (ChaCha8).
pub const SHARE_SEED: u64 = 0x6e65_6564_6c65_0020;
/// How many.
pub const SHARE_POSES: usize = 200_000;

/// The share of the domain (uniform over x, z, theta_x, theta_z and depth) in the balls
/// `entries`, from [`SHARE_POSES`] random poses.
pub fn domain_share(entries: &[Entry]) -> f64 {
    use rand::{RngCore, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(SHARE_SEED);
    let mut unit = || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
    let mut hits = 0usize;
    for _ in 0..SHARE_POSES {
        let n: [f64; 4] = std::array::from_fn(|_| 2.0 * unit() - 1.0);
        let d = DEPTH_MAX_MM * unit();
        hits += usize::from(inside_exact(entries, n, d));
    }
    hits as f64 / SHARE_POSES as f64
}

/// The region with every ball's radius replaced by `radius` (normalised): the alternative
/// rule of a fixed radius, for the report.
pub fn with_radius(r: &Region, radius: f64) -> Region {
    let mut out = r.clone();
    for f in &mut out.failed {
        f.radius_q15 = ((radius * Q15 as f64).floor() as i64).clamp(0, Q15);
    }
    out
}

/// The solved runs (mirror images count as their run) whose pose lies in a ball of `r`
/// at some depth.
pub fn solved_inside(r: &Region) -> Vec<String> {
    let entries = r.entries();
    let mut names: Vec<String> = r
        .solved
        .iter()
        .filter(|(_, n)| inside_exact(&entries, *n, DEPTH_MAX_MM))
        .map(|(name, _)| name.rsplit(' ').next().unwrap_or(name).to_string())
        .collect();
    names.sort();
    names.dedup();
    names
}

/// What `needle fit` prints of the region: each failed pose, the balls, the share of the
/// domain, and the alternative of a fixed radius.
pub fn summary(r: &Region) -> String {
    let mut s = String::new();
    let entries = r.entries();
    let _ = writeln!(
        s,
        "unsolved region ({FILE}, status FE_UNSOLVED): {} failed pose(s), {} ball(s) with mirror images; radius: half the distance to the nearest solved run (normalised x/12, z/12, theta_x/15, theta_z/15)",
        r.failed.len(),
        entries.len()
    );
    if r.failed.is_empty() {
        return s;
    }
    let _ = writeln!(s, "{:<9} {:<24} {:>9} {:>8} {:>7}  nearest solved", "pose", "source", "from mm", "radius", "images");
    for f in &r.failed {
        let from = f.reached_depth_mm.map_or_else(|| "0 (any)".to_string(), |d| format!("{d:.2}"));
        let _ = writeln!(
            s,
            "{:<9} {:<24} {:>9} {:>8.4} {:>7}  {} at {:.4}",
            f.pose,
            f.source,
            from,
            f.radius_q15 as f64 / Q15 as f64,
            f.centres_q15.len(),
            f.nearest_solved,
            f.nearest_distance
        );
    }
    let _ = writeln!(s, "share of the domain in the region: {:.3} % ({SHARE_POSES} random poses)", 100.0 * domain_share(&entries));
    let mut alt = Vec::new();
    for radius in [0.1, 0.2, 0.3, 0.5] {
        let a = with_radius(r, radius);
        let inside = solved_inside(&a);
        alt.push(format!(
            "r = {radius}: {:.2} % of the domain, {} solved run(s) inside{}",
            100.0 * domain_share(&a.entries()),
            inside.len(),
            if inside.is_empty() { String::new() } else { format!(" ({})", inside.join(", ")) }
        ));
    }
    let _ = writeln!(s, "a fixed radius instead: {}", alt.join("; "));
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_text_reads_back_through_the_generator() {
        let r = Region {
            failed: vec![FailedPose {
                pose: "tx+15".into(),
                at: [0.0, 0.0, 15.0, 0.0],
                source: "campaign.fit_without".into(),
                reached_depth_mm: Some(4.2),
                cause: "max \"reformations\"".into(),
                nearest_solved: "tx+12".into(),
                nearest_distance: 0.2,
                radius_q15: 3276,
                depth_q16: 275_251,
                centres_q15: vec![[0, 0, 32767, 0], [0, 0, -32767, 0]],
            }],
            solved: Vec::new(),
        };
        let text = to_toml("default", &r);
        let back = needle_codegen::unsolved::parse_str(&text, Path::new(FILE)).expect("the generator reads it");
        let balls: Vec<Entry> =
            back.balls.iter().map(|b| Entry { centre_q15: b.centre_q15, radius_q15: b.radius_q15, depth_q16: b.depth_q16 }).collect();
        assert_eq!(balls, r.entries());
        assert_eq!(back.poses, ["tx+15"]);
    }
}
