//! [`SetFolder`]: a set folder (`coeffs/<set>/`) opened once. Its campaign spec
//! (`campaign.toml`) and the manifest of its FE runs (`fe/manifest.toml`) are read and
//! checked when it is opened; the CLI opens the folder of each command once and passes the
//! handle to `fit`, `plot` and `explore`, so no module below it reads either file
//! a second time (the fitter's runs are checked against this one copy of the manifest).
//!
//! **Invariant**: [`spec_and_manifest_reads`] counts every read of a campaign spec
//! ([`spec::load`]) and of a manifest ([`read_manifest`]) in this process, so that a test
//! can hold a command to one of each.

pub use crate::read_count::{spec_and_manifest_reads, spec_reads};

use crate::manifest::{read_manifest, Manifest, MANIFEST};
use crate::spec::{self, Campaign, PoseSpec};
use anyhow::Result;
use std::path::{Path, PathBuf};

/// Sub-folder of `<set>/fe/` holding the deep runs and their manifest (`[deep]`).
pub const DEEP_DIR: &str = "deep";

/// Sub-folder of `<set>/fe/` holding the ramp-and-hold runs and their manifest
/// (`[viscoelastic]`).
pub const VISCO_DIR: &str = "visco";

/// Sub-folder of `<set>/fe/` holding the material family's runs and their manifest
/// (`[family]`).
pub const FAMILY_DIR: &str = "family";

/// A set folder with its spec and manifest read once.
#[derive(Debug, Clone)]
pub struct SetFolder {
    dir: PathBuf,
    spec_path: PathBuf,
    campaign: Campaign,
    manifest: Manifest,
}

impl SetFolder {
    /// Opens the set folder `dir`: reads and checks `campaign.toml` and
    /// `fe/manifest.toml` (a missing manifest is an empty one: nothing solved yet).
    ///
    /// # Errors
    /// The spec cannot be read or is refused ([`spec::SpecError`]); the manifest exists
    /// but cannot be read or is not a valid one ([`crate::manifest::ManifestError`]).
    pub fn open(dir: &Path) -> Result<Self> {
        let (campaign, spec_path) = spec::load(dir)?;
        let manifest = read_manifest(&fe_dir(dir).join(MANIFEST))?;
        Ok(Self { dir: dir.to_path_buf(), spec_path, campaign, manifest })
    }

    /// The set's folder, as given to [`open`](Self::open).
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The spec's path, `<set>/campaign.toml`.
    pub fn spec_path(&self) -> &Path {
        &self.spec_path
    }

    /// The campaign spec.
    pub fn campaign(&self) -> &Campaign {
        &self.campaign
    }

    /// The manifest of the set's FE runs, `<set>/fe/manifest.toml`, as read when opened.
    pub fn manifest(&self) -> &Manifest {
        &self.manifest
    }

    /// The folder of the FE runs, `<set>/fe`.
    pub fn fe_dir(&self) -> PathBuf {
        fe_dir(&self.dir)
    }

    /// The result file of `pose`, `<set>/fe/<pose>.csv`.
    pub fn run_path(&self, pose: &PoseSpec) -> PathBuf {
        run_path(&self.dir, pose)
    }

    /// A file of the set by its name, e.g. `model.toml`.
    pub fn file(&self, name: &str) -> PathBuf {
        self.dir.join(name)
    }
}

/// The folder of the FE runs of the set folder `set_dir`, `<set>/fe`.
pub fn fe_dir(set_dir: &Path) -> PathBuf {
    set_dir.join("fe")
}

/// The result file of `pose` in the set folder `set_dir`, `<set>/fe/<pose>.csv`.
pub fn run_path(set_dir: &Path, pose: &PoseSpec) -> PathBuf {
    fe_dir(set_dir).join(format!("{}.csv", pose.name))
}
