//! What a campaign run will do, worked out before anything is solved: the spec with the
//! run's variant applied (`--steps`, `--deep`, `--visco`, a tissue scale, an edge radius),
//! the mesh level, the output folder and which poses are up to date.

use super::{work_dir, RunOptions};
use crate::manifest::{read_manifest, Manifest, MANIFEST};
use crate::report::{PoseReport, Status};
use crate::results::{self, Row};
use crate::resume;
use crate::set_folder::SetFolder;
use crate::spec::{self, Campaign, PoseSpec};
use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};

/// What a campaign run will do, worked out before anything is solved or submitted:
/// the spec (with the `--solver` and `--steps` overrides applied), the mesh level, the
/// output folder and, per selected pose, whether its result is up to date. Shared by the
/// local run ([`run_with`](super::run_with)), the SLURM submission
/// ([`launcher::slurm`](crate::launcher::slurm)) and `needle fe status`.
pub struct Plan {
    /// The spec with the overrides applied.
    pub campaign: Campaign,
    /// `campaign.toml`'s path.
    pub spec_path: PathBuf,
    /// Mesh level name.
    pub mesh_name: String,
    /// Load steps per run.
    pub steps: u32,
    /// The output folder (`<set>/fe` unless `--out`).
    pub out_dir: PathBuf,
    /// The manifest as read.
    pub manifest: Manifest,
    /// One report per selected pose, in campaign order: [`Status::UpToDate`] (with the
    /// manifest's figures) or, for the poses in `to_run`, [`Status::NotRun`] until their
    /// solve reports.
    pub reports: Vec<PoseReport>,
    /// Indices into `reports` (and the selected poses) of the poses to solve.
    pub to_run: Vec<usize>,
    /// The selected poses, in campaign order (same order as `reports`).
    pub selected: Vec<PoseSpec>,
    /// Every pose of the run variant, selected or not.
    pub all: Vec<PoseSpec>,
}

impl Plan {
    /// Names of the poses to solve, in campaign order.
    pub fn to_run_names(&self) -> Vec<String> {
        self.to_run.iter().filter_map(|&i| self.selected.get(i)).map(|p| p.name.clone()).collect()
    }

    /// Whether `pose` is solved again only to resume an interrupted `--force` rerun (its
    /// earlier result is current; [`resume::unfinished`]).
    pub fn resumes_forced_rerun(&self, pose: &PoseSpec) -> bool {
        interrupted_force_rerun(&self.out_dir, &self.campaign, pose, &self.mesh_name, self.steps)
    }
}

/// Whether `pose`'s work folder in `out_dir` holds an unfinished run of exactly this spec,
/// mesh level and step count: an interrupted `--force` rerun, which a rerun resumes even
/// when the pose's result is up to date.
fn interrupted_force_rerun(out_dir: &Path, campaign: &Campaign, pose: &PoseSpec, mesh_name: &str, steps: u32) -> bool {
    resume::unfinished(&work_dir(out_dir, &pose.name), &campaign.run_hash(pose, mesh_name), mesh_name, steps)
}

/// Work out what `opts` asks for of the set `set` (opened once by the caller: its spec is
/// not read again) without changing any file: check the spec, pick the mesh level and the
/// poses, read the output folder's manifest, and sort the poses into up to date and to
/// solve (module docs).
///
/// # Errors
/// As [`run`](super::run), except solver problems (nothing is solved here); `opts.set_dir`
/// is not the folder `set` was opened from.
pub fn plan(set: &SetFolder, opts: &RunOptions) -> Result<Plan> {
    if opts.set_dir != set.dir() {
        bail!("the run options name the set {} but the set opened is {}", opts.set_dir.display(), set.dir().display());
    }
    let mut campaign = set.campaign().clone();
    let spec_path = set.spec_path().to_path_buf();
    let stability = crate::material::check(&campaign.tissue)
        .with_context(|| format!("{}: the tissue fails the material stability check; nothing was run", spec_path.display()))?;
    needle_stdx::noteln!("material check passed: {}", stability.to_string().replace('\n', "\n  "));
    if let Some(engine) = opts.solver {
        campaign.solver.engine = engine;
    }
    let variant = apply_variant(opts, &mut campaign, &spec_path)?;
    let steps = campaign.loading.steps;
    let mesh_name = opts.mesh.clone().unwrap_or(variant.mesh);
    campaign.mesh_level(&mesh_name)?;
    let all = variant.poses.unwrap_or_else(|| campaign.poses());
    let selected: Vec<PoseSpec> = spec::select(&all, opts.only.as_deref())?.into_iter().cloned().collect();
    if selected.is_empty() {
        bail!(
            "--only {:?} matches no pose (poses: {})",
            opts.only.as_deref().unwrap_or(""),
            all.iter().map(|p| p.name.as_str()).collect::<Vec<_>>().join(", ")
        );
    }
    let out_dir = opts.out_dir.clone().unwrap_or(variant.out_dir);
    let manifest = read_manifest(&out_dir.join(MANIFEST))?;
    let mut reports: Vec<PoseReport> = Vec::with_capacity(selected.len());
    let mut to_run: Vec<usize> = Vec::new();
    for pose in &selected {
        let csv = out_dir.join(format!("{}.csv", pose.name));
        let entry = manifest.current_entry(&campaign, pose, &mesh_name).ok();
        // a CSV whose content is not what the campaign wrote is not up to date
        let rows = entry
            .and_then(|e| std::fs::read_to_string(&csv).ok().filter(|text| e.content_matches(text.as_bytes())))
            .and_then(|text| match campaign.loading.ramp_hold {
                Some(_) => results::parse_timed_csv(&text, &csv).ok().map(|(_, rows)| rows),
                None => results::parse_csv(&text, &csv).ok(),
            })
            .filter(|r| r.len() == steps as usize + 1);
        let mut report = PoseReport {
            pose: pose.name.clone(),
            status: Status::UpToDate,
            wall_s: None,
            increments: None,
            fy_final_n: None,
            work_dir: None,
        };
        let interrupted = interrupted_force_rerun(&out_dir, &campaign, pose, &mesh_name, steps);
        match (entry, rows) {
            (Some(e), Some(rows)) if !opts.force && !interrupted => {
                report.wall_s = Some(e.wall_s);
                report.increments = Some(e.increments);
                report.fy_final_n = rows.last().map(Row::fy_n);
            }
            _ => {
                report.status = Status::NotRun;
                to_run.push(reports.len());
            }
        }
        reports.push(report);
    }
    Ok(Plan { campaign, spec_path, mesh_name, steps, out_dir, manifest, reports, to_run, selected, all })
}

/// What a run variant (`--deep`, a tissue scale) changes besides the spec it rewrites.
struct Variant {
    /// Default mesh level.
    mesh: String,
    /// The poses to select from (`None`: every pose of the campaign).
    poses: Option<Vec<PoseSpec>>,
    /// Default output folder.
    out_dir: PathBuf,
}

/// Apply `--steps`, `--deep` and the tissue scale of `opts` to `campaign` (in that order:
/// `--steps` overrides the deep steps too).
fn apply_variant(opts: &RunOptions, campaign: &mut Campaign, spec_path: &Path) -> Result<Variant> {
    let mut v = Variant { mesh: campaign.campaign.mesh.clone(), poses: None, out_dir: opts.set_dir.join("fe") };
    if let Some(run) = opts.family_run {
        v = apply_family(opts, campaign, spec_path, run)?;
    }
    if opts.deep {
        let d = campaign.deep.clone().with_context(|| format!("{}: --deep: the spec has no [deep] section", spec_path.display()))?;
        let every = campaign.poses();
        *campaign = d.apply(campaign);
        v.poses = Some(d.poses.iter().filter_map(|n| every.iter().find(|p| &p.name == n).cloned()).collect());
        v.mesh = d.mesh;
        v.out_dir = opts.set_dir.join("fe").join(crate::deep::DEEP_DIR);
    }
    if let Some(s) = opts.steps {
        if s == 0 {
            bail!("--steps 0: must be >= 1");
        }
        campaign.loading.steps = s;
    }
    if opts.visco_speed_mm_per_s.is_some() || opts.visco_frictionless {
        let v = campaign
            .viscoelastic
            .clone()
            .with_context(|| format!("{}: --visco: the spec has no [viscoelastic] section", spec_path.display()))?;
        if opts.deep {
            bail!("--visco and --deep: the ramp-and-hold runs go to loading.depth_mm only");
        }
        let (run, poses) = match opts.visco_speed_mm_per_s {
            Some(speed) => {
                let friction =
                    if opts.visco_frictionless { crate::spec::visco::Friction::None } else { crate::spec::visco::Friction::Campaign };
                crate::spec::visco::apply(campaign, &v, speed, campaign.loading.steps, friction)
            }
            None => crate::spec::visco::apply_frictionless_elastic(campaign, &v).with_context(|| {
                format!("{}: the frictionless elastic companions: [viscoelastic] frictionless is not set", spec_path.display())
            })?,
        };
        *campaign = run;
        return Ok(Variant { mesh: v.mesh, poses: Some(poses), out_dir: opts.set_dir.join("fe").join(crate::set_folder::VISCO_DIR) });
    }
    if let Some(s) = opts.tissue_scale {
        if !(s.is_finite() && s > 0.0) || opts.out_dir.is_none() {
            bail!("tissue scale {s}: must be finite and > 0, with its own output folder (never <set>/fe)");
        }
        campaign.tissue.scale_moduli(s);
    }
    if let Some(r) = opts.edge_radius_mm {
        if !campaign.needle.fits_edge_radius(r) || opts.out_dir.is_none() {
            bail!("edge radius {r} mm: must be > 0 and below the needle's radius, with its own output folder (never <set>/fe)");
        }
        campaign.needle.tip_edge_radius_mm = r;
    }
    Ok(v)
}

/// A run of the material family (`crate::family`): the member's tissue (material-checked),
/// its poses, depth and mesh (`--steps` then overrides the family's steps in
/// [`apply_variant`], as it does the deep runs').
fn apply_family(opts: &RunOptions, campaign: &mut Campaign, spec_path: &Path, run: crate::family::FamilyRun) -> Result<Variant> {
    let f = campaign.family.clone().with_context(|| format!("{}: --family: the spec has no [family] section", spec_path.display()))?;
    if opts.deep
        || opts.visco
        || opts.visco_speed_mm_per_s.is_some()
        || opts.visco_frictionless
        || opts.tissue_scale.is_some()
        || opts.edge_radius_mm.is_some()
    {
        bail!("--family runs its own members: not with --deep, --visco, a tissue scale or an edge radius");
    }
    let (member, poses, mesh) = crate::family::apply(campaign, &f, run);
    crate::material::check(&member.tissue).with_context(|| {
        format!("{}: family run of {} fails the material stability check; nothing was run", spec_path.display(), run.label())
    })?;
    *campaign = member;
    Ok(Variant { mesh, poses: Some(poses), out_dir: opts.set_dir.join("fe").join(crate::family::FAMILY_DIR) })
}
