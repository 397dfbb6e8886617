//! Deep runs: `[deep]` of campaign.toml, the pre-puncture response beyond the campaign's
//! `loading.depth_mm` (issue 41, item 5). `needle fe run --deep` solves the listed poses
//! to `deep.depth_mm` in `deep.steps` load steps on `deep.mesh` through the campaign's
//! own machinery (resume, retry ladder, continuation from the last must point, manifest)
//! into `<set>/fe/deep/<pose>.csv` and `<set>/fe/deep/manifest.toml`.
//!
//! A deep run is the campaign's spec with `[loading]` replaced by the deep depth and
//! steps (`DeepSettings::apply`, in `spec`, as its check `validate_deep`), so its run hash differs from the shallow run's and the
//! two never mix. The mesh level's fine layers must reach past the deep depth: the tip
//! would otherwise cut through layers that grow geometrically below `fine_depth_mm`.

use serde::{Deserialize, Serialize};

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

/// The shipped set's `campaign.toml`, the 1-based line of `key` in its `[section]` and
/// that line's text: for tests that edit one line of the shipped spec.
#[cfg(test)]
pub(crate) fn shipped_key(section: &str, key: &str) -> (String, usize, String) {
    let path = needle_stdx::workspace_root().join("coeffs/default/campaign.toml");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let line = key_line(&text, section, key);
    assert!(line > 0, "the shipped campaign.toml has [{section}] {key}");
    let shipped = text.lines().nth(line - 1).unwrap_or_default().to_string();
    (text, line, shipped)
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
