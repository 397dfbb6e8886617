//! `[contact]`: the needle-tissue contact and its friction.

use super::error::{SpecError, SpecResult};
use super::positive;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// `[contact]`
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Contact {
    /// "surface-to-surface".
    #[serde(rename = "type")]
    pub kind: String,
    /// Penalty slope of the linear pressure-overclosure law, N/mm^3.
    pub penalty_slope_n_per_mm3: f64,
    /// Coulomb friction coefficient.
    pub friction: f64,
    /// Stick slope of the friction law, N/mm^3.
    pub stick_slope_n_per_mm3: f64,
}

impl Contact {
    /// Check the section; messages start with the spec's `path`.
    ///
    /// # Errors
    /// A slope not finite and > 0, a negative or non-finite friction, a contact type
    /// other than surface-to-surface.
    pub fn validate(&self, path: &Path) -> SpecResult<()> {
        positive(path, "contact.penalty_slope_n_per_mm3", self.penalty_slope_n_per_mm3)?;
        positive(path, "contact.stick_slope_n_per_mm3", self.stick_slope_n_per_mm3)?;
        let p = path.display();
        if !(self.friction.is_finite() && self.friction >= 0.0) {
            return Err(SpecError::range(&p, "contact.friction", format!("contact.friction = {}: must be finite and >= 0", self.friction)));
        }
        if self.kind != "surface-to-surface" {
            return Err(SpecError::range(
                &p,
                "contact.type",
                format!("contact.type = {:?}: only \"surface-to-surface\" converges (node-to-surface did not)", self.kind),
            ));
        }
        Ok(())
    }
}
