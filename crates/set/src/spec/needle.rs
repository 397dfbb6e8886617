//! `[needle]`: the rigid needle's geometry and the wrench's reference point.

use super::error::{SpecError, SpecResult};
use super::positive;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// `[needle]`
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Needle {
    /// Shaft diameter, mm.
    pub diameter_mm: f64,
    /// Length from tip to hub, mm.
    pub length_mm: f64,
    /// Half angle of the symmetric wedge, degrees.
    pub wedge_half_angle_deg: f64,
    /// Radius of the rounded cutting edge, mm.
    pub tip_edge_radius_mm: f64,
    /// Distance of the wrench reference point from the tip along the axis, mm.
    pub reference_from_tip_mm: f64,
}

impl Needle {
    /// Whether `r_mm` can be this needle's edge radius: finite, > 0 and below its radius.
    pub fn fits_edge_radius(&self, r_mm: f64) -> bool {
        r_mm.is_finite() && r_mm > 0.0 && r_mm < self.diameter_mm / 2.0
    }

    /// Check the section; messages start with the spec's `path`.
    ///
    /// # Errors
    /// A length or angle not finite and > 0; a wedge half angle of 90 degrees or more.
    pub fn validate(&self, path: &Path) -> SpecResult<()> {
        for (name, v) in [
            ("needle.diameter_mm", self.diameter_mm),
            ("needle.length_mm", self.length_mm),
            ("needle.wedge_half_angle_deg", self.wedge_half_angle_deg),
            ("needle.tip_edge_radius_mm", self.tip_edge_radius_mm),
            ("needle.reference_from_tip_mm", self.reference_from_tip_mm),
        ] {
            positive(path, name, v)?;
        }
        if self.wedge_half_angle_deg >= 90.0 {
            return Err(SpecError::range(
                path.display(),
                "needle.wedge_half_angle_deg",
                format!("needle.wedge_half_angle_deg = {}: must be < 90", self.wedge_half_angle_deg),
            ));
        }
        Ok(())
    }
}
