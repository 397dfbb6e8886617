//! The shipped set's mesh study (`needle fe verify --mesh`, issue 42, item 1): in
//! `coeffs/default/fe/verify.toml` `[mesh]`, the campaign's level against its refinement,
//! after the best single scale. The goal (2 % RMS, 4 % largest of peak |Fy|, every
//! component) is judged on the must points; a pose the refinement could not solve is
//! listed with its failure (a record, counted as missed in the README), never skipped
//! silently.
//!
//! What this test holds, per compared pose:
//! - the shape in the model's form (each run's degree-4 depth fit, `fit_worst_*`) is
//!   within the goal: the shape the product is built from has converged;
//! - where the reference is clean (its must points lie within half the goal's largest
//!   difference of its own fit, `fine_off_fit_percent`), the must points are within the
//!   goal too. Where it is not, the must-point comparison measures the reference's own
//!   scatter as much as the campaign's shape: printed, counted as missed in the README,
//!   not asserted. Why a reference can be unclean is measured in
//!   coeffs/default/README.md ("Mesh study": Newton's loose energy, then residual,
//!   tolerance, under which the must points depended on the time steps taken).
//! - the centre is compared, clean and within the goal.
//!
//! The numbers are FEBio's, written by the tool (never typed in).

use needle_fe::verify::shape::{SHAPE_MAX_GOAL_PERCENT, SHAPE_RMS_GOAL_PERCENT};
use std::path::Path;

/// A reference whose must points lie within this of its own depth fit (% of peak |Fy|) is
/// clean enough to judge the must-point goal: half the goal's largest difference, so that
/// its scatter alone cannot take the comparison past the goal.
const CLEAN_REFERENCE_PERCENT: f64 = SHAPE_MAX_GOAL_PERCENT / 2.0;

fn num(t: &toml::Value, key: &str) -> f64 {
    t.get(key).and_then(toml::Value::as_float).unwrap_or(f64::NAN)
}

fn text<'a>(t: &'a toml::Value, key: &str) -> &'a str {
    t.get(key).and_then(toml::Value::as_str).unwrap_or("")
}

#[test]
fn the_campaign_level_carries_the_refinements_shape() {
    let set = Path::new(env!("CARGO_MANIFEST_DIR")).join("../coeffs/default");
    let (c, _) = needle_fe::spec::load(&set).expect("the shipped spec");
    let path = set.join("fe/verify.toml");
    let t: toml::Value = std::fs::read_to_string(&path).expect("fe/verify.toml").parse().expect("TOML");
    let mesh = t.get("mesh").unwrap_or_else(|| panic!("{}: no [mesh]", path.display()));
    let (committed, refined) = (text(mesh, "committed"), text(mesh, "refined"));
    assert_eq!(committed, c.campaign.mesh, "the study judges the campaign's level");
    let refined_level = c.mesh_level(refined).expect("the refinement is a level of the spec");
    assert!(refined_level.etol.is_some(), "the reference level {refined} is solved to its own energy tolerance");
    assert!(refined_level.rtol.is_some(), "and to its own residual tolerance");
    let shapes = mesh.get("shape").and_then(toml::Value::as_array).cloned().unwrap_or_default();
    let levels = mesh.get("levels").and_then(toml::Value::as_array).cloned().unwrap_or_default();
    let poses: Vec<&str> = std::iter::once("centre").chain(c.campaign.mesh_study_poses.iter().map(String::as_str)).collect();
    let mut clean = Vec::new();
    for pose in poses {
        let pair = shapes.iter().find(|s| text(s, "pose") == pose && text(s, "coarse") == committed && text(s, "fine") == refined);
        let Some(pair) = pair else {
            let run = levels.iter().find(|l| text(l, "pose") == pose && text(l, "level") == refined);
            let failure = run.map(|l| text(l, "failure")).unwrap_or("");
            assert!(!failure.is_empty(), "{pose}: neither a shape comparison nor a recorded failure on {refined}");
            assert_ne!(pose, "centre", "the centre must be compared: {failure}");
            println!("{pose}: not solved on {refined} (counted as missed): {failure}");
            continue;
        };
        let (rms, max, scatter) = (num(pair, "worst_rms_percent"), num(pair, "worst_max_percent"), num(pair, "fine_off_fit_percent"));
        let (fit_rms, fit_max) = (num(pair, "fit_worst_rms_percent"), num(pair, "fit_worst_max_percent"));
        println!(
            "{pose}: {committed} vs {refined}: {rms:.2} % RMS, {max:.2} % largest; on the depth fits {fit_rms:.2} / {fit_max:.2} %; {refined} off its own fit {scatter:.2} %"
        );
        assert!(fit_rms <= SHAPE_RMS_GOAL_PERCENT, "{pose}: the depth fits differ by {fit_rms} % RMS > {SHAPE_RMS_GOAL_PERCENT} %");
        assert!(fit_max <= SHAPE_MAX_GOAL_PERCENT, "{pose}: the depth fits differ by {fit_max} % > {SHAPE_MAX_GOAL_PERCENT} %");
        if scatter < CLEAN_REFERENCE_PERCENT {
            assert!(rms <= SHAPE_RMS_GOAL_PERCENT, "{pose}: {rms} % RMS > {SHAPE_RMS_GOAL_PERCENT} %");
            assert!(max <= SHAPE_MAX_GOAL_PERCENT, "{pose}: {max} % largest > {SHAPE_MAX_GOAL_PERCENT} %");
            clean.push(pose);
        } else {
            let met = rms <= SHAPE_RMS_GOAL_PERCENT && max <= SHAPE_MAX_GOAL_PERCENT;
            println!(
                "{pose}: the reference scatters by {scatter:.2} % about its own fit: the must-point goal {}",
                if met { "met" } else { "missed" }
            );
        }
    }
    assert!(clean.contains(&"centre"), "the centre's reference is clean and within the goal (clean: {clean:?})");
}
