//! `[solver]`: the FE engine of the campaign and its settings.

use super::error::SpecResult;
use super::febio::FebioSettings;
use anyhow::{bail, Result};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The FE engines a campaign can run on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, PartialOrd, Ord)]
#[serde(rename_all = "kebab-case")]
pub enum Engine {
    /// CalculiX `ccx` (Debian `calculix-ccx`): C3D8 tissue, penalty contact.
    #[default]
    Ccx,
    /// FEBio 4: three-field hex8 tissue, rigid-body needle, sliding-elastic contact.
    Febio,
}

impl Engine {
    /// The name used in campaign.toml, on the command line and in the manifest.
    pub fn name(self) -> &'static str {
        match self {
            Engine::Ccx => "ccx",
            Engine::Febio => "febio",
        }
    }

    /// Parse a name as written in campaign.toml or after `--solver`.
    ///
    /// # Errors
    /// Not one of `ccx`, `febio`.
    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "ccx" => Ok(Engine::Ccx),
            "febio" => Ok(Engine::Febio),
            other => bail!("solver {other:?}: must be \"febio\" or \"ccx\""),
        }
    }
}

/// `[solver]`: which engine solves the campaign and that engine's settings. Everything
/// here is part of the spec hash of a FEBio run (a ccx run hashes as before the section
/// existed, so that ccx results stay current).
#[derive(Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Solver {
    /// The engine of the campaign; `needle fe run --solver` overrides it per run.
    #[serde(default)]
    pub engine: Engine,
    /// Settings of the FEBio engine (ignored by ccx).
    #[serde(default)]
    pub febio: FebioSettings,
}

impl Solver {
    /// Check the section; messages start with the spec's `path`.
    ///
    /// # Errors
    /// As [`FebioSettings::validate`].
    pub fn validate(&self, path: &Path) -> SpecResult<()> {
        self.febio.validate(path)
    }
}
