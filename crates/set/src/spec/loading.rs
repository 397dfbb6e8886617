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
    /// Number of equal load steps (results at steps + 1 depths, 0 included); of a
    /// ramp-and-hold run, its must points on the ramp and the hold.
    pub steps: u32,
    /// The time course of a viscoelastic ramp-and-hold run (`needle_fe::visco::apply`; never
    /// in the file); absent: quasi-static, time = depth in mm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ramp_hold: Option<super::visco::RampHold>,
}

impl Loading {
    /// Depth after step `k` (0 ..= steps), mm.
    pub fn depth_at(&self, k: u32) -> f64 {
        match &self.ramp_hold {
            Some(r) => r.depth_mm(self.depth_mm, k),
            None => self.depth_mm * f64::from(k) / f64::from(self.steps),
        }
    }

    /// The solver's time at must point `k` (0 ..= steps): the depth in mm of a
    /// quasi-static run, seconds of a ramp-and-hold run.
    pub fn time_at(&self, k: u32) -> f64 {
        match &self.ramp_hold {
            Some(r) => r.time_s(self.depth_mm, k),
            None => self.depth_at(k),
        }
    }

    /// The load step ending at must point `k` (1 ..= steps), in the solver's time.
    pub fn step_time(&self, k: u32) -> f64 {
        self.time_at(k) - self.time_at(k.saturating_sub(1))
    }

    /// The unit of [`Loading::time_at`], for messages.
    pub fn time_unit(&self) -> &'static str {
        if self.ramp_hold.is_some() {
            "s"
        } else {
            "mm"
        }
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
