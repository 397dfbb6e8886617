//! `[tissue]`: the Ogden hyperelastic tissue.

use super::error::{SpecError, SpecResult};
use super::positive;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// `[tissue]`: Ogden hyperelastic tissue, Abaqus/CalculiX convention.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Tissue {
    /// Ogden mu_i, N/mm^2.
    pub mu_n_per_mm2: Vec<f64>,
    /// Ogden alpha_i (dimensionless).
    pub alpha: Vec<f64>,
    /// Initial bulk modulus over initial shear modulus, K0 / mu0.
    pub bulk_to_shear: f64,
    /// Smallest principal stretch the stability check covers.
    pub stretch_min: f64,
    /// Largest principal stretch the stability check covers.
    pub stretch_max: f64,
    /// The Prony series of a viscoelastic run (`needle_fe::visco::apply`; never in the
    /// file); absent: elastic.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub prony: Option<super::visco::Prony>,
}

impl Tissue {
    /// Initial shear modulus mu0 = sum mu_i, N/mm^2.
    pub fn mu0_n_per_mm2(&self) -> f64 {
        self.mu_n_per_mm2.iter().sum()
    }
    /// Every modulus times `s` (the bulk modulus follows: `bulk_to_shear` is kept): the
    /// same material `s` times as stiff.
    pub fn scale_moduli(&mut self, s: f64) {
        self.mu_n_per_mm2.iter_mut().for_each(|mu| *mu *= s);
    }
    /// Initial bulk modulus K0 = bulk_to_shear * mu0, N/mm^2.
    pub fn k0_n_per_mm2(&self) -> f64 {
        self.bulk_to_shear * self.mu0_n_per_mm2()
    }

    /// Check the section; messages start with the spec's `path`.
    ///
    /// # Errors
    /// `mu_n_per_mm2` and `alpha` of different lengths or empty; `bulk_to_shear` not
    /// finite and > 0.
    pub fn validate(&self, path: &Path) -> SpecResult<()> {
        if self.mu_n_per_mm2.is_empty() || self.mu_n_per_mm2.len() != self.alpha.len() {
            return Err(SpecError::inconsistent(
                path.display(),
                "tissue.mu_n_per_mm2",
                format!(
                    "tissue: mu_n_per_mm2 has {} terms and alpha {}; they must match and be non-empty",
                    self.mu_n_per_mm2.len(),
                    self.alpha.len()
                ),
            ));
        }
        positive(path, "tissue.bulk_to_shear", self.bulk_to_shear)
    }
}
