//! Issue 64, item 2: the material family's law at the check poses. The shipped
//! `coeffs/default/family.toml`'s `[[pose_check]]` tables are what a fresh computation
//! gives from the shipped `model.toml`, the law's coefficients in `family.toml` and the
//! check runs in `fe/family/` (every run present there, complete or partial, has its
//! table); a complete run's Fy error is recomputed here from the CSV on its own; every
//! complete check run meets the must (5 %). The goal (3 %) is held per pose (the issue's
//! "two family members far from the paper's"): every check pose has at least two complete
//! members within it. Not every member meets it: x+04_w0p01 (worst 3.35 %, its Fx and
//! Mz, from two must points where the member's lateral force jumps: contact stick-slip),
//! x+04_w0p03 and z+02_w0p03 (4.2-4.5 %) and z+02_w0p01 (3.01 %) are within the must only.
use needle_fit::family::{ratio, TERMS};
use needle_fit::family_poses::{checks, PoseCheck, GOAL_PCT, MUST_PCT};
use needle_set::set_folder::SetFolder;
use std::path::PathBuf;

fn set_dir() -> PathBuf {
    needle_stdx::workspace_root().join("coeffs/default")
}

fn floats(v: &toml::Value, key: &str) -> Vec<f64> {
    v.get(key).and_then(toml::Value::as_array).map(|a| a.iter().filter_map(toml::Value::as_float).collect()).unwrap_or_default()
}

fn float(v: &toml::Value, key: &str) -> Option<f64> {
    v.get(key).and_then(toml::Value::as_float)
}

/// One shipped table against its fresh computation, field by field (exact: the same
/// f64 computation, written shortest round trip).
fn assert_table(t: &toml::Value, c: &PoseCheck) {
    let at = format!("[[pose_check]] {} w {}", c.pose, c.weight);
    assert_eq!(t.get("complete").and_then(toml::Value::as_bool), Some(c.complete), "{at}: complete");
    assert_eq!(float(t, "depth_mm"), Some(c.depth_mm), "{at}: depth_mm");
    assert_eq!(t.get("must_points").and_then(toml::Value::as_integer), Some(c.must_points as i64), "{at}: must_points");
    assert_eq!(float(t, "peak_fy_n"), Some(c.peak_fy_n), "{at}: peak_fy_n");
    assert_eq!(floats(t, "rms_pct"), c.rms_pct.to_vec(), "{at}: rms_pct");
    assert_eq!(floats(t, "max_pct"), c.max_pct.to_vec(), "{at}: max_pct");
    assert_eq!(float(t, "worst_pct"), Some(c.worst_pct), "{at}: worst_pct");
    assert_eq!(float(t, "fe_paper_worst_pct"), c.fe_paper_worst_pct(), "{at}: fe_paper_worst_pct");
    assert_eq!(floats(t, "fe_paper_rms_pct"), c.fe_paper_rms_pct.map(|r| r.to_vec()).unwrap_or_default(), "{at}: fe_paper_rms_pct");
}

/// The check runs in `fe/family/` by their file names (`<pose>_w<w>.csv` or
/// `.partial.csv` for each check pose and weight of the spec), found without the fitter.
fn check_runs_on_disk(set: &SetFolder) -> Vec<(String, f64, bool)> {
    let f = set.campaign().family.clone().expect("coeffs/default has a [family] section");
    let dir = set.fe_dir().join("family");
    let mut out = Vec::new();
    for pose in &f.check_poses {
        for &w in &f.check_weight {
            let stem = format!("{pose}_w{}", format!("{w}").replace('.', "p"));
            if dir.join(format!("{stem}.csv")).is_file() {
                out.push((pose.clone(), w, true));
            } else if dir.join(format!("{stem}.partial.csv")).is_file() {
                out.push((pose.clone(), w, false));
            }
        }
    }
    out
}

/// The RMS of `model g - FE` in Fy over the run's must points, % of its peak |Fy|: the
/// definition, written out here apart from the fitter's.
fn fy_rms_pct(set: &SetFolder, model: &needle_fit::model::Model, law: (&[f64; TERMS], f64), c: &PoseCheck) -> f64 {
    let p = set.campaign().poses().into_iter().find(|p| p.name == c.pose).expect("the check pose is a campaign pose");
    let file = set.fe_dir().join("family").join(format!("{}_w{}.csv", c.pose, format!("{}", c.weight).replace('.', "p")));
    let rows = needle_set::results::read_csv(&file).expect("the complete check run");
    let rows: Vec<_> = rows.iter().filter(|r| r.depth_mm > 0.0).collect();
    let peak = rows.iter().map(|r| r.wrench[1].abs()).fold(0.0, f64::max);
    let sum: f64 = rows
        .iter()
        .map(|r| {
            let w = needle_fit::eval::float64::eval(model, [p.x_mm, p.z_mm, p.theta_x_deg, p.theta_z_deg, r.depth_mm]).0;
            let e = w[1] * ratio(law.0, law.1, r.depth_mm, c.weight) - r.wrench[1];
            e * e
        })
        .sum();
    100.0 * (sum / rows.len() as f64).sqrt() / peak
}

#[test]
fn the_shipped_pose_checks_are_a_fresh_computation_and_a_complete_run_meets_the_must() {
    let set = SetFolder::open(&set_dir()).unwrap_or_else(|e| panic!("{e:#}"));
    let model = needle_fit::model_file::read(&set.file(needle_fit::MODEL_FILE)).unwrap_or_else(|e| panic!("{e}"));
    let path = set.file(needle_fit::family::FILE);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let file: toml::Value = toml::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let coeffs: [f64; TERMS] = floats(&file, "coeffs").try_into().expect("TERMS coefficients");
    let depth_max_mm = float(&file, "depth_max_mm").expect("depth_max_mm");
    let fresh = checks(&set, &model, &coeffs, depth_max_mm).unwrap_or_else(|e| panic!("{e:#}"));

    let on_disk = check_runs_on_disk(&set);
    let computed: Vec<(String, f64, bool)> = fresh.checks.iter().map(|c| (c.pose.clone(), c.weight, c.complete)).collect();
    assert_eq!(computed, on_disk, "one pose check per check run in fe/family/, complete or partial");
    let tables = file.get("pose_check").and_then(toml::Value::as_array).cloned().unwrap_or_default();
    assert_eq!(tables.len(), fresh.checks.len(), "{}: one [[pose_check]] per check run: rerun needle fit", path.display());
    for (t, c) in tables.iter().zip(&fresh.checks) {
        assert_eq!(t.get("pose").and_then(toml::Value::as_str), Some(c.pose.as_str()));
        assert_eq!(float(t, "weight"), Some(c.weight));
        assert_table(t, c);
    }

    let complete: Vec<&PoseCheck> = fresh.checks.iter().filter(|c| c.complete).collect();
    assert!(!complete.is_empty(), "no complete check run in fe/family/ (x+04_w0p01 is committed)");
    for c in &complete {
        eprintln!(
            "{} w {}: worst {:.3} % (rms % {:?}); with fe/{}.csv x g: {:?} %",
            c.pose,
            c.weight,
            c.worst_pct,
            c.rms_pct,
            c.pose,
            c.fe_paper_worst_pct()
        );
        assert_eq!(c.must_points, 20, "{} w {}: a complete run has every must point to 6 mm", c.pose, c.weight);
        let own = fy_rms_pct(&set, &model, (&coeffs, depth_max_mm), c);
        assert!(
            (own - c.rms_pct[1]).abs() <= 1e-9 * own.max(1.0),
            "{} w {}: Fy {own} % here, {} % by the fitter",
            c.pose,
            c.weight,
            c.rms_pct[1]
        );
        assert_eq!(c.worst_pct, c.rms_pct.iter().copied().fold(0.0, f64::max));
        assert!(c.worst_pct.is_finite() && c.worst_pct > 0.0, "{} w {}: worst {}", c.pose, c.weight, c.worst_pct);
        assert!(c.worst_pct <= MUST_PCT, "{} w {}: the law misses the must: worst {:.3} % > {MUST_PCT} %", c.pose, c.weight, c.worst_pct);
    }
}

#[test]
fn every_check_pose_has_two_complete_members_within_the_goal() {
    let set = SetFolder::open(&set_dir()).unwrap_or_else(|e| panic!("{e:#}"));
    let path = set.file(needle_fit::family::FILE);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let file: toml::Value = toml::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let tables = file.get("pose_check").and_then(toml::Value::as_array).cloned().unwrap_or_default();
    let family = set.campaign().family.clone().expect("coeffs/default has a [family] section");
    for pose in &family.check_poses {
        let within: Vec<f64> = tables
            .iter()
            .filter(|t| t.get("pose").and_then(toml::Value::as_str) == Some(pose.as_str()))
            .filter(|t| t.get("complete").and_then(toml::Value::as_bool) == Some(true))
            .filter(|t| float(t, "worst_pct").is_some_and(|w| w <= GOAL_PCT))
            .filter_map(|t| float(t, "weight"))
            .collect();
        eprintln!("{pose}: complete members within {GOAL_PCT} %: {within:?}");
        assert!(within.len() >= 2, "{pose}: {} complete member(s) within the goal {GOAL_PCT} % ({within:?}); two wanted", within.len());
    }
}
