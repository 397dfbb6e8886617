//! `[campaign]`: the committed mesh level, the generated designs (Latin hypercube,
//! Sobol training poses and their replacements), the runs the fit leaves out, the mesh
//! study.

use super::error::{SpecError, SpecResult};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Most generated poses of one kind (`campaign.lhs_count`, `campaign.train_count`): at
/// minutes per FE run, 10,000 runs are months of solving; the bound keeps a typo from
/// allocating billions of poses.
pub const MAX_GENERATED_POSES: u32 = 10_000;

/// `[campaign]`
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CampaignSettings {
    /// Mesh level of the committed reference data.
    pub mesh: String,
    /// Seed of the Latin hypercube of validation poses.
    pub lhs_seed: u64,
    /// Number of Latin hypercube poses.
    pub lhs_count: u32,
    /// Seed of the Owen scrambling of the Sobol sequence of training poses (role
    /// `train`); its own seed, so the training poses never coincide with the validation
    /// hypercube by construction of the seeds.
    #[serde(default)]
    pub train_seed: u32,
    /// Number of training poses, `train-01` .. : the first `train_count` points of the
    /// scrambled Sobol sequence. Raising it keeps the earlier poses (a prefix of the
    /// sequence), so solved training runs stay valid and a learning curve can use nested
    /// prefixes. 0: none.
    #[serde(default)]
    pub train_count: u32,
    /// Sweep and training runs the fitter leaves out, by pose name, each because its FE
    /// run cannot be solved (the reason is written next to the list in campaign.toml). The
    /// run stays in the campaign; the fit needs at least 5 distinct values per sweep
    /// without it, and model.toml names what was left out.
    #[serde(default)]
    pub fit_without: Vec<String>,
    /// Training poses that failed every attempt of the retry ladder, each replaced by the
    /// next point of the Sobol sequence (issue 42, item 3): entry k (0-based) is replaced
    /// by point `train_count + k`, named `train-<train_count + k + 1>`, so the design
    /// keeps `train_count` runs to fit. A replaced pose stays in the campaign (a record:
    /// `needle fe run` still tries it, `needle fe status` shows its failures) but is not
    /// fitted; its replacement's manifest entry names it (`replaces`) and why
    /// (`replaced_because`). A replacement that fails every attempt is listed in turn.
    #[serde(default)]
    pub train_replaced: Vec<TrainReplacement>,
    /// Mesh levels of `needle fe verify --mesh`, the ladder: coarse to fine, each a 2x
    /// refinement of the one before. A committed level (`mesh`) on the ladder is judged
    /// against the level after it; one off the ladder against `mesh_reference`
    /// ([`super::mesh_study`]). Empty: `[mesh, "fine"]`.
    #[serde(default)]
    pub mesh_study: Vec<String>,
    /// The level a committed level off the ladder of `mesh_study` is judged against by the
    /// mesh study: a level of the ladder, not its first, that refines it everywhere
    /// (checked when the spec loads). Absent: the committed level is on the ladder.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh_reference: Option<String>,
    /// Poses besides the centre that the mesh study solves on the committed level and its
    /// refinement (`needle fe verify --mesh`; issue 42: an x, a z and a theta pose).
    #[serde(default)]
    pub mesh_study_poses: Vec<String>,
    /// Needle edge radii, mm, of the edge study (`needle fe verify --edge`; issue 42): the
    /// centre solved on every level of `mesh_study` with `needle.tip_edge_radius_mm` set
    /// to each, into `fe/edge/r<radius>mm/<level>/`, and compared like the mesh study.
    /// Each > 0, below the needle's radius, not the campaign's own edge (the mesh study
    /// has it), listed once.
    #[serde(default)]
    pub edge_study_radii_mm: Vec<f64>,
    /// Poses besides the centre that the edge study solves with each radius on the
    /// committed level and its refinement (as `mesh_study_poses` for the mesh study).
    #[serde(default)]
    pub edge_study_poses: Vec<String>,
}

/// `[[campaign.train_replaced]]`: a training pose replaced by the next point of the
/// design's sequence.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrainReplacement {
    /// The training pose that failed every attempt, e.g. `train-31`.
    pub pose: String,
    /// Why, from its failed attempts' logs (`needle fe status`): class, depth reached.
    pub why: String,
}

impl CampaignSettings {
    /// Check the section's own values; messages start with the spec's `path` (what it
    /// names in the other sections and in the poses: `Campaign`'s checks).
    ///
    /// # Errors
    /// A generated count above [`MAX_GENERATED_POSES`].
    pub fn validate(&self, path: &Path) -> SpecResult<()> {
        for (name, n) in [("campaign.lhs_count", self.lhs_count), ("campaign.train_count", self.train_count)] {
            if n > MAX_GENERATED_POSES {
                return Err(SpecError::range(path.display(), name, format!("{name} = {n}: must be <= {MAX_GENERATED_POSES}")));
            }
        }
        Ok(())
    }
}
