//! `[block]`: the tissue block and its boundary conditions.

use super::error::{SpecError, SpecResult};
use super::positive;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// `[block]`
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Block {
    /// Extent along x, mm (centred on the origin).
    pub size_x_mm: f64,
    /// Extent along z, mm (centred on the origin).
    pub size_z_mm: f64,
    /// Depth below the top surface, mm.
    pub depth_mm: f64,
    /// Boundary condition on the four sides: "pinned".
    pub sides: String,
    /// Boundary condition on the bottom: "encastre".
    pub bottom: String,
}

impl Block {
    /// Check the section; messages start with the spec's `path`.
    ///
    /// # Errors
    /// A size not finite and > 0; boundary conditions other than pinned sides and an
    /// encastre bottom.
    pub fn validate(&self, path: &Path) -> SpecResult<()> {
        for (name, v) in [("block.size_x_mm", self.size_x_mm), ("block.size_z_mm", self.size_z_mm), ("block.depth_mm", self.depth_mm)] {
            positive(path, name, v)?;
        }
        if self.sides != "pinned" || self.bottom != "encastre" {
            return Err(SpecError::range(
                path.display(),
                "block.sides",
                format!("block: sides = {:?}, bottom = {:?}: only \"pinned\" and \"encastre\" are implemented", self.sides, self.bottom),
            ));
        }
        Ok(())
    }
}
