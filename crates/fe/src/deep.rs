//! Deep runs: `[deep]` of campaign.toml, the pre-puncture response beyond the campaign's
//! `loading.depth_mm` (issue 41, item 5). `needle fe run --deep` solves the listed poses
//! to `deep.depth_mm` in `deep.steps` load steps on `deep.mesh` through the campaign's
//! own machinery (resume, retry ladder, continuation from the last must point, manifest)
//! into `<set>/fe/deep/<pose>.csv` and `<set>/fe/deep/manifest.toml`.
//!
//! A deep run is the campaign's spec with `[loading]` replaced by the deep depth and
//! steps ([`DeepSettings::apply`]), so its run hash differs from the shallow run's and the
//! two never mix. The mesh level's fine layers must reach past the deep depth: the tip
//! would otherwise cut through layers that grow geometrically below `fine_depth_mm`.

use crate::spec::{check_pose_in_block, Campaign, Loading};
use anyhow::{bail, Result};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Sub-folder of `<set>/fe/` holding the deep runs and their manifest.
pub const DEEP_DIR: &str = "deep";

/// `[deep]`: which poses are solved how deep, in how many load steps, on which mesh.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DeepSettings {
    /// Final depth along the needle axis, mm (beyond `loading.depth_mm`, inside the block).
    pub depth_mm: f64,
    /// Number of equal load steps to `depth_mm` (results at steps + 1 depths).
    pub steps: u32,
    /// Mesh level (`[mesh.<level>]`) whose fine layers reach past `depth_mm`.
    pub mesh: String,
    /// Pose names of the campaign (listed or generated), solved in this order.
    pub poses: Vec<String>,
}

impl DeepSettings {
    /// The campaign's spec as a deep run sees it: `[loading]` to the deep depth and steps.
    pub fn apply(&self, c: &Campaign) -> Campaign {
        let mut deep = c.clone();
        deep.loading = Loading { depth_mm: self.depth_mm, steps: self.steps };
        deep
    }
}

/// The 1-based line of `key = ...` inside the `[section]` table of `text` (0 when not
/// found), for `file:line` in messages.
pub fn key_line(text: &str, section: &str, key: &str) -> usize {
    let header = format!("[{section}]");
    let mut inside = false;
    for (i, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.starts_with('[') {
            inside = t == header;
            if inside && key.is_empty() {
                return i + 1;
            }
            continue;
        }
        if inside && t.split('=').next().map(str::trim) == Some(key) {
            return i + 1;
        }
    }
    0
}

/// Check `[deep]` against the rest of the spec; messages start with `file:line:` and name
/// the field (`deep.depth_mm = ...`).
///
/// # Errors
/// A depth not beyond `loading.depth_mm` or not inside the block, 0 steps, an unknown
/// mesh level or one whose fine layers stop above the depth, no poses, an unknown or
/// repeated pose, or a pose whose needle leaves the block at the deep depth.
pub fn validate(c: &Campaign, text: &str, path: &Path) -> Result<()> {
    let Some(d) = &c.deep else { return Ok(()) };
    let at = |key: &str| format!("{}:{}", path.display(), key_line(text, "deep", key));
    if !(d.depth_mm.is_finite() && d.depth_mm > c.loading.depth_mm && d.depth_mm < c.block.depth_mm) {
        bail!(
            "{}: deep.depth_mm = {}: must be beyond loading.depth_mm ({} mm) and inside the block (block.depth_mm = {} mm)",
            at("depth_mm"),
            d.depth_mm,
            c.loading.depth_mm,
            c.block.depth_mm
        );
    }
    if d.steps == 0 {
        bail!("{}: deep.steps = 0: must be >= 1", at("steps"));
    }
    let Some(level) = c.mesh.get(&d.mesh) else {
        let levels: Vec<&str> = c.mesh.keys().map(String::as_str).collect();
        bail!("{}: deep.mesh = {:?}: no [mesh.{}] level (levels: {})", at("mesh"), d.mesh, d.mesh, levels.join(", "));
    };
    if level.fine_depth_mm < d.depth_mm {
        bail!(
            "{}: deep.mesh = {:?}: its fine layers end at fine_depth_mm = {} mm, above deep.depth_mm = {} mm (the tip would cut through coarse layers)",
            at("mesh"),
            d.mesh,
            level.fine_depth_mm,
            d.depth_mm
        );
    }
    if d.poses.is_empty() {
        bail!("{}: deep.poses is empty: name at least one pose (e.g. \"centre\")", at("poses"));
    }
    let every = c.poses();
    for (k, name) in d.poses.iter().enumerate() {
        if d.poses[..k].contains(name) {
            bail!("{}: deep.poses: {name:?} is listed twice", at("poses"));
        }
        let Some(pose) = every.iter().find(|p| &p.name == name) else {
            bail!("{}: deep.poses: {name:?} is not a pose of this campaign", at("poses"));
        };
        let radius_mm = c.needle.diameter_mm / 2.0;
        check_pose_in_block(pose, &c.block, radius_mm, d.depth_mm, &at("poses"))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shipped() -> String {
        std::fs::read_to_string(crate::workspace_root().join("coeffs/default/campaign.toml")).expect("campaign.toml")
    }

    fn error_of(text: &str) -> String {
        crate::spec::parse(text, Path::new("campaign.toml")).err().map(|e| e.to_string()).unwrap_or_default()
    }

    #[test]
    fn the_shipped_deep_section_applies_its_depth_and_steps() {
        let text = shipped();
        let c = crate::spec::parse(&text, Path::new("campaign.toml")).expect("the shipped spec");
        let d = c.deep.clone().expect("coeffs/default has a [deep] section");
        let deep = d.apply(&c);
        assert_eq!((deep.loading.depth_mm, deep.loading.steps), (d.depth_mm, d.steps));
        assert_eq!(d.poses.first().map(String::as_str), Some("centre"));
        let centre = c.poses().into_iter().find(|p| p.name == "centre").expect("centre");
        assert_ne!(deep.run_hash(&centre, &d.mesh), c.run_hash(&centre, &d.mesh), "a deep run never passes for a shallow one");
    }

    #[test]
    fn bad_deep_sections_are_refused_with_file_line_and_field() {
        let text = shipped();
        let line = |key: &str| key_line(&text, "deep", key);
        assert!(line("depth_mm") > 0 && line("mesh") > 0 && line("poses") > 0, "the shipped [deep] names its fields");
        let deep_line = |key: &str| text.lines().nth(line(key) - 1).expect("a [deep] line").to_string();
        let (depth, poses, mesh, steps) = (deep_line("depth_mm"), deep_line("poses"), deep_line("mesh"), deep_line("steps"));
        let cases = [
            (text.replace(&depth, "depth_mm = 5.0"), format!("campaign.toml:{}: deep.depth_mm = 5: must be beyond", line("depth_mm"))),
            (text.replace(&depth, "depth_mm = 31.0"), "inside the block (block.depth_mm = 30 mm)".to_string()),
            (
                text.replace(&mesh, "mesh = \"needle8\""),
                format!("campaign.toml:{}: deep.mesh = \"needle8\": its fine layers end at fine_depth_mm = 0.4 mm", line("mesh")),
            ),
            (text.replace(&mesh, "mesh = \"huge\""), "deep.mesh = \"huge\": no [mesh.huge] level".to_string()),
            (text.replace(&poses, "poses = []"), format!("campaign.toml:{}: deep.poses is empty", line("poses"))),
            (
                text.replace(&poses, "poses = [\"centre\", \"nowhere\"]"),
                "deep.poses: \"nowhere\" is not a pose of this campaign".to_string(),
            ),
            (text.replace(&poses, "poses = [\"centre\", \"centre\"]"), "deep.poses: \"centre\" is listed twice".to_string()),
            // x = 12 mm tilted 15 degrees outwards: inside a 30 mm wide block at 6 mm
            // (reach 14.05 mm), outside at 15 mm (16.38 mm)
            (
                format!("{text}\n[[pose]]\nname = \"edge\"\nrole = \"mirror\"\nx_mm = 12.0\ntheta_z_deg = 15.0\n")
                    .replace("size_x_mm = 50.0", "size_x_mm = 30.0")
                    .replace(&poses, "poses = [\"centre\", \"edge\"]")
                    .replace(&depth, "depth_mm = 15.0")
                    .replace(&steps, "steps = 50"),
                format!(
                    "campaign.toml:{}: pose \"edge\": x_mm = 12 with a lateral travel of 3.882 mm at full depth (15 mm)",
                    line("poses")
                ),
            ),
        ];
        for (spec, want) in cases {
            assert_ne!(spec, text, "the test's edit did not apply ({want})");
            let msg = error_of(&spec);
            assert!(msg.contains(&want), "want {want:?} in: {msg}");
        }
        let zero = text.replace(&steps, "steps = 0");
        assert!(error_of(&zero).contains(&format!("campaign.toml:{}: deep.steps = 0: must be >= 1", line("steps"))), "{}", error_of(&zero));
    }

    #[test]
    fn key_line_finds_keys_inside_their_table_only() {
        let t = "[a]\nx = 1\n[deep]\n# c\nx = 2\nposes = [\"a\"]\n[b]\nx = 3\n";
        assert_eq!((key_line(t, "deep", "x"), key_line(t, "deep", "poses"), key_line(t, "deep", "")), (5, 6, 3));
        assert_eq!(key_line(t, "deep", "y"), 0);
    }
}
