//! The campaign spec, `coeffs/<set>/campaign.toml`: tissue, needle, block, contact,
//! loading, mesh levels and the named poses. Parsing, validation and the spec hash.

use anyhow::{bail, Context, Result};
use rand::{seq::SliceRandom, Rng, SeedableRng};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

mod visco;

/// The domain of the model (docs/architecture.md section 3); poses outside it are refused.
pub const X_MAX_MM: f64 = 12.0;
/// Largest |z| of a pose, mm.
pub const Z_MAX_MM: f64 = 12.0;
/// Largest |theta_x|, |theta_z| of a pose, degrees.
pub const THETA_MAX_DEG: f64 = 15.0;

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
    /// The deep runs of `needle fe run --deep` (`crate::deep`); absent: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub deep: Option<crate::deep::DeepSettings>,
    /// The ramp-and-hold runs of `needle fe run --visco` (`crate::visco`); absent: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub viscoelastic: Option<crate::visco::settings::ViscoSettings>,
    /// The named poses as written (the Latin hypercube poses are added by [`Campaign::poses`]).
    #[serde(rename = "pose", default)]
    pub pose: Vec<PoseSpec>,
}

/// `[set]`
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SetInfo {
    /// Short name.
    pub name: String,
    /// One line on what the set is.
    pub description: String,
}

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
    /// The Prony series of a viscoelastic run (`crate::visco::apply`; never in the
    /// file); absent: elastic.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub prony: Option<crate::visco::settings::Prony>,
}

impl Tissue {
    /// Initial shear modulus mu0 = sum mu_i, N/mm^2.
    pub fn mu0_n_per_mm2(&self) -> f64 {
        self.mu_n_per_mm2.iter().sum()
    }
    /// Initial bulk modulus K0 = bulk_to_shear * mu0, N/mm^2.
    pub fn k0_n_per_mm2(&self) -> f64 {
        self.bulk_to_shear * self.mu0_n_per_mm2()
    }
}

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

/// `[loading]`
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Loading {
    /// Final depth along the needle axis, mm.
    pub depth_mm: f64,
    /// Number of equal load steps (results at steps + 1 depths, 0 included); of a
    /// ramp-and-hold run, its must points on the ramp and the hold.
    pub steps: u32,
    /// The time course of a viscoelastic ramp-and-hold run (`crate::visco::apply`; never
    /// in the file); absent: quasi-static, time = depth in mm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ramp_hold: Option<crate::visco::settings::RampHold>,
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
}

/// `[mesh.<level>]`: the O-grid tissue mesh and the needle facets.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshLevel {
    /// Half side of the fine core square around the needle path, mm.
    pub core_half_mm: f64,
    /// Elements along each side of the core square (even).
    pub core_elements: u32,
    /// Size of the first ring and of the fine layers, mm.
    pub fine_size_mm: f64,
    /// Depth of the fine layers under the surface, mm.
    pub fine_depth_mm: f64,
    /// Geometric growth ratio of rings and layers.
    pub growth: f64,
    /// Needle facets per quarter circumference.
    pub needle_facets_per_quarter: u32,
    /// Needle layer length near the tip, mm.
    pub needle_axial_mm: f64,
}

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

/// The FE engines a campaign can run on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, PartialOrd, Ord)]
#[serde(rename_all = "kebab-case")]
pub enum Engine {
    /// CalculiX `ccx` (Debian `calculix-ccx`): C3D8 tissue, penalty contact.
    #[default]
    Ccx,
    /// FEBio 4 `febio4`: three-field hex8 tissue, rigid-body needle, sliding-elastic contact.
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

/// `[solver.febio]`: the FEBio model's numerical settings (the physics, friction
/// included, is in the other sections). Defaults are the campaign's verified choice;
/// `coeffs/default/campaign.toml` says why.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct FebioSettings {
    /// FEBio contact type: "sliding-elastic" (or "sliding-facet-on-facet",
    /// "sliding-node-on-facet").
    pub contact: String,
    /// Which surface is the contact's primary (FEBio's former "slave"): "tissue" or "needle".
    pub primary: String,
    /// Augmented Lagrangian enforcement (FEBio `laugon` = AUGLAG) instead of a pure penalty.
    pub augmented: bool,
    /// Penalty factor (with `auto_penalty`: a multiplier of FEBio's modulus-based
    /// estimate; without: N/mm^3).
    pub penalty: f64,
    /// Scale `penalty` by FEBio's estimate from the tissue's modulus and element size.
    pub auto_penalty: bool,
    /// Relative tolerance of the Lagrange multipliers' change between augmentations
    /// (`tolerance`), when `augmented`; 0: off (augment only while the largest gap
    /// exceeds `gap_tolerance_mm`).
    pub aug_tolerance: f64,
    /// Gap tolerance of the augmentations (`gaptol`), mm; 0: off.
    pub gap_tolerance_mm: f64,
    /// Most augmentations per time step.
    pub max_aug: u32,
    /// Two-pass contact (each surface is primary once).
    pub two_pass: bool,
    /// Projection search tolerance (`search_tol`, parametric).
    pub search_tol: f64,
    /// Search radius of the projection, mm (`search_radius`).
    pub search_radius_mm: f64,
    /// Newton iterations of each augmentation in which the contact projections are
    /// updated (`seg_up`); later iterations keep the facets found so far. 0: every
    /// iteration (FEBio's default). A node sliding over a facet edge can otherwise flip
    /// between two facets from one iteration to the next and stall Newton's method.
    pub seg_up: u32,
    /// `seg_up` of the attempts that try the other projection rule (FEBio attempts 2 and
    /// 4; on the full block 1 and 3, see `FebioBackend::attempts`); 0: every iteration. Left out of the run hash
    /// when 0, so adding it kept the results solved before it existed.
    #[serde(default, skip_serializing_if = "is_zero_u32")]
    pub retry_seg_up: u32,
    /// Quasi-Newton updates between stiffness reformations (0: full Newton).
    pub max_ups: u32,
    /// Most stiffness reformations per time step.
    pub max_refs: u32,
    /// Optimal Newton iterations of the automatic time stepper.
    pub opt_iter: u32,
    /// Retries with a smaller time step before FEBio gives up.
    pub max_retries: u32,
    /// Smallest automatic time step, as a fraction of one load step.
    pub dtmin_fraction: f64,
    /// Displacement convergence tolerance (`dtol`; 0: off).
    pub dtol: f64,
    /// Energy convergence tolerance (`etol`).
    pub etol: f64,
    /// Residual convergence tolerance (`rtol`; 0: off).
    pub rtol: f64,
    /// Line search tolerance (`lstol`; 0: off).
    pub lstol: f64,
    /// `dtol` of the campaign's retry of a failed run (0: off). Seen on the committed
    /// mesh: a contact point chattering by a few micrometres keeps the displacement norm
    /// from converging (x+06, "max nr of reformations") while energy and residual have;
    /// the retry then judges convergence by energy and residual.
    pub retry_dtol: f64,
    /// `rtol` of the retry.
    pub retry_rtol: f64,
    /// `penalty` times this on the last attempt (the fourth retry), in (0, 1]: a softer
    /// contact for poses whose Newton iterations chatter on the stiff one (seen on the
    /// committed mesh at theta_x = 15 degrees and Table 2's t2-b: "max nr of
    /// reformations" in both earlier attempts). The augmentations still hold the gap
    /// below `gap_tolerance_mm`; the manifest's `solver_settings` names the penalty used.
    pub last_attempt_penalty_scale: f64,
    /// Depth (mm) over which a fresh attempt with whole load steps keeps its time steps at
    /// most `first_contact_step_fraction` of a load step, its first step included (0: off).
    /// Issue 42: `seg_up` 5 with whole first increments inverted elements at first
    /// contact in 17 of its 25 failures, all at 0.19-0.60 mm. A setting of the ladder
    /// (the path to the must points, not the problem): left out of the run hash, recorded
    /// in the manifest's `solver_settings` of each run it shaped.
    #[serde(skip_serializing)]
    pub first_contact_depth_mm: f64,
    /// The largest time step within `first_contact_depth_mm`, as a fraction of one load
    /// step, in (0, 1]. Left out of the run hash like `first_contact_depth_mm`.
    #[serde(skip_serializing)]
    pub first_contact_step_fraction: f64,
}

impl Default for FebioSettings {
    fn default() -> Self {
        FebioSettings {
            contact: "sliding-elastic".into(),
            primary: "tissue".into(),
            augmented: true,
            penalty: 1000.0,
            auto_penalty: true,
            aug_tolerance: 0.1,
            gap_tolerance_mm: 0.005,
            max_aug: 30,
            two_pass: false,
            search_tol: 0.01,
            search_radius_mm: 1.0,
            seg_up: 0,
            retry_seg_up: 0,
            max_ups: 0,
            max_refs: 15,
            opt_iter: 10,
            max_retries: 8,
            dtmin_fraction: 1e-3,
            dtol: 1e-3,
            etol: 1e-2,
            rtol: 0.0,
            lstol: 0.9,
            retry_dtol: 0.0,
            retry_rtol: 1e-3,
            last_attempt_penalty_scale: 0.1,
            first_contact_depth_mm: 0.6,
            first_contact_step_fraction: 0.25,
        }
    }
}

impl FebioSettings {
    fn validate(&self, path: &Path) -> Result<()> {
        let p = path.display();
        const CONTACTS: [&str; 3] = ["sliding-elastic", "sliding-facet-on-facet", "sliding-node-on-facet"];
        if !CONTACTS.contains(&self.contact.as_str()) {
            bail!("{p}: solver.febio.contact = {:?}: must be one of {}", self.contact, CONTACTS.join(", "));
        }
        if !matches!(self.primary.as_str(), "tissue" | "needle") {
            bail!("{p}: solver.febio.primary = {:?}: must be \"tissue\" or \"needle\"", self.primary);
        }
        for (name, v) in [
            ("penalty", self.penalty),
            ("search_tol", self.search_tol),
            ("search_radius_mm", self.search_radius_mm),
            ("dtmin_fraction", self.dtmin_fraction),
            ("etol", self.etol),
        ] {
            if !(v.is_finite() && v > 0.0) {
                bail!("{p}: solver.febio.{name} = {v}: must be finite and > 0");
            }
        }
        for (name, v) in [
            ("aug_tolerance", self.aug_tolerance),
            ("gap_tolerance_mm", self.gap_tolerance_mm),
            ("dtol", self.dtol),
            ("rtol", self.rtol),
            ("lstol", self.lstol),
            ("retry_dtol", self.retry_dtol),
            ("retry_rtol", self.retry_rtol),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                bail!("{p}: solver.febio.{name} = {v}: must be finite and >= 0");
            }
        }
        if self.augmented && self.aug_tolerance == 0.0 && self.gap_tolerance_mm == 0.0 {
            bail!("{p}: solver.febio: augmented = true needs aug_tolerance > 0 or gap_tolerance_mm > 0 (with both 0 FEBio skips every augmentation: set augmented = false for a pure penalty)");
        }
        if !(self.last_attempt_penalty_scale > 0.0 && self.last_attempt_penalty_scale <= 1.0) {
            bail!("{p}: solver.febio.last_attempt_penalty_scale = {}: must be in (0, 1]", self.last_attempt_penalty_scale);
        }
        if !(self.first_contact_depth_mm.is_finite() && self.first_contact_depth_mm >= 0.0) {
            bail!("{p}: solver.febio.first_contact_depth_mm = {}: must be finite and >= 0 (0: off)", self.first_contact_depth_mm);
        }
        if !(self.first_contact_step_fraction > 0.0 && self.first_contact_step_fraction <= 1.0) {
            bail!(
                "{p}: solver.febio.first_contact_step_fraction = {}: must be in (0, 1] (a fraction of one load step)",
                self.first_contact_step_fraction
            );
        }
        if self.dtmin_fraction > 1.0 {
            bail!("{p}: solver.febio.dtmin_fraction = {}: must be <= 1 (a fraction of one load step)", self.dtmin_fraction);
        }
        if self.max_refs == 0 || self.opt_iter == 0 {
            bail!("{p}: solver.febio.max_refs and opt_iter must be >= 1");
        }
        Ok(())
    }
}

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
    /// Mesh levels of `needle fe verify --mesh`, coarse to fine, each a 2x refinement of
    /// the one before; the committed level (`mesh`) must be followed by its refinement.
    /// Empty: `[mesh, "fine"]`.
    #[serde(default)]
    pub mesh_study: Vec<String>,
    /// Poses besides the centre that the mesh study solves on the committed level and its
    /// refinement (`needle fe verify --mesh`; issue 42: an x, a z and a theta pose).
    #[serde(default)]
    pub mesh_study_poses: Vec<String>,
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

/// What a pose is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, PartialOrd, Ord)]
#[serde(rename_all = "kebab-case")]
pub enum Role {
    /// The centred vertical needle: the baseline of every sweep.
    Centre,
    /// Sweep along x (others zero), fitted.
    SweepX,
    /// Sweep along z, fitted.
    SweepZ,
    /// Sweep in theta_x, fitted.
    SweepThetaX,
    /// Sweep in theta_z, fitted.
    SweepThetaZ,
    /// Mirror-side run that checks a symmetry, not fitted.
    Mirror,
    /// The paper's Table 2 validation points, never fitted.
    Table2,
    /// Latin hypercube validation poses, never fitted.
    Lhs,
    /// Combined poses of the Sobol training design (generated from
    /// `campaign.train_seed`), fitted by the coupled model form only: the paper's form
    /// stays a fit of the sweeps.
    Train,
}

impl Role {
    /// Whether the fitter may use runs of this role.
    pub fn is_fitted(self) -> bool {
        matches!(self, Role::Centre | Role::SweepX | Role::SweepZ | Role::SweepThetaX | Role::SweepThetaZ)
    }
    /// Whether `campaign.fit_without` may name a run of this role: a sweep or a training
    /// run whose FE run cannot be solved. The centre run is always fitted; validation runs
    /// are never fitted.
    pub fn may_be_left_out(self) -> bool {
        matches!(self, Role::SweepX | Role::SweepZ | Role::SweepThetaX | Role::SweepThetaZ | Role::Train)
    }
    /// Whether the run is a validation run (never fitted).
    pub fn is_validation(self) -> bool {
        matches!(self, Role::Table2 | Role::Lhs)
    }
}

/// One named pose: needle tip on the top surface at (x, 0, z), tilted by theta_x about x
/// and theta_z about z, then fed `loading.depth_mm` along its own axis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoseSpec {
    /// File stem of the result, `fe/<name>.csv`.
    pub name: String,
    /// What the run is for.
    pub role: Role,
    /// Tip x on the top surface, mm.
    #[serde(default)]
    pub x_mm: f64,
    /// Tip z on the top surface, mm.
    #[serde(default)]
    pub z_mm: f64,
    /// Tilt about the x axis, degrees.
    #[serde(default)]
    pub theta_x_deg: f64,
    /// Tilt about the z axis, degrees.
    #[serde(default)]
    pub theta_z_deg: f64,
}

/// Mirror planes of the block and the needle that a pose keeps: a run can be solved on
/// the half (or quarter) of the block on the positive side of each plane.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Symmetry {
    /// The pose is symmetric under x -> -x (plane x = 0).
    pub plane_x: bool,
    /// The pose is symmetric under z -> -z (plane z = 0).
    pub plane_z: bool,
}

impl PoseSpec {
    /// The mirror planes this pose keeps. The block is symmetric about x = 0 and z = 0 and
    /// the double-bevel wedge about both of its own mid-planes, so a pose keeps plane
    /// x = 0 when x = 0 and theta_z = 0, and plane z = 0 when z = 0 and theta_x = 0.
    pub fn symmetry(&self) -> Symmetry {
        Symmetry { plane_x: self.x_mm == 0.0 && self.theta_z_deg == 0.0, plane_z: self.z_mm == 0.0 && self.theta_x_deg == 0.0 }
    }

    /// Unit vector along the needle axis from the tip towards the hub (at theta = 0: +y).
    /// The needle is rotated first by theta_x about x, then by theta_z about z.
    pub fn axis(&self) -> [f64; 3] {
        let (sx, cx) = self.theta_x_deg.to_radians().sin_cos();
        let (sz, cz) = self.theta_z_deg.to_radians().sin_cos();
        // R = Rz * Rx applied to (0, 1, 0): Rx(0,1,0) = (0, cx, sx); Rz(a,b,c) = (cz a - sz b, sz a + cz b, c)
        [-sz * cx, cz * cx, sx]
    }

    /// Lateral travel (x, z) of the tip over an insertion of `depth_mm` along the axis, mm.
    pub fn lateral_travel(&self, depth_mm: f64) -> (f64, f64) {
        let a = self.axis();
        (-a[0] * depth_mm, -a[2] * depth_mm)
    }
}

/// Most load steps of a run (`loading.steps`, `deep.steps`): each step is one FE
/// increment of seconds to minutes, so 10,000 is days of solving for one pose, far past
/// any campaign; the bound keeps a typo (`4e9`) from allocating the results of billions
/// of steps.
pub const MAX_LOAD_STEPS: u32 = 10_000;

/// Most generated poses of one kind (`campaign.lhs_count`, `campaign.train_count`): at
/// minutes per FE run, 10,000 runs are months of solving; the bound keeps a typo from
/// allocating billions of poses.
pub const MAX_GENERATED_POSES: u32 = 10_000;

/// Read and validate a campaign spec.
///
/// # Errors
/// The file cannot be read, is not valid TOML for [`Campaign`] (the message has the file
/// and line), or a value is out of range (the message names the field and the value).
pub fn load(set_dir: &Path) -> Result<(Campaign, PathBuf)> {
    let path = set_dir.join("campaign.toml");
    let text = std::fs::read_to_string(&path).with_context(|| format!("{}: cannot read the campaign spec", path.display()))?;
    let campaign = parse(&text, &path)?;
    Ok((campaign, path))
}

/// Parse and validate a campaign spec from text; `path` is only used in messages.
///
/// # Errors
/// As [`load`].
pub fn parse(text: &str, path: &Path) -> Result<Campaign> {
    let campaign: Campaign = toml::from_str(text).map_err(|e| {
        let line = e.span().map(|s| text[..s.start.min(text.len())].lines().count().max(1)).unwrap_or(0);
        anyhow::anyhow!("{}:{}: {}", path.display(), line, e.message())
    })?;
    campaign.validate(path)?;
    validate_deep(&campaign, text, path)?;
    visco::validate(&campaign, text, path)?;
    Ok(campaign)
}

impl Campaign {
    fn validate(&self, path: &Path) -> Result<()> {
        let p = path.display();
        let t = &self.tissue;
        if t.mu_n_per_mm2.is_empty() || t.mu_n_per_mm2.len() != t.alpha.len() {
            bail!(
                "{p}: tissue: mu_n_per_mm2 has {} terms and alpha {}; they must match and be non-empty",
                t.mu_n_per_mm2.len(),
                t.alpha.len()
            );
        }
        for (name, v) in [
            ("tissue.bulk_to_shear", t.bulk_to_shear),
            ("needle.diameter_mm", self.needle.diameter_mm),
            ("needle.length_mm", self.needle.length_mm),
            ("needle.wedge_half_angle_deg", self.needle.wedge_half_angle_deg),
            ("needle.tip_edge_radius_mm", self.needle.tip_edge_radius_mm),
            ("needle.reference_from_tip_mm", self.needle.reference_from_tip_mm),
            ("block.size_x_mm", self.block.size_x_mm),
            ("block.size_z_mm", self.block.size_z_mm),
            ("block.depth_mm", self.block.depth_mm),
            ("contact.penalty_slope_n_per_mm3", self.contact.penalty_slope_n_per_mm3),
            ("contact.stick_slope_n_per_mm3", self.contact.stick_slope_n_per_mm3),
            ("loading.depth_mm", self.loading.depth_mm),
        ] {
            if !(v.is_finite() && v > 0.0) {
                bail!("{p}: {name} = {v}: must be finite and > 0");
            }
        }
        if self.needle.wedge_half_angle_deg >= 90.0 {
            bail!("{p}: needle.wedge_half_angle_deg = {}: must be < 90", self.needle.wedge_half_angle_deg);
        }
        if !(self.contact.friction.is_finite() && self.contact.friction >= 0.0) {
            bail!("{p}: contact.friction = {}: must be finite and >= 0", self.contact.friction);
        }
        if self.loading.steps == 0 || self.loading.steps > MAX_LOAD_STEPS {
            bail!("{p}: loading.steps = {}: must be 1 ..= {MAX_LOAD_STEPS}", self.loading.steps);
        }
        for (name, n) in [("campaign.lhs_count", self.campaign.lhs_count), ("campaign.train_count", self.campaign.train_count)] {
            if n > MAX_GENERATED_POSES {
                bail!("{p}: {name} = {n}: must be <= {MAX_GENERATED_POSES}");
            }
        }
        if self.block.sides != "pinned" || self.block.bottom != "encastre" {
            bail!(
                "{p}: block: sides = {:?}, bottom = {:?}: only \"pinned\" and \"encastre\" are implemented",
                self.block.sides,
                self.block.bottom
            );
        }
        if self.contact.kind != "surface-to-surface" {
            bail!("{p}: contact.type = {:?}: only \"surface-to-surface\" converges (node-to-surface did not)", self.contact.kind);
        }
        for (name, m) in &self.mesh {
            if m.core_elements < 2 || m.core_elements % 2 != 0 {
                bail!("{p}: mesh.{name}.core_elements = {}: must be even and >= 2", m.core_elements);
            }
            if m.needle_facets_per_quarter < 2 {
                bail!("{p}: mesh.{name}.needle_facets_per_quarter = {}: must be >= 2", m.needle_facets_per_quarter);
            }
            for (f, v) in [
                ("core_half_mm", m.core_half_mm),
                ("fine_size_mm", m.fine_size_mm),
                ("fine_depth_mm", m.fine_depth_mm),
                ("needle_axial_mm", m.needle_axial_mm),
            ] {
                if !(v.is_finite() && v > 0.0) {
                    bail!("{p}: mesh.{name}.{f} = {v}: must be finite and > 0");
                }
            }
            if !(m.growth.is_finite() && m.growth >= 1.0) {
                bail!("{p}: mesh.{name}.growth = {}: must be >= 1", m.growth);
            }
        }
        if !self.mesh.contains_key(&self.campaign.mesh) {
            bail!(
                "{p}: campaign.mesh = {:?}: no [mesh.{}] level (levels: {})",
                self.campaign.mesh,
                self.campaign.mesh,
                self.mesh.keys().cloned().collect::<Vec<_>>().join(", ")
            );
        }
        self.solver.febio.validate(path)?;
        for level in &self.campaign.mesh_study {
            if !self.mesh.contains_key(level) {
                bail!("{p}: campaign.mesh_study: no [mesh.{level}] level");
            }
        }
        let mut seen = std::collections::BTreeSet::new();
        for pose in &self.pose {
            check_pose(pose, &p.to_string())?;
            check_pose_role(pose, &p.to_string())?;
            check_pose_in_block(pose, &self.block, self.needle.diameter_mm / 2.0, self.loading.depth_mm, &p.to_string())?;
            if !seen.insert(pose.name.clone()) {
                bail!("{p}: pose {:?} is listed twice", pose.name);
            }
            if pose.role == Role::Lhs {
                bail!("{p}: pose {:?}: role lhs is generated from campaign.lhs_seed, not listed", pose.name);
            }
            if pose.role == Role::Train {
                bail!("{p}: pose {:?}: role train is generated from campaign.train_seed, not listed", pose.name);
            }
        }
        let every_pose = self.poses();
        for name in &self.campaign.mesh_study_poses {
            if !every_pose.iter().any(|q| &q.name == name) {
                bail!("{p}: campaign.mesh_study_poses: {name:?} is not a pose of this campaign");
            }
        }
        let mut replaced = std::collections::BTreeSet::new();
        for (k, r) in self.campaign.train_replaced.iter().enumerate() {
            let replacement = self.train_name(self.campaign.train_count as usize + k);
            // the pose must be a training pose drawn before its replacement
            let drawn_before = (0..self.campaign.train_count as usize + k).any(|i| self.train_name(i) == r.pose);
            if !drawn_before {
                bail!(
                    "{p}: campaign.train_replaced[{k}]: {:?} is not a training pose drawn before its replacement {replacement:?}",
                    r.pose
                );
            }
            if !replaced.insert(r.pose.clone()) {
                bail!("{p}: campaign.train_replaced: {:?} is listed twice", r.pose);
            }
            if r.why.trim().is_empty() {
                bail!("{p}: campaign.train_replaced[{k}] ({}): `why` is empty (the failure from its logs)", r.pose);
            }
            if self.campaign.fit_without.contains(&r.pose) {
                bail!("{p}: campaign.fit_without: {:?} is in campaign.train_replaced, so it is not fitted already; list it once", r.pose);
            }
        }
        for name in &self.campaign.fit_without {
            match every_pose.iter().find(|q| &q.name == name) {
                None => bail!("{p}: campaign.fit_without: {name:?} is not a pose of this campaign"),
                Some(q) if !q.role.may_be_left_out() => {
                    bail!(
                        "{p}: campaign.fit_without: pose {name:?} has role {:?}; only sweep and training runs can be left out of the fit",
                        q.role
                    )
                }
                Some(_) => {}
            }
        }
        Ok(())
    }

    /// Every pose of the campaign: the listed ones, then `lhs_count` Latin hypercube
    /// poses named `lhs-01`, `lhs-02`, ... drawn with ChaCha8 from `lhs_seed`: each of the
    /// four inputs is split into `lhs_count` equal strata over the whole domain, one point
    /// uniform in each stratum, strata shuffled independently per input. Coordinates are
    /// rounded to 0.01 mm / 0.01 degree so that the deck is reproducible from the name.
    pub fn poses(&self) -> Vec<PoseSpec> {
        let mut out = self.pose.clone();
        let n = self.campaign.lhs_count as usize;
        if n == 0 {
            out.extend(self.train_poses());
            return out;
        }
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(self.campaign.lhs_seed);
        let ranges = [X_MAX_MM, Z_MAX_MM, THETA_MAX_DEG, THETA_MAX_DEG];
        let mut cols: Vec<Vec<f64>> = Vec::new();
        for half in ranges {
            let mut col: Vec<f64> = (0..n)
                .map(|i| {
                    let u = (i as f64 + rng.gen::<f64>()) / n as f64;
                    let v = -half + 2.0 * half * u;
                    (v * 100.0).round() / 100.0
                })
                .collect();
            col.shuffle(&mut rng);
            cols.push(col);
        }
        for i in 0..n {
            out.push(PoseSpec {
                name: format!("lhs-{:02}", i + 1),
                role: Role::Lhs,
                x_mm: cols[0][i],
                z_mm: cols[1][i],
                theta_x_deg: cols[2][i],
                theta_z_deg: cols[3][i],
            });
        }
        out.extend(self.train_poses());
        out
    }

    /// The `train_count` training poses `train-01`, `train-02`, ...: point i of the
    /// Owen-scrambled Sobol sequence in four dimensions (seed `train_seed`) mapped onto
    /// the whole domain, |x|, |z| <= 12 mm and |theta| <= 15 degrees, rounded like the
    /// hypercube. Every prefix of 2^k points is stratified in each input and in each pair
    /// of inputs, which is what the learning curve's nested subsets rely on.
    /// Then one more point per entry of `campaign.train_replaced`: the replacements
    /// ([`Campaign::replacement_of`]).
    pub fn train_poses(&self) -> Vec<PoseSpec> {
        let ranges = [X_MAX_MM, Z_MAX_MM, THETA_MAX_DEG, THETA_MAX_DEG];
        let drawn = self.campaign.train_count.saturating_add(u32::try_from(self.campaign.train_replaced.len()).unwrap_or(u32::MAX));
        (0..drawn)
            .map(|i| {
                let v: Vec<f64> = ranges
                    .iter()
                    .zip(0u32..)
                    .map(|(half, dim)| {
                        let u = f64::from(sobol_burley::sample(i, dim, self.campaign.train_seed));
                        (((-half + 2.0 * half * u) * 100.0).round() / 100.0).clamp(-half, *half)
                    })
                    .collect();
                PoseSpec {
                    name: self.train_name(i as usize),
                    role: Role::Train,
                    x_mm: v[0],
                    z_mm: v[1],
                    theta_x_deg: v[2],
                    theta_z_deg: v[3],
                }
            })
            .collect()
    }

    /// Name of point `i` (0-based) of the training sequence: `train-01`, ...
    pub fn train_name(&self, i: usize) -> String {
        format!("train-{:02}", i + 1)
    }

    /// The replacement of training pose `name` listed in `campaign.train_replaced`
    /// (`None`: not replaced).
    pub fn replacement_of(&self, name: &str) -> Option<String> {
        let k = self.campaign.train_replaced.iter().position(|r| r.pose == name)?;
        Some(self.train_name(self.campaign.train_count as usize + k))
    }

    /// The entry of `campaign.train_replaced` that pose `name` replaces (`None`: `name`
    /// is not a replacement).
    pub fn replaced_by(&self, name: &str) -> Option<&TrainReplacement> {
        let n = self.campaign.train_count as usize;
        self.campaign.train_replaced.iter().enumerate().find(|(k, _)| self.train_name(n + k) == name).map(|(_, r)| r)
    }

    /// Whether training pose `name` is replaced (not fitted: its replacement takes its slot).
    pub fn is_replaced(&self, name: &str) -> bool {
        self.campaign.train_replaced.iter().any(|r| r.pose == name)
    }

    /// The training design's `train_count` slots after the replacements: each pose of
    /// the first `train_count` as drawn, or the last replacement in its chain.
    pub fn train_design(&self) -> Vec<String> {
        (0..self.campaign.train_count as usize)
            .map(|i| {
                let mut name = self.train_name(i);
                while let Some(r) = self.replacement_of(&name) {
                    name = r;
                }
                name
            })
            .collect()
    }

    /// The levels of the mesh study (`campaign.mesh_study`, or the committed level and
    /// `fine` when it is empty).
    pub fn mesh_study(&self) -> Vec<String> {
        if self.campaign.mesh_study.is_empty() {
            vec![self.campaign.mesh.clone(), "fine".to_string()]
        } else {
            self.campaign.mesh_study.clone()
        }
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

    /// Hash of everything that determines the result of one run: the whole spec except
    /// the pose list and description, plus this pose and the mesh level. Hex SHA-256.
    pub fn run_hash(&self, pose: &PoseSpec, mesh_name: &str) -> String {
        #[derive(Serialize)]
        struct Key<'a> {
            tissue: &'a Tissue,
            needle: &'a Needle,
            block: &'a Block,
            contact: &'a Contact,
            loading: &'a Loading,
            mesh_name: &'a str,
            mesh: Option<&'a MeshLevel>,
            pose: &'a PoseSpec,
            generator: u32,
            #[serde(skip_serializing_if = "Option::is_none")]
            solver: Option<&'a Solver>,
        }
        let key = Key {
            tissue: &self.tissue,
            needle: &self.needle,
            block: &self.block,
            contact: &self.contact,
            loading: &self.loading,
            mesh_name,
            mesh: self.mesh.get(mesh_name),
            pose,
            generator: match self.solver.engine {
                Engine::Ccx => crate::versions::CCX_DECK,
                Engine::Febio => crate::versions::FEBIO_INPUT,
            },
            solver: (self.solver.engine != Engine::Ccx).then_some(&self.solver),
        };
        // plain data with string keys: serialising cannot fail; if it ever did, an empty
        // key would give every run the same hash, so fail loudly instead
        let json = serde_json::to_string(&key).unwrap_or_else(|e| panic!("the spec hash key does not serialise: {e}"));
        hex(&Sha256::digest(json.as_bytes()))
    }
}

fn is_zero_u32(v: &u32) -> bool {
    *v == 0
}

/// A sweep pose varies its own axis only (the centre none): the fitter reads a sweep
/// run as the deviation along that axis alone.
fn check_pose_role(pose: &PoseSpec, p: &str) -> Result<()> {
    let own = match pose.role {
        Role::Centre => None,
        Role::SweepX => Some("x_mm"),
        Role::SweepZ => Some("z_mm"),
        Role::SweepThetaX => Some("theta_x_deg"),
        Role::SweepThetaZ => Some("theta_z_deg"),
        _ => return Ok(()),
    };
    for (f, v) in [("x_mm", pose.x_mm), ("z_mm", pose.z_mm), ("theta_x_deg", pose.theta_x_deg), ("theta_z_deg", pose.theta_z_deg)] {
        if Some(f) != own && v != 0.0 {
            let what = own.map_or("the centre pose has all four at 0".to_string(), |o| format!("a {:?} pose varies {o} only", pose.role));
            bail!("{p}: pose {:?}: {f} = {v}: must be 0 ({what})", pose.name);
        }
    }
    Ok(())
}

/// The needle stays inside the block: at entry and at full depth (after the lateral
/// travel of the tilt), the needle's axis is at least its radius from each side face.
pub(crate) fn check_pose_in_block(pose: &PoseSpec, block: &Block, radius_mm: f64, depth_mm: f64, p: &str) -> Result<()> {
    let (tx, tz) = pose.lateral_travel(depth_mm);
    for (f, entry, travel, half) in [("x_mm", pose.x_mm, tx, block.size_x_mm / 2.0), ("z_mm", pose.z_mm, tz, block.size_z_mm / 2.0)] {
        let reach = entry.abs().max((entry + travel).abs()) + radius_mm;
        if reach > half {
            bail!(
                "{p}: pose {:?}: {f} = {entry} with a lateral travel of {travel:.3} mm at full depth ({depth_mm} mm): the needle (radius {radius_mm} mm) reaches {reach:.3} mm from the centre, beyond the block's side at {half} mm",
                pose.name
            );
        }
    }
    Ok(())
}

fn check_pose(pose: &PoseSpec, p: &str) -> Result<()> {
    if pose.name.is_empty() || !pose.name.chars().all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '+' | '_')) {
        bail!("{p}: pose name {:?}: use letters, digits, '-', '+', '_' only", pose.name);
    }
    for (f, v, max, unit) in [
        ("x_mm", pose.x_mm, X_MAX_MM, "mm"),
        ("z_mm", pose.z_mm, Z_MAX_MM, "mm"),
        ("theta_x_deg", pose.theta_x_deg, THETA_MAX_DEG, "deg"),
        ("theta_z_deg", pose.theta_z_deg, THETA_MAX_DEG, "deg"),
    ] {
        if !(v.is_finite() && v.abs() <= max) {
            bail!("{p}: pose {:?}: {f} = {v}: outside the domain |{f}| <= {max} {unit}", pose.name);
        }
    }
    Ok(())
}

/// Lower-case hex of a byte string.
pub fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// Select poses whose name matches a glob `pattern` (`*`, `?`, `[..]`), or any of several
/// globs separated by commas (`lhs-09,lhs-1*`). Poses keep the spec's order.
///
/// # Errors
/// A pattern is empty or not a valid glob.
pub fn select<'a>(poses: &'a [PoseSpec], pattern: Option<&str>) -> Result<Vec<&'a PoseSpec>> {
    let Some(list) = pattern else { return Ok(poses.iter().collect()) };
    let globs = list
        .split(',')
        .map(|pat| {
            if pat.trim().is_empty() {
                bail!("--only {list:?}: empty pattern between commas");
            }
            glob::Pattern::new(pat.trim()).with_context(|| format!("--only {list:?}: {pat:?} is not a valid glob"))
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(poses.iter().filter(|p| globs.iter().any(|g| g.matches(&p.name))).collect())
}

#[cfg(test)]
mod tests {
    use super::{select, FebioSettings, PoseSpec, Role};
    use std::path::Path;

    #[test]
    fn febio_augmentation_needs_one_tolerance() {
        let p = Path::new("campaign.toml");
        let gap_only = FebioSettings { aug_tolerance: 0.0, ..FebioSettings::default() };
        assert!(gap_only.validate(p).is_ok(), "gap tolerance alone stops the augmentations");
        let neither = FebioSettings { aug_tolerance: 0.0, gap_tolerance_mm: 0.0, ..FebioSettings::default() };
        let msg = neither.validate(p).err().map(|e| e.to_string()).unwrap_or_default();
        assert!(msg.contains("aug_tolerance > 0 or gap_tolerance_mm > 0"), "{msg}");
        let penalty = FebioSettings { augmented: false, ..neither };
        assert!(penalty.validate(p).is_ok(), "a pure penalty needs no tolerance");
        let negative = FebioSettings { aug_tolerance: -0.1, ..FebioSettings::default() };
        assert!(negative.validate(p).is_err());
    }

    /// The ladder's first-contact steps are checked, and left out of the run hash (they
    /// change the path to the must points, not the problem: results solved before them
    /// stay up to date), unlike a tolerance.
    #[test]
    fn first_contact_steps_are_checked_and_not_hashed() {
        let p = Path::new("campaign.toml");
        for (depth, fraction, ok) in
            [(0.6, 0.25, true), (0.0, 1.0, true), (-0.1, 0.25, false), (0.6, 0.0, false), (0.6, 1.5, false), (f64::NAN, 0.25, false)]
        {
            let s = FebioSettings { first_contact_depth_mm: depth, first_contact_step_fraction: fraction, ..FebioSettings::default() };
            assert_eq!(s.validate(p).is_ok(), ok, "depth {depth} mm, fraction {fraction}");
        }
        let set = crate::workspace_root().join("coeffs/default");
        let Ok((c, _)) = super::load(&set) else { panic!("cannot load {}", set.display()) };
        let centre = c.poses().into_iter().find(|p| p.name == "centre").expect("centre");
        let h = c.run_hash(&centre, "needle8");
        let mut other = c.clone();
        other.solver.febio.first_contact_depth_mm = 1.2;
        other.solver.febio.first_contact_step_fraction = 0.5;
        assert_eq!(other.run_hash(&centre, "needle8"), h);
        other.solver.febio.retry_rtol *= 2.0;
        assert_ne!(other.run_hash(&centre, "needle8"), h, "a tolerance is part of the problem's hash");
    }

    /// The training design: a prefix of the scrambled Sobol sequence, inside the
    /// domain, one point per stratum of each input for 8 and 16 points, another seed
    /// another design.
    #[test]
    fn training_poses_are_nested_stratified_sobol_prefixes() {
        let set = crate::workspace_root().join("coeffs/default");
        let Ok((mut c, _)) = super::load(&set) else { panic!("cannot load {}", set.display()) };
        c.campaign.train_replaced.clear();
        c.campaign.train_seed = 7;
        c.campaign.train_count = 16;
        let sixteen = c.train_poses();
        c.campaign.train_count = 8;
        let eight = c.train_poses();
        assert_eq!(sixteen.len(), 16);
        assert_eq!(eight[..], sixteen[..8], "raising train_count keeps the earlier poses");
        assert_eq!(sixteen[15].name, "train-16");
        assert!(sixteen.iter().all(|p| p.role == Role::Train));
        for (n, poses) in [(8usize, &eight), (16, &sixteen)] {
            let ranges = [super::X_MAX_MM, super::Z_MAX_MM, super::THETA_MAX_DEG, super::THETA_MAX_DEG];
            for (dim, half) in ranges.iter().enumerate() {
                let mut hit = vec![0u32; n];
                for p in poses.iter() {
                    let v = [p.x_mm, p.z_mm, p.theta_x_deg, p.theta_z_deg][dim];
                    assert!(v.abs() <= *half, "{}: input {dim} = {v} outside +-{half}", p.name);
                    // stratum of the unrounded point; rounding to 0.01 may move a point
                    // across a boundary by at most 0.005
                    let k = (((v + half) / (2.0 * half)) * n as f64).floor().clamp(0.0, n as f64 - 1.0) as usize;
                    hit[k] += 1;
                }
                let empty = hit.iter().filter(|&&h| h == 0).count();
                assert!(empty <= 1, "{n} points, input {dim}: strata hit {hit:?}");
            }
        }
        c.campaign.train_seed = 8;
        assert_ne!(c.train_poses(), eight, "the seed scrambles the design");
        assert!(c.poses().iter().filter(|p| p.role == Role::Train).count() == 8, "poses() lists the training poses");
    }

    /// Issue 42, item 3: a training pose that fails every attempt is replaced by the next
    /// point of the sequence; a replacement that fails is replaced in turn.
    #[test]
    fn replaced_training_poses_take_the_next_points_of_the_sequence() {
        let set = crate::workspace_root().join("coeffs/default");
        let text = std::fs::read_to_string(set.join("campaign.toml")).expect("campaign.toml");
        let Ok((mut c, _)) = super::load(&set) else { panic!("cannot load {}", set.display()) };
        c.campaign.train_replaced.clear();
        c.campaign.train_count = 10;
        let ten = c.train_poses();
        c.campaign.train_count = 8;
        let why = |p: &str| super::TrainReplacement { pose: p.into(), why: "all attempts failed".into() };
        c.campaign.train_replaced = vec![why("train-03"), why("train-09")];
        let got = c.train_poses();
        assert_eq!(got, ten, "8 drawn + 2 replacements = the first 10 points of the sequence");
        assert_eq!(c.replacement_of("train-03").as_deref(), Some("train-09"));
        assert_eq!(c.replacement_of("train-09").as_deref(), Some("train-10"));
        assert_eq!(c.replacement_of("train-04"), None);
        assert_eq!(c.replaced_by("train-10").map(|r| r.pose.as_str()), Some("train-09"));
        assert_eq!(c.replaced_by("train-03").map(|r| r.pose.as_str()), None);
        assert!(c.is_replaced("train-09") && !c.is_replaced("train-10"));
        let design = c.train_design();
        assert_eq!(design.len(), 8);
        assert_eq!(design[2], "train-10", "slot 3: train-03 -> train-09 -> train-10");
        assert_eq!(design[3], "train-04");
        // the spec's checks, on the text: entries appended after the shipped ones (a TOML
        // array of tables of [campaign] goes after its plain keys, before [deep])
        let shipped = super::parse(&text, Path::new("campaign.toml")).map(|c| c.campaign.train_replaced.len()).unwrap_or(usize::MAX);
        let at_end = |entries: &[(&str, &str)]| {
            let add: String =
                entries.iter().map(|(p, w)| format!("[[campaign.train_replaced]]\npose = \"{p}\"\nwhy = \"{w}\"\n")).collect();
            let t = text.replacen("\n[deep]\n", &format!("\n{add}\n[deep]\n"), 1);
            assert_ne!(t, text, "the test's edit did not apply");
            super::parse(&t, Path::new("campaign.toml")).map(|c| c.campaign.train_replaced.len())
        };
        assert_eq!(at_end(&[("train-09", "x")]).ok(), Some(shipped + 1));
        let err = |r: anyhow::Result<usize>| r.err().map(|e| e.to_string()).unwrap_or_default();
        let msg = err(at_end(&[("train-60", "x")]));
        assert!(msg.contains("\"train-60\" is not a training pose drawn before its replacement"), "{msg}");
        let msg = err(at_end(&[("train-09", "x"), ("train-09", "y")]));
        assert!(msg.contains("\"train-09\" is listed twice"), "{msg}");
        let msg = err(at_end(&[("train-09", " ")]));
        assert!(msg.contains("`why` is empty"), "{msg}");
        let both = text.replacen("fit_without = [", "fit_without = [\"train-09\", ", 1).replacen(
            "\n[deep]\n",
            "\n[[campaign.train_replaced]]\npose = \"train-09\"\nwhy = \"x\"\n\n[deep]\n",
            1,
        );
        let msg = err(super::parse(&both, Path::new("campaign.toml")).map(|c| c.campaign.train_replaced.len()));
        assert!(msg.contains("\"train-09\" is in campaign.train_replaced"), "{msg}");
        // a replacement replaced in turn
        let first = format!("train-{}", 33 + shipped);
        assert_eq!(at_end(&[("train-09", "x"), (first.as_str(), "y")]).ok(), Some(shipped + 2));
    }

    fn names(poses: &[&PoseSpec]) -> Vec<String> {
        poses.iter().map(|p| p.name.clone()).collect()
    }

    #[test]
    fn select_takes_comma_separated_globs_in_spec_order() {
        let poses: Vec<PoseSpec> = ["centre", "lhs-03", "lhs-09", "lhs-10", "lhs-13"]
            .iter()
            .map(|n| PoseSpec { name: (*n).to_owned(), role: Role::Lhs, x_mm: 0.0, z_mm: 0.0, theta_x_deg: 0.0, theta_z_deg: 0.0 })
            .collect();
        let all = select(&poses, None).map(|v| names(&v)).ok();
        assert_eq!(all.map(|v| v.len()), Some(5));
        let two = select(&poses, Some("lhs-1*,lhs-09")).map(|v| names(&v)).ok();
        assert_eq!(two, Some(vec!["lhs-09".into(), "lhs-10".into(), "lhs-13".into()]));
        assert!(select(&poses, Some("lhs-09,,x")).is_err(), "an empty pattern is refused");
        assert!(select(&poses, Some("lhs-[")).is_err(), "a broken glob is refused");
    }

    /// Issue 18: a pose outside the block and a sweep pose off its axis were accepted.
    #[test]
    fn poses_outside_the_block_or_off_their_sweep_axis_are_refused() {
        let set = crate::workspace_root().join("coeffs/default");
        let text = std::fs::read_to_string(set.join("campaign.toml")).expect("campaign.toml");
        let cases = [
            // block 10 mm wide: x+06 (the first listed pose beyond 4.5 mm) is outside
            (
                text.replace("size_x_mm = 50.0", "size_x_mm = 10.0"),
                "pose \"x+06\": x_mm = 6 with a lateral travel of 0.000 mm at full depth (6 mm): the needle (radius 0.5 mm) reaches 6.500 mm from the centre, beyond the block's side at 5 mm",
            ),
            // a sweep-x pose with z = 3
            (text.replacen("role = \"sweep-x\"\nx_mm = 2.0", "role = \"sweep-x\"\nx_mm = 2.0\nz_mm = 3.0", 1), "pose \"x+02\": z_mm = 3: must be 0 (a SweepX pose varies x_mm only)"),
        ];
        for (spec, want) in cases {
            assert_ne!(spec, text, "the test's edit did not apply");
            let msg = super::parse(&spec, Path::new("campaign.toml")).err().map(|e| e.to_string()).unwrap_or_default();
            assert!(msg.contains(want), "{msg}");
        }
        assert!(super::parse(&text, Path::new("campaign.toml")).is_ok(), "the shipped spec passes");
        // a malformed value: file and line
        let line = text.lines().position(|l| l.starts_with("bulk_to_shear =")).expect("bulk_to_shear line") + 1;
        let bad = text.replace("bulk_to_shear = 100.0", "bulk_to_shear = abc");
        let msg = super::parse(&bad, Path::new("campaign.toml")).err().map(|e| e.to_string()).unwrap_or_default();
        assert!(msg.starts_with(&format!("campaign.toml:{line}: ")), "{msg}");
    }
}

/// `[deep]` (crate::deep) checked and applied here, beside the rest of the spec: the
/// section's type lives in `deep`, which does not depend on `spec`.
impl crate::deep::DeepSettings {
    /// The campaign's spec as a deep run sees it: `[loading]` to the deep depth and steps.
    pub fn apply(&self, c: &Campaign) -> Campaign {
        let mut deep = c.clone();
        deep.loading = Loading { depth_mm: self.depth_mm, steps: self.steps, ramp_hold: None };
        deep
    }
}

/// Check `[deep]` against the rest of the spec; messages start with `file:line:` and name
/// the field (`deep.depth_mm = ...`).
///
/// # Errors
/// A depth not beyond `loading.depth_mm` or not inside the block, 0 steps, an unknown
/// mesh level or one whose fine layers stop above the depth, no poses, an unknown or
/// repeated pose, or a pose whose needle leaves the block at the deep depth.
pub fn validate_deep(c: &Campaign, text: &str, path: &Path) -> Result<()> {
    let Some(d) = &c.deep else { return Ok(()) };
    let at = |key: &str| format!("{}:{}", path.display(), crate::deep::key_line(text, "deep", key));
    if !(d.depth_mm.is_finite() && d.depth_mm > c.loading.depth_mm && d.depth_mm < c.block.depth_mm) {
        bail!(
            "{}: deep.depth_mm = {}: must be beyond loading.depth_mm ({} mm) and inside the block (block.depth_mm = {} mm)",
            at("depth_mm"),
            d.depth_mm,
            c.loading.depth_mm,
            c.block.depth_mm
        );
    }
    if d.steps == 0 || d.steps > MAX_LOAD_STEPS {
        bail!("{}: deep.steps = {}: must be 1 ..= {MAX_LOAD_STEPS}", at("steps"), d.steps);
    }
    let Some(level) = c.mesh.get(&d.mesh) else {
        let levels: Vec<&str> = c.mesh.keys().map(String::as_str).collect();
        bail!("{}: deep.mesh = {:?}: no [mesh.{}] level (levels: {})", at("mesh"), d.mesh, d.mesh, levels.join(", "));
    };
    if level.fine_depth_mm < d.depth_mm {
        bail!(
            "{}: deep.mesh = {:?}: its fine layers end at fine_depth_mm = {} mm, above deep.depth_mm = {} mm (the tip would cut through coarse layers)",
            at("mesh"),
            d.mesh,
            level.fine_depth_mm,
            d.depth_mm
        );
    }
    if d.poses.is_empty() {
        bail!("{}: deep.poses is empty: name at least one pose (e.g. \"centre\")", at("poses"));
    }
    let every = c.poses();
    for (k, name) in d.poses.iter().enumerate() {
        if d.poses[..k].contains(name) {
            bail!("{}: deep.poses: {name:?} is listed twice", at("poses"));
        }
        let Some(pose) = every.iter().find(|p| &p.name == name) else {
            bail!("{}: deep.poses: {name:?} is not a pose of this campaign", at("poses"));
        };
        let radius_mm = c.needle.diameter_mm / 2.0;
        check_pose_in_block(pose, &c.block, radius_mm, d.depth_mm, &at("poses"))?;
    }
    Ok(())
}

#[cfg(test)]
mod deep_tests {
    use super::*;
    use crate::deep::key_line;

    fn shipped() -> String {
        std::fs::read_to_string(crate::workspace_root().join("coeffs/default/campaign.toml")).expect("campaign.toml")
    }

    fn error_of(text: &str) -> String {
        parse(text, Path::new("campaign.toml")).err().map(|e| e.to_string()).unwrap_or_default()
    }

    #[test]
    fn the_shipped_deep_section_applies_its_depth_and_steps() {
        let text = shipped();
        let c = parse(&text, Path::new("campaign.toml")).expect("the shipped spec");
        let d = c.deep.clone().expect("coeffs/default has a [deep] section");
        let deep = d.apply(&c);
        assert_eq!((deep.loading.depth_mm, deep.loading.steps), (d.depth_mm, d.steps));
        assert_eq!(d.poses.first().map(String::as_str), Some("centre"));
        let centre = c.poses().into_iter().find(|p| p.name == "centre").expect("centre");
        assert_ne!(deep.run_hash(&centre, &d.mesh), c.run_hash(&centre, &d.mesh), "a deep run never passes for a shallow one");
    }

    #[test]
    fn bad_deep_sections_are_refused_with_file_line_and_field() {
        let text = shipped();
        let line = |key: &str| key_line(&text, "deep", key);
        assert!(line("depth_mm") > 0 && line("mesh") > 0 && line("poses") > 0, "the shipped [deep] names its fields");
        let deep_line = |key: &str| text.lines().nth(line(key) - 1).expect("a [deep] line").to_string();
        let (depth, poses, mesh, steps) = (deep_line("depth_mm"), deep_line("poses"), deep_line("mesh"), deep_line("steps"));
        let cases = [
            (text.replace(&depth, "depth_mm = 5.0"), format!("campaign.toml:{}: deep.depth_mm = 5: must be beyond", line("depth_mm"))),
            (text.replace(&depth, "depth_mm = 31.0"), "inside the block (block.depth_mm = 30 mm)".to_string()),
            (
                text.replace(&mesh, "mesh = \"needle8\""),
                format!("campaign.toml:{}: deep.mesh = \"needle8\": its fine layers end at fine_depth_mm = 0.4 mm", line("mesh")),
            ),
            (text.replace(&mesh, "mesh = \"huge\""), "deep.mesh = \"huge\": no [mesh.huge] level".to_string()),
            (text.replace(&poses, "poses = []"), format!("campaign.toml:{}: deep.poses is empty", line("poses"))),
            (
                text.replace(&poses, "poses = [\"centre\", \"nowhere\"]"),
                "deep.poses: \"nowhere\" is not a pose of this campaign".to_string(),
            ),
            (text.replace(&poses, "poses = [\"centre\", \"centre\"]"), "deep.poses: \"centre\" is listed twice".to_string()),
            // x = 12 mm tilted 15 degrees outwards: inside a 30 mm wide block at 6 mm
            // (reach 14.05 mm), outside at 15 mm (16.38 mm)
            (
                format!("{text}\n[[pose]]\nname = \"edge\"\nrole = \"mirror\"\nx_mm = 12.0\ntheta_z_deg = 15.0\n")
                    .replace("size_x_mm = 50.0", "size_x_mm = 30.0")
                    .replace(&poses, "poses = [\"centre\", \"edge\"]")
                    .replace(&depth, "depth_mm = 15.0")
                    .replace(&steps, "steps = 50"),
                format!(
                    "campaign.toml:{}: pose \"edge\": x_mm = 12 with a lateral travel of 3.882 mm at full depth (15 mm)",
                    line("poses")
                ),
            ),
        ];
        for (spec, want) in cases {
            assert_ne!(spec, text, "the test's edit did not apply ({want})");
            let msg = error_of(&spec);
            assert!(msg.contains(&want), "want {want:?} in: {msg}");
        }
        for (n, shown) in [("0", "0"), ("4000000000", "4000000000")] {
            let bad = text.replace(&steps, &format!("steps = {n}"));
            let want = format!("campaign.toml:{}: deep.steps = {shown}: must be 1 ..= {MAX_LOAD_STEPS}", line("steps"));
            assert!(error_of(&bad).contains(&want), "{}", error_of(&bad));
        }
    }

    /// A typo of billions (`4e9` read as 4,000,000,000) in a count the campaign
    /// allocates per item is refused at load, before anything is allocated (it aborted
    /// `fe status`, `validate` and `fe run` with an allocation failure).
    #[test]
    fn counts_of_billions_are_refused_at_load() {
        let text = shipped();
        let line_of = |table: &str, key: &str| -> String {
            let l = key_line(&text, table, key);
            assert!(l > 0, "the shipped spec has {table}.{key}");
            text.lines().nth(l - 1).expect("line").to_string()
        };
        for (table, key, want) in [
            ("loading", "steps", format!("loading.steps = 4000000000: must be 1 ..= {MAX_LOAD_STEPS}")),
            ("campaign", "lhs_count", format!("campaign.lhs_count = 4000000000: must be <= {MAX_GENERATED_POSES}")),
            ("campaign", "train_count", format!("campaign.train_count = 4000000000: must be <= {MAX_GENERATED_POSES}")),
        ] {
            let bad = text.replacen(&line_of(table, key), &format!("{key} = 4000000000"), 1);
            assert_ne!(bad, text);
            assert!(error_of(&bad).contains(&want), "want {want:?} in: {}", error_of(&bad));
        }
    }

    #[test]
    fn key_line_finds_keys_inside_their_table_only() {
        let t = "[a]\nx = 1\n[deep]\n# c\nx = 2\nposes = [\"a\"]\n[b]\nx = 3\n";
        assert_eq!((key_line(t, "deep", "x"), key_line(t, "deep", "poses"), key_line(t, "deep", "")), (5, 6, 3));
        assert_eq!(key_line(t, "deep", "y"), 0);
    }
}
