//! `[loading]`: the insertion's depth and load steps.

use super::error::{SpecError, SpecResult};
use super::positive;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Most load steps of a run (`loading.steps`, `deep.steps`): each step is one FE
/// increment of seconds to minutes, so 10,000 is days of solving for one pose, far past
/// any campaign; the bound keeps a typo (`4e9`) from allocating the results of billions
/// of steps.
pub const MAX_LOAD_STEPS: u32 = 10_000;

/// `[loading]`
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Loading {
    /// Final depth along the needle axis, mm.
    pub depth_mm: f64,
    /// Number of equal load steps (results at steps + 1 depths, 0 included).
    pub steps: u32,
}

impl Loading {
    /// Depth after step `k` (0 ..= steps), mm.
    pub fn depth_at(&self, k: u32) -> f64 {
        self.depth_mm * f64::from(k) / f64::from(self.steps)
    }

    /// Check the section; messages start with the spec's `path`.
    ///
    /// # Errors
    /// A depth not finite and > 0; steps not in 1 ..= [`MAX_LOAD_STEPS`].
    pub fn validate(&self, path: &Path) -> SpecResult<()> {
        positive(path, "loading.depth_mm", self.depth_mm)?;
        if self.steps == 0 || self.steps > MAX_LOAD_STEPS {
            return Err(SpecError::range(
                path.display(),
                "loading.steps",
                format!("loading.steps = {}: must be 1 ..= {MAX_LOAD_STEPS}", self.steps),
            ));
        }
        Ok(())
    }
}
