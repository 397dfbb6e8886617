//! The campaign spec, `coeffs/<set>/campaign.toml`: tissue, needle, block, contact,
//! loading, mesh levels and the named poses. Parsing, validation and the spec hash.
//!
//! One module per section, each section's struct checking its own values (`validate`):
//! [`set`], [`tissue`], [`needle`], [`block`], [`contact`], [`loading`], [`mesh`],
//! [`solver`] and [`febio`] (`[solver.febio]`), [`fit`], [`campaign`], [`pose`]
//! (`[[pose]]`), [`deep`] (`[deep]`), [`family`] (`[family]`). Here, the whole spec: reading it and the checks
//! across sections; [`design`] generates the poses `[campaign]` asks for, [`hash`] is the
//! run hash.

pub mod block;
pub mod campaign;
pub mod contact;
pub mod deep;
pub mod design;
pub mod error;
pub mod family;
pub mod febio;
pub mod fit;
pub mod hash;
pub mod lines;
pub mod loading;
pub mod mesh;
pub mod mesh_study;
pub mod needle;
pub mod pose;
pub mod set;
pub mod solver;
pub mod tissue;
pub mod visco;

pub use block::Block;
pub use campaign::{CampaignSettings, TrainReplacement, MAX_GENERATED_POSES};
pub use contact::Contact;
pub use deep::{validate_deep, DeepSettings};
pub use error::{SpecError, SpecResult};
pub use family::{validate_family, FamilySettings};
pub use febio::FebioSettings;
pub use fit::{FitSettings, ModelForm};
pub use hash::hex;
pub use lines::{key_line, shipped_key};
pub use loading::{Loading, MAX_LOAD_STEPS};
pub use mesh::MeshLevel;
pub use needle::Needle;
pub use pose::{select, PoseSpec, Role, Symmetry, THETA_MAX_DEG, X_MAX_MM, Z_MAX_MM};
pub use set::SetInfo;
pub use solver::{Engine, Solver};
pub use tissue::Tissue;

use pose::check_pose_in_block;

use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The whole campaign spec as written in `campaign.toml`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Campaign {
    /// Name and description of the set.
    pub set: SetInfo,
    /// The tissue material.
    pub tissue: Tissue,
    /// The (rigid) needle.
    pub needle: Needle,
    /// The tissue block.
    pub block: Block,
    /// Needle-tissue contact.
    pub contact: Contact,
    /// The insertion.
    pub loading: Loading,
    /// Named mesh levels.
    pub mesh: BTreeMap<String, MeshLevel>,
    /// Campaign-wide settings.
    pub campaign: CampaignSettings,
    /// The FE engine and its settings; absent: CalculiX with the deck's fixed settings.
    #[serde(default)]
    pub solver: Solver,
    /// What `needle fit` fits; absent: the paper's model.
    #[serde(default)]
    pub fit: FitSettings,
    /// The deep runs of `needle fe run --deep` (`needle_fe::deep`); absent: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub deep: Option<DeepSettings>,
    /// The ramp-and-hold runs of `needle fe run --visco` (`needle_fe::visco`); absent: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub viscoelastic: Option<visco::ViscoSettings>,
    /// The material family of `needle fe run --family` (`needle_fe::family`); absent: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub family: Option<FamilySettings>,
    /// The named poses as written (the Latin hypercube poses are added by [`Campaign::poses`]).
    #[serde(rename = "pose", default)]
    pub pose: Vec<PoseSpec>,
}

/// Read and validate a campaign spec.
///
/// # Errors
/// The file cannot be read, is not valid TOML for [`Campaign`] (the message has the file
/// and line), or a value is out of range (the message names the field and the value).
pub fn load(set_dir: &Path) -> SpecResult<(Campaign, PathBuf)> {
    let path = set_dir.join("campaign.toml");
    crate::read_count::count_spec_read();
    let text = match std::fs::read_to_string(&path) {
        Ok(text) => text,
        Err(source) => return Err(SpecError::Read { path, source }),
    };
    let campaign = parse(&text, &path)?;
    Ok((campaign, path))
}

/// Parse and validate a campaign spec from text; `path` is only used in messages.
///
/// # Errors
/// As [`load`].
pub fn parse(text: &str, path: &Path) -> SpecResult<Campaign> {
    let campaign: Campaign = toml::from_str(text).map_err(|e| {
        let line = e.span().map(|s| text[..s.start.min(text.len())].lines().count().max(1)).unwrap_or(0);
        SpecError::Syntax { path: path.to_path_buf(), line, message: e.message().to_string() }
    })?;
    campaign.validate(path).map_err(|e| e.located(text))?;
    validate_deep(&campaign, text, path)?;
    validate_family(&campaign, text, path)?;
    visco::validate(&campaign, text, path).map_err(SpecError::Viscoelastic)?;
    Ok(campaign)
}

impl Campaign {
    /// Every section's own checks, then the checks across sections.
    fn validate(&self, path: &Path) -> SpecResult<()> {
        self.tissue.validate(path)?;
        self.needle.validate(path)?;
        self.block.validate(path)?;
        self.contact.validate(path)?;
        self.loading.validate(path)?;
        self.campaign.validate(path)?;
        for (name, m) in &self.mesh {
            m.validate(path, name)?;
        }
        self.validate_mesh_levels(path)?;
        self.validate_listed_poses(path)?;
        self.validate_design(path)
    }

    /// The levels `[campaign]` names exist; the solver's settings (checked between the
    /// two, in the order of the checks before the sections checked themselves).
    fn validate_mesh_levels(&self, path: &Path) -> SpecResult<()> {
        let p = path.display();
        if !self.mesh.contains_key(&self.campaign.mesh) {
            return Err(SpecError::unknown(
                &p,
                "campaign.mesh",
                &self.campaign.mesh,
                format!(
                    "campaign.mesh = {:?}: no [mesh.{}] level (levels: {})",
                    self.campaign.mesh,
                    self.campaign.mesh,
                    self.mesh.keys().cloned().collect::<Vec<_>>().join(", ")
                ),
            ));
        }
        self.solver.validate(path)?;
        for level in &self.campaign.mesh_study {
            if !self.mesh.contains_key(level) {
                return Err(SpecError::unknown(&p, "campaign.mesh_study", level, format!("campaign.mesh_study: no [mesh.{level}] level")));
            }
        }
        self.validate_mesh_reference(path)?;
        Ok(())
    }

    /// Each listed pose on its own, inside the block, listed once, of a role that is
    /// listed (not generated).
    fn validate_listed_poses(&self, path: &Path) -> SpecResult<()> {
        let p = path.display();
        let mut seen = std::collections::BTreeSet::new();
        for pose in &self.pose {
            pose.validate(&p.to_string())?;
            check_pose_in_block(pose, &self.block, self.needle.diameter_mm / 2.0, self.loading.depth_mm, &p.to_string())?;
            if !seen.insert(pose.name.clone()) {
                return Err(SpecError::duplicate(&p, "pose", &pose.name, format!("pose {:?} is listed twice", pose.name)));
            }
            if pose.role == Role::Lhs {
                return Err(SpecError::inconsistent(
                    &p,
                    "pose.role",
                    format!("pose {:?}: role lhs is generated from campaign.lhs_seed, not listed", pose.name),
                ));
            }
            if pose.role == Role::Train {
                return Err(SpecError::inconsistent(
                    &p,
                    "pose.role",
                    format!("pose {:?}: role train is generated from campaign.train_seed, not listed", pose.name),
                ));
            }
        }
        Ok(())
    }

    /// The mesh level named `name`.
    ///
    /// # Errors
    /// No such level in `[mesh.*]`.
    pub fn mesh_level(&self, name: &str) -> Result<&MeshLevel> {
        self.mesh.get(name).with_context(|| {
            format!("no mesh level {name:?} in the spec (levels: {})", self.mesh.keys().cloned().collect::<Vec<_>>().join(", "))
        })
    }
}

/// `name = v` must be finite and > 0; the message starts with the spec's `path`.
fn positive(path: &Path, name: &str, v: f64) -> SpecResult<()> {
    if !(v.is_finite() && v > 0.0) {
        return Err(SpecError::range(path.display(), name, format!("{name} = {v}: must be finite and > 0")));
    }
    Ok(())
}
