//! `/set.json` of the explorer: what the page needs besides the evaluator.

use anyhow::{Context, Result};
use needle_fit::data::{run_path, FeRuns};
use needle_set::set_folder::SetFolder;
use serde_json::{json, Value};

/// The set's name, the folder as given on the command line (for "copy as command"), the
/// needle and block dimensions (mm, degrees: the side view), and every solved FE run of
/// the set (`fe/<pose>.csv`): pose, role, depths (mm) and the six wrench components (N,
/// N*mm) per depth. Poses not solved yet are left out, and so is a CSV without an entry
/// in `fe/manifest.toml` (no FE run of the campaign vouches for it: `needle validate`
/// leaves it out too). `viscoelastic`: the Prony terms of the campaign's FE verification
/// (`[viscoelastic]`: `g`, `tau_s`), or null; the insertion player starts with them.
///
/// # Errors
/// A run file exists but is not a complete run of the
/// spec's depth grid (the message names the file).
pub fn set_json(set: &SetFolder) -> Result<Value> {
    let (c, set_dir) = (set.campaign(), set.dir());
    let fe = FeRuns::new(set, c);
    let manifest = fe.manifest();
    let mut runs = Vec::new();
    for pose in c.poses() {
        if !run_path(set_dir, &pose).is_file() || !manifest.pose.contains_key(&pose.name) {
            continue;
        }
        let run = fe.read(&pose).with_context(|| format!("FE run {} of the explorer", pose.name))?;
        runs.push(json!({
            "name": pose.name,
            "role": serde_json::to_value(pose.role)?,
            "x_mm": pose.x_mm,
            "z_mm": pose.z_mm,
            "theta_x_deg": pose.theta_x_deg,
            "theta_z_deg": pose.theta_z_deg,
            "depth_mm": run.rows.iter().map(|r| r.depth_mm).collect::<Vec<_>>(),
            "wrench": run.rows.iter().map(|r| r.wrench.to_vec()).collect::<Vec<_>>(),
        }));
    }
    Ok(json!({
        "set": c.set.name,
        "set_arg": set_dir.display().to_string(),
        "needle": {
            "diameter_mm": c.needle.diameter_mm,
            "wedge_half_angle_deg": c.needle.wedge_half_angle_deg,
            "reference_from_tip_mm": c.needle.reference_from_tip_mm,
        },
        "block": { "size_x_mm": c.block.size_x_mm, "size_z_mm": c.block.size_z_mm, "depth_mm": c.block.depth_mm },
        "runs": runs,
        "viscoelastic": c.viscoelastic.as_ref().map(|v| json!({ "g": v.g, "tau_s": v.tau_s })),
    }))
}
