//! The unsolved region (coeffs/README.md, "The unsolved region"; status `FE_UNSOLVED`,
//! 0x20) of the set compiled into the library: every failed pose is flagged, no solved
//! run is, and the f32 and fixed-point evaluators agree on the flag at every golden pose
//! (those within rounding of a ball's surface apart, which are counted and must be few).
use needle_fit::unsolved::{self, Entry};
use needle_haptics::{fixed, model_info, wrench, wrench_and_stiffness, Pose, Status};
use std::path::Path;

const Q15: f64 = 32768.0;
const Q16: f64 = 65536.0;
const V: [f64; 4] = needle_contract::HALF_RANGES;

fn set_dir() -> &'static Path {
    Path::new(model_info::SET_DIR)
}

fn region() -> unsolved::Region {
    unsolved::region(&needle_set::set_folder::SetFolder::open(set_dir()).unwrap_or_else(|e| panic!("{e:#}")))
        .unwrap_or_else(|e| panic!("{e:#}"))
}

fn entries() -> Vec<Entry> {
    let text = std::fs::read_to_string(set_dir().join(unsolved::FILE)).unwrap_or_default();
    let r = needle_codegen::unsolved::parse_str(&text, Path::new(unsolved::FILE)).unwrap_or_else(|e| panic!("{e}"));
    r.balls.iter().map(|b| Entry { centre_q15: b.centre_q15, radius_q15: b.radius_q15, depth_q16: b.depth_q16 }).collect()
}

fn f32_flag(p: [f32; 5]) -> bool {
    let s = wrench(&Pose::new(p[0], p[1], p[2], p[3], p[4])).status;
    s.contains(Status::FE_UNSOLVED)
}

fn fixed_flag(p: [i32; 5]) -> bool {
    fixed::wrench(&fixed::Pose::new(p[0], p[1], p[2], p[3], p[4])).status.contains(Status::FE_UNSOLVED)
}

/// Whether the (clamped, f64) pose is within `band` (normalised) of a ball's surface, or
/// within `band` mm of its depth threshold: where the two evaluators' roundings may
/// disagree.
fn near_surface(entries: &[Entry], p: [f64; 5], band: f64) -> bool {
    let n: [f64; 4] = std::array::from_fn(|k| p[k].clamp(-V[k], V[k]) / V[k]);
    let d = p[4].clamp(0.0, needle_contract::DEPTH_MAX_MM);
    entries.iter().any(|e| {
        let dist = (0..4).map(|k| (n[k] - e.centre_q15[k] as f64 / Q15).powi(2)).sum::<f64>().sqrt();
        let r = e.radius_q15 as f64 / Q15;
        (dist - r).abs() < band || ((d - e.depth_q16 as f64 / Q16).abs() < band && dist < r + band)
    })
}

#[test]
fn the_compiled_region_is_the_one_the_fitter_derives_from_the_records() {
    let r = region();
    let want: Vec<Entry> = r.entries();
    assert_eq!(entries(), want, "{}: regenerate with `needle fit --set {}`", unsolved::FILE, set_dir().display());
    assert_eq!(model_info::UNSOLVED_BALLS, want.len(), "the library's region is not this set's: rebuild");
}

#[test]
fn every_failed_pose_is_flagged_and_no_solved_run_is() {
    let r = region();
    assert!(!r.failed.is_empty(), "the shipped set has failed poses: the test needs some");
    for f in &r.failed {
        // the failed pose and its mirror images, at full depth and just past the threshold
        for c in &f.centres_q15 {
            let at: [f64; 4] = std::array::from_fn(|k| c[k] as f64 / Q15 * V[k]);
            let beyond = f.depth_q16 as f64 / Q16 + 0.01;
            for d in [6.0, beyond] {
                let p = [at[0] as f32, at[1] as f32, at[2] as f32, at[3] as f32, d as f32];
                assert!(f32_flag(p), "{} image {c:?} at {d} mm: not flagged (f32)", f.pose);
                let q = p.map(|v| (f64::from(v) * Q16).round() as i32);
                assert!(fixed_flag(q), "{} image {c:?} at {d} mm: not flagged (fixed)", f.pose);
                // the flag does not zero the wrench
                let e = wrench(&Pose::new(p[0], p[1], p[2], p[3], p[4]));
                assert!(!e.status.is_error() && e.wrench.fy_n != 0.0, "{}: the flagged wrench is the model's", f.pose);
                assert_eq!(wrench_and_stiffness(&Pose::new(p[0], p[1], p[2], p[3], p[4])).status, e.status);
            }
            if f.depth_q16 > 0 {
                let d = (f.depth_q16 as f64 / Q16) as f32;
                assert!(!f32_flag([at[0] as f32, at[1] as f32, at[2] as f32, at[3] as f32, d]), "{}: flagged at its reached depth", f.pose);
            }
        }
    }
    // every run that solved, at every depth of its CSV and its mirror images: never flagged
    let (campaign, _) = needle_set::spec::load(set_dir()).expect("campaign");
    let mut checked = 0;
    for p in campaign.poses() {
        if !set_dir().join("fe").join(format!("{}.csv", p.name)).is_file() || r.failed.iter().any(|f| f.pose == p.name) {
            continue;
        }
        let n = unsolved::normalised([p.x_mm, p.z_mm, p.theta_x_deg, p.theta_z_deg]);
        for image in unsolved::mirror_images(n) {
            for step in 0..=20 {
                let d = 0.3 * f64::from(step);
                let at: [f32; 5] =
                    [(image[0] * V[0]) as f32, (image[1] * V[1]) as f32, (image[2] * V[2]) as f32, (image[3] * V[3]) as f32, d as f32];
                assert!(!f32_flag(at), "solved run {} (image {image:?}) flagged at {d} mm", p.name);
                assert!(!fixed_flag(at.map(|v| (f64::from(v) * Q16).round() as i32)), "solved run {} flagged (fixed) at {d} mm", p.name);
                checked += 1;
            }
        }
    }
    assert!(checked > 1000, "only {checked} solved poses checked");
    // far from every ball: the centred vertical needle, every depth
    for step in 0..=12 {
        assert!(!f32_flag([0.0, 0.0, 0.0, 0.0, 0.5 * step as f32]), "the centre is not in the region");
    }
}

#[test]
fn f32_and_fixed_point_agree_on_the_flag_at_every_golden_pose() {
    let entries = entries();
    let band = 1e-4;
    // golden-fixed.csv: the Q16.16 poses, and the same poses in f32 (exact: |v| < 2^24 / 2^16)
    let fixed_rows = needle_fit::golden::fixed::parse_csv(
        &std::fs::read_to_string(set_dir().join("golden-fixed.csv")).expect("golden-fixed.csv"),
        Path::new("golden-fixed.csv"),
    )
    .expect("parse");
    let (mut flagged, mut near, mut rows) = (0, 0, 0);
    for row in &fixed_rows {
        let q = row.pose;
        let exact = q.map(|v| f64::from(v) / Q16);
        if exact.iter().any(|v| v.abs() >= 256.0) {
            continue; // the f32 pose would not be exact
        }
        rows += 1;
        let (a, b) = (fixed_flag(q), f32_flag(exact.map(|v| v as f32)));
        assert_eq!(a, row.status & needle_contract::status::FE_UNSOLVED != 0, "golden-fixed.csv pose {q:?}: the flag is not the file's");
        flagged += usize::from(a);
        if a != b {
            assert!(near_surface(&entries, exact, band), "pose {q:?}: fixed {a}, f32 {b}, and not within {band} of a ball's surface");
            near += 1;
        }
    }
    // golden-f32.csv: the finite poses, and their nearest Q16.16 pose
    let f32_rows = needle_fit::golden::float32::parse_csv(
        &std::fs::read_to_string(set_dir().join("golden-f32.csv")).expect("golden-f32.csv"),
        Path::new("golden-f32.csv"),
    )
    .expect("parse");
    for row in &f32_rows {
        let p = row.pose;
        if p.iter().any(|v| !v.is_finite() || v.abs() >= 256.0) {
            continue;
        }
        rows += 1;
        let exact = p.map(f64::from);
        let (a, b) = (f32_flag(p), fixed_flag(exact.map(|v| (v * Q16).round() as i32)));
        assert_eq!(a, row.status & needle_contract::status::FE_UNSOLVED != 0, "golden-f32.csv pose {p:?}: the flag is not the file's");
        flagged += usize::from(a);
        if a != b {
            assert!(near_surface(&entries, exact, band), "pose {p:?}: f32 {a}, fixed {b}, and not within {band} of a ball's surface");
            near += 1;
        }
    }
    println!("{rows} golden poses: {flagged} flagged; f32 and fixed point disagree at {near}, each within {band} of a ball's surface");
    assert!(flagged > 100, "the golden poses must include poses in the region: only {flagged}");
    assert!(rows - flagged > 1000, "and poses outside it");
    assert_eq!(near, 0, "the golden poses keep away from the balls' surfaces, so the evaluators agree on every one");
}

/// The library's prefilter never drops a ball that holds the pose: at random poses around
/// every ball (a box of 1.5 radii, random depths), its flag is the fitter's test over
/// every ball, in f32 and in fixed point.
#[test]
fn the_prefilter_drops_no_ball() {
    use rand::{Rng, SeedableRng};
    let entries = entries();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0x6e65_6564_6c65_0021);
    let [rx, rz, rtx, rtz] = needle_contract::CROSS_SCALES_F32;
    let (mut inside, mut total) = (0, 0);
    for e in &entries {
        let r = e.radius_q15 as f64 / Q15;
        for _ in 0..4000 {
            let v: [f64; 4] = std::array::from_fn(|k| (e.centre_q15[k] as f64 / Q15 + rng.gen_range(-1.5..1.5) * r) * V[k]);
            let d: f64 = rng.gen_range(-0.5..6.5);
            let p = [v[0] as f32, v[1] as f32, v[2] as f32, v[3] as f32, d as f32];
            let c: [f32; 5] =
                [p[0].clamp(-12.0, 12.0), p[1].clamp(-12.0, 12.0), p[2].clamp(-15.0, 15.0), p[3].clamp(-15.0, 15.0), p[4].clamp(0.0, 6.0)];
            let want = unsolved::inside_f32(&entries, [c[0] * rx, c[1] * rz, c[2] * rtx, c[3] * rtz], c[4]);
            assert_eq!(f32_flag(p), want, "f32 pose {p:?}");
            let q = p.map(|v| (f64::from(v) * Q16).round() as i32);
            let qc: [i64; 5] = [
                i64::from(q[0]).clamp(-12 << 16, 12 << 16),
                i64::from(q[1]).clamp(-12 << 16, 12 << 16),
                i64::from(q[2]).clamp(-15 << 16, 15 << 16),
                i64::from(q[3]).clamp(-15 << 16, 15 << 16),
                i64::from(q[4]).clamp(0, 6 << 16),
            ];
            let divisors = needle_contract::FIXED_CROSS_DIVISORS.map(i64::from);
            let n: [i64; 4] = std::array::from_fn(|k| {
                let m = (qc[k].abs() + divisors[k] / 2) / divisors[k];
                if qc[k] < 0 {
                    -m
                } else {
                    m
                }
            });
            assert_eq!(fixed_flag(q), unsolved::inside_fixed(&entries, n, qc[4]), "fixed pose {q:?}");
            inside += usize::from(want);
            total += 1;
        }
    }
    println!("{total} poses around the balls, {inside} inside");
    assert!(inside > total / 30, "the poses must reach into the balls");
}
