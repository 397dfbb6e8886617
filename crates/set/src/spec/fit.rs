//! `[fit]`: the model form `needle fit` writes.

use serde::{Deserialize, Serialize};

/// `[fit]`: the model form `needle fit` writes (coeffs/README.md, "The model" and "The
/// coupled form"). Not part of any run's hash: changing it refits, it never reruns FE.
#[derive(Debug, Clone, Copy, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FitSettings {
    /// The model form.
    #[serde(default)]
    pub form: ModelForm,
}

/// The model forms of `model.toml` (`form = ...`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ModelForm {
    /// The paper's additive superposition of four single-axis sweeps, fitted on the centre
    /// and sweep runs.
    #[default]
    Paper,
    /// The paper's superposition plus cross terms fitted on the training runs (role
    /// `train`), their size chosen by cross-validation.
    Coupled,
}

impl ModelForm {
    /// The name used in campaign.toml and model.toml.
    pub fn name(self) -> &'static str {
        match self {
            ModelForm::Paper => "paper",
            ModelForm::Coupled => "coupled",
        }
    }
}
