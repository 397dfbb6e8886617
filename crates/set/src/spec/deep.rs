//! `[deep]` of campaign.toml: the section's type, checked and applied beside the rest of
//! the spec (the engine's `needle_fe::deep` runs it).

use super::error::{SpecError, SpecResult};
use super::loading::{Loading, MAX_LOAD_STEPS};
use super::pose::check_pose_in_block;
use super::Campaign;
use serde::{Deserialize, Serialize};
use std::path::Path;

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
        deep.loading = Loading { depth_mm: self.depth_mm, steps: self.steps, ramp_hold: None };
        deep
    }
}

/// Check `[deep]` against the rest of the spec; messages start with `file:line:` and name
/// the field (`deep.depth_mm = ...`).
///
/// # Errors
/// A depth not beyond `loading.depth_mm` or not inside the block, 0 steps, an unknown
/// mesh level or one whose fine layers stop above the depth, no poses, an unknown or
/// repeated pose, or a pose whose needle leaves the block at the deep depth.
pub fn validate_deep(c: &Campaign, text: &str, path: &Path) -> SpecResult<()> {
    let Some(d) = &c.deep else { return Ok(()) };
    let at = |key: &str| format!("{}:{}", path.display(), super::key_line(text, "deep", key));
    if !(d.depth_mm.is_finite() && d.depth_mm > c.loading.depth_mm && d.depth_mm < c.block.depth_mm) {
        return Err(SpecError::range(
            at("depth_mm"),
            "deep.depth_mm",
            format!(
                "deep.depth_mm = {}: must be beyond loading.depth_mm ({} mm) and inside the block (block.depth_mm = {} mm)",
                d.depth_mm, c.loading.depth_mm, c.block.depth_mm
            ),
        ));
    }
    if d.steps == 0 || d.steps > MAX_LOAD_STEPS {
        return Err(SpecError::range(at("steps"), "deep.steps", format!("deep.steps = {}: must be 1 ..= {MAX_LOAD_STEPS}", d.steps)));
    }
    let Some(level) = c.mesh.get(&d.mesh) else {
        let levels: Vec<&str> = c.mesh.keys().map(String::as_str).collect();
        let message = format!("deep.mesh = {:?}: no [mesh.{}] level (levels: {})", d.mesh, d.mesh, levels.join(", "));
        return Err(SpecError::unknown(at("mesh"), "deep.mesh", &d.mesh, message));
    };
    if level.fine_depth_mm < d.depth_mm {
        return Err(SpecError::inconsistent(
            at("mesh"),
            "deep.mesh",
            format!(
                "deep.mesh = {:?}: its fine layers end at fine_depth_mm = {} mm, above deep.depth_mm = {} mm (the tip would cut through coarse layers)",
                d.mesh, level.fine_depth_mm, d.depth_mm
            ),
        ));
    }
    if d.poses.is_empty() {
        return Err(SpecError::range(at("poses"), "deep.poses", "deep.poses is empty: name at least one pose (e.g. \"centre\")"));
    }
    let every = c.poses();
    for (k, name) in d.poses.iter().enumerate() {
        if d.poses[..k].contains(name) {
            return Err(SpecError::duplicate(at("poses"), "deep.poses", name, format!("deep.poses: {name:?} is listed twice")));
        }
        let Some(pose) = every.iter().find(|p| &p.name == name) else {
            return Err(SpecError::unknown(
                at("poses"),
                "deep.poses",
                name,
                format!("deep.poses: {name:?} is not a pose of this campaign"),
            ));
        };
        let radius_mm = c.needle.diameter_mm / 2.0;
        check_pose_in_block(pose, &c.block, radius_mm, d.depth_mm, &at("poses"))?;
    }
    Ok(())
}

#[cfg(test)]
mod deep_tests {
    use super::*;
    use crate::spec::key_line;
    use crate::spec::parse;

    fn shipped() -> String {
        std::fs::read_to_string(needle_stdx::workspace_root().join("coeffs/default/campaign.toml")).expect("campaign.toml")
    }

    fn refusal(text: &str) -> SpecError {
        match parse(text, Path::new("campaign.toml")) {
            Ok(_) => panic!("the spec was accepted"),
            Err(e) => e,
        }
    }

    #[test]
    fn the_shipped_deep_section_applies_its_depth_and_steps() {
        let text = shipped();
        let c = parse(&text, Path::new("campaign.toml")).expect("the shipped spec");
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
        type Is = fn(&SpecError) -> bool;
        let range: Is = |e| matches!(e, SpecError::OutOfRange { .. });
        let inconsistent: Is = |e| matches!(e, SpecError::Inconsistent { .. });
        let unknown: Is = |e| matches!(e, SpecError::Unknown { .. });
        let duplicate: Is = |e| matches!(e, SpecError::Duplicate { .. });
        let outside: Is = |e| matches!(e, SpecError::OutsideBlock { pose, .. } if pose == "edge");
        let cases: [(String, Is, &str, &str); 8] = [
            (text.replace(&depth, "depth_mm = 5.0"), range, "deep.depth_mm", "depth_mm"),
            (text.replace(&depth, "depth_mm = 31.0"), range, "deep.depth_mm", "depth_mm"),
            // its fine layers end at 0.4 mm
            (text.replace(&mesh, "mesh = \"needle8\""), inconsistent, "deep.mesh", "mesh"),
            (text.replace(&mesh, "mesh = \"huge\""), unknown, "deep.mesh", "mesh"),
            (text.replace(&poses, "poses = []"), range, "deep.poses", "poses"),
            (text.replace(&poses, "poses = [\"centre\", \"nowhere\"]"), unknown, "deep.poses", "poses"),
            (text.replace(&poses, "poses = [\"centre\", \"centre\"]"), duplicate, "deep.poses", "poses"),
            // x = 12 mm tilted 15 degrees outwards: inside a 30 mm wide block at 6 mm
            // (reach 14.05 mm), outside at 15 mm (16.38 mm)
            (
                format!("{text}\n[[pose]]\nname = \"edge\"\nrole = \"mirror\"\nx_mm = 12.0\ntheta_z_deg = 15.0\n")
                    .replace("size_x_mm = 50.0", "size_x_mm = 30.0")
                    .replace(&poses, "poses = [\"centre\", \"edge\"]")
                    .replace(&depth, "depth_mm = 15.0")
                    .replace(&steps, "steps = 50"),
                outside,
                "pose",
                "poses",
            ),
        ];
        for (spec, is, field, key) in cases {
            assert_ne!(spec, text, "the test's edit did not apply ({field})");
            let e = refusal(&spec);
            assert!(is(&e) && e.field() == field, "want {field} refused: {e:?}");
            assert_eq!(e.at(), format!("campaign.toml:{}", line(key)), "{e}");
            assert!(e.to_string().starts_with(&format!("campaign.toml:{}: ", line(key))), "file:line first: {e}");
        }
        for n in ["0", "4000000000"] {
            let e = refusal(&text.replace(&steps, &format!("steps = {n}")));
            assert!(
                matches!(&e, SpecError::OutOfRange { field, at, .. } if field == "deep.steps" && *at == format!("campaign.toml:{}", line("steps"))),
                "{e:?}"
            );
        }
    }

    /// A typo of billions (`4e9` read as 4,000,000,000) in a count the campaign
    /// allocates per item is refused at load, before anything is allocated (it aborted
    /// `fe status`, `validate` and `fe run` with an allocation failure).
    #[test]
    fn counts_of_billions_are_refused_at_load() {
        let text = shipped();
        let line_of = |table: &str, key: &str| -> String {
            let l = key_line(&text, table, key);
            assert!(l > 0, "the shipped spec has {table}.{key}");
            text.lines().nth(l - 1).expect("line").to_string()
        };
        for (table, key, field) in [
            ("loading", "steps", "loading.steps"),
            ("campaign", "lhs_count", "campaign.lhs_count"),
            ("campaign", "train_count", "campaign.train_count"),
        ] {
            let bad = text.replacen(&line_of(table, key), &format!("{key} = 4000000000"), 1);
            assert_ne!(bad, text);
            let e = refusal(&bad);
            assert!(matches!(&e, SpecError::OutOfRange { field: f, .. } if f == field), "want {field} refused: {e:?}");
        }
    }

    #[test]
    fn key_line_finds_keys_inside_their_table_only() {
        let t = "[a]\nx = 1\n[deep]\n# c\nx = 2\nposes = [\"a\"]\n[b]\nx = 3\n";
        assert_eq!((key_line(t, "deep", "x"), key_line(t, "deep", "poses"), key_line(t, "deep", "")), (5, 6, 3));
        assert_eq!(key_line(t, "deep", "y"), 0);
    }
}
