//! The FE runs of a set, by role: the fitted sweeps (with the centre run) and the
//! validation runs, read from `<set>/fe/<pose>.csv` as the campaign spec names them.

use super::contract::{Sweep, DEPTH_MAX_MM, NCOEF};
pub use super::run_error::RunError;
use anyhow::{bail, Context, Result};
use needle_set::manifest::Manifest;
use needle_set::results::{parse_csv, Row};
use needle_set::set_folder::SetFolder;
use needle_set::spec::{hex, Campaign, ModelForm, PoseSpec, Role};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// One FE run: its pose and the wrench at every depth.
#[derive(Debug, Clone)]
pub struct Run {
    /// The pose as the campaign spec gives it (mm, degrees).
    pub pose: PoseSpec,
    /// File name inside `fe/`, e.g. `x+02.csv`.
    pub file_name: String,
    /// One row per depth (depth in mm, wrench in N and N·mm).
    pub rows: Vec<Row>,
}

impl Run {
    /// The pose `[x, z, theta_x, theta_z, depth]` of this run at `depth_mm` (mm, degrees).
    pub fn pose_at(&self, depth_mm: f64) -> super::contract::Pose64 {
        let p = &self.pose;
        [p.x_mm, p.z_mm, p.theta_x_deg, p.theta_z_deg, depth_mm]
    }
}

/// One point of a sweep: the swept value (mm or degrees, >= 0) and its run.
#[derive(Debug, Clone)]
pub struct SweepPoint {
    /// The swept variable's value: 0 for the centre run.
    pub value: f64,
    /// The run.
    pub run: Run,
}

/// Everything the fitter reads.
#[derive(Debug, Clone)]
pub struct FitData {
    /// The campaign spec.
    pub campaign: Campaign,
    /// The centred vertical run.
    pub centre: Run,
    /// Per sweep in contract order: the centre run at value 0, then the sweep's runs in
    /// increasing value.
    pub sweeps: [Vec<SweepPoint>; 4],
    /// The training runs (role train, spec order) when the set fits the coupled form
    /// (`[fit] form = "coupled"`); empty for the paper form.
    pub train: Vec<Run>,
    /// SHA-256 (hex) of the FE files read, as coeffs/README.md defines `fe_sha256`.
    pub fe_sha256: String,
}

/// The sweep a fitting role belongs to (None for the centre and for unfitted roles).
pub fn sweep_of(role: Role) -> Option<Sweep> {
    match role {
        Role::SweepX => Some(Sweep::X),
        Role::SweepZ => Some(Sweep::Z),
        Role::SweepThetaX => Some(Sweep::ThetaX),
        Role::SweepThetaZ => Some(Sweep::ThetaZ),
        _ => None,
    }
}

/// The pose's value of the swept variable `k` (mm or degrees) and the largest |value| of
/// the other three inputs.
fn sweep_value(pose: &PoseSpec, k: Sweep) -> (f64, f64) {
    let all = [pose.x_mm, pose.z_mm, pose.theta_x_deg, pose.theta_z_deg];
    let v = all[k.index()];
    let others = all.iter().enumerate().filter(|(i, _)| *i != k.index()).map(|(_, v)| v.abs()).fold(0.0, f64::max);
    (v, others)
}

pub use needle_set::set_folder::run_path;

/// A set's FE results as the fitter reads them: the spec's loading and the manifest, the
/// manifest read once ([`FeRuns::new`]) and every run checked against that copy (issue 37:
/// the manifest used to be parsed again for each run).
pub struct FeRuns<'a> {
    set: &'a SetFolder,
    campaign: &'a Campaign,
}

impl<'a> FeRuns<'a> {
    /// The runs of `set` read with the spec `campaign` (the set's, or a copy with
    /// another `[fit] form`), checked against the manifest `set` was opened with.
    pub fn new(set: &'a SetFolder, campaign: &'a Campaign) -> Self {
        Self { set, campaign }
    }

    /// The set's manifest, as read when the set was opened.
    pub fn manifest(&self) -> &Manifest {
        self.set.manifest()
    }

    /// Read one run, check its content against the manifest (`check_content`) and its
    /// depth grid against the spec's loading (steps + 1 rows at `depth_at(k)`, to 1e-9 mm).
    ///
    /// # Errors
    /// The file cannot be read or parsed, its content is not what the campaign wrote, or
    /// its depths are not the spec's.
    pub fn read(&self, pose: &PoseSpec) -> Result<Run> {
        let path = self.set.run_path(pose);
        let text = std::fs::read_to_string(&path).with_context(|| format!("{}: cannot read", path.display()))?;
        check_content(self.set.manifest(), pose, &path, text.as_bytes())?;
        let rows = parse_csv(&text, &path)?;
        let loading = &self.campaign.loading;
        let steps = loading.steps;
        if rows.len() != steps as usize + 1 {
            return Err(RunError::DepthRows { path, found: rows.len(), expected: steps as usize + 1 }.into());
        }
        for (k, r) in (0u32..).zip(&rows) {
            let want = loading.depth_at(k);
            if (r.depth_mm - want).abs() > 1e-9 {
                return Err(RunError::Depth { path, line: k as usize + 2, found_mm: r.depth_mm, expected_mm: want }.into());
            }
        }
        Ok(Run { pose: pose.clone(), file_name: format!("{}.csv", pose.name), rows })
    }
}

/// A run's CSV must be the bytes the campaign wrote: when its manifest entry records a
/// `csv_sha256`, the file's hash must match (issue 18: a hand-edited CSV was fitted and
/// validated silently), and an entry without the hash is refused (issue 38: a hash
/// recorded later vouched for an edited file). The original is not kept, so the message
/// gives both hashes.
///
/// # Errors
/// `bytes` (the file at `path`) differ from the hash `manifest` records, or it records none.
fn check_content(manifest: &Manifest, pose: &PoseSpec, path: &Path, bytes: &[u8]) -> std::result::Result<(), RunError> {
    let Some(entry) = manifest.pose.get(&pose.name) else { return Ok(()) };
    let Some(want) = entry.csv_sha256.as_ref() else {
        return Err(RunError::NoHash { path: path.into(), pose: pose.name.clone() });
    };
    if !entry.content_matches(bytes) {
        let now = needle_set::results::content_sha256(bytes);
        return Err(RunError::ContentChanged { path: path.into(), pose: pose.name.clone(), now, recorded: want.clone() });
    }
    Ok(())
}

/// Why the present result of `pose` cannot be used with the current spec, or `None` when
/// it is current on the spec's committed mesh level ([`Manifest::current_entry`]). A
/// result solved before `campaign.toml` changed (tissue, contact, mesh, loading...) is
/// stale: fitting or validating on a mix of old and new runs would be silently wrong.
pub fn stale_reason(manifest: &Manifest, campaign: &Campaign, pose: &PoseSpec) -> Option<String> {
    manifest.current_entry(campaign, pose, &campaign.campaign.mesh).err()
}

/// The poses the fitter uses: the centre, every sweep run and, for the coupled form, every
/// training run, less those listed in `campaign.fit_without` and the training runs
/// replaced by the next point of the design (`campaign.train_replaced`; their files make
/// up `fe_sha256`).
pub fn fitted_poses(campaign: &Campaign) -> Vec<PoseSpec> {
    let left_out = &campaign.campaign.fit_without;
    let coupled = campaign.fit.form == ModelForm::Coupled;
    campaign
        .poses()
        .into_iter()
        .filter(|p| {
            (p.role.is_fitted() || (coupled && p.role == Role::Train)) && !left_out.contains(&p.name) && !campaign.is_replaced(&p.name)
        })
        .collect()
}

/// Load the campaign and every run the fitter uses: the centre and the four sweeps.
///
/// # Errors
/// The spec cannot be loaded; its loading depth is not the contract's 6 mm; a fitted run
/// is missing (the message lists every missing pose; runs named in `campaign.fit_without`
/// are not fitted and may be missing); a fitted run cannot be read or has
/// the wrong depths; a sweep pose has another input nonzero or a negative value; there is
/// not exactly one centre pose; a sweep has fewer than 5 distinct values (centre
/// included) or a value outside its half-range.
pub fn load_fit_data(set: &SetFolder) -> Result<FitData> {
    load_fit_data_in(set, None)
}

/// [`load_fit_data`] as if the set's `[fit] form` were `"paper"`: the centre and sweep
/// runs only (no training runs, which may then be missing), `fe_sha256` over those; the
/// data of the paper form that a coupled set is compared with.
///
/// # Errors
/// As [`load_fit_data`], for the centre and sweep runs.
pub fn load_paper_data(set: &SetFolder) -> Result<FitData> {
    load_fit_data_in(set, Some(ModelForm::Paper))
}

fn load_fit_data_in(set: &SetFolder, form: Option<ModelForm>) -> Result<FitData> {
    let (mut campaign, spec_path) = (set.campaign().clone(), set.spec_path());
    if let Some(f) = form {
        campaign.fit.form = f;
    }
    if campaign.loading.depth_mm != DEPTH_MAX_MM {
        bail!(
            "{}: loading.depth_mm = {}: the model contract (coeffs/README.md) fixes the depth range to 0 ..= {DEPTH_MAX_MM} mm",
            spec_path.display(),
            campaign.loading.depth_mm
        );
    }
    let fitted = fitted_poses(&campaign);
    let (centre, sweeps, train) = {
        let runs = FeRuns::new(set, &campaign);
        check_fitted_runs_current(&runs, &fitted)?;
        let centre = centre_run(&runs, spec_path, &fitted)?;
        let sweeps = sweep_points(&runs, spec_path, &fitted, &centre)?;
        let train = fitted.iter().filter(|p| p.role == Role::Train).map(|p| runs.read(p)).collect::<Result<Vec<_>>>()?;
        (centre, sweeps, train)
    };
    let fe_sha256 = fitted_fe_sha256(set.dir(), &fitted)?;
    Ok(FitData { campaign, centre, sweeps, train, fe_sha256 })
}

/// Every fitted pose has a result and it is current (the manifest's record of the spec).
fn check_fitted_runs_current(runs: &FeRuns<'_>, fitted: &[PoseSpec]) -> Result<()> {
    let (set_dir, campaign) = (runs.set.dir(), runs.campaign);
    let missing: Vec<String> = fitted.iter().filter(|p| !run_path(set_dir, p).is_file()).map(|p| p.name.clone()).collect();
    if !missing.is_empty() {
        return Err(RunError::Missing { set_dir: set_dir.into(), fitted: fitted.len(), poses: missing }.into());
    }
    let stale: Vec<(String, String)> =
        fitted.iter().filter_map(|p| stale_reason(runs.manifest(), campaign, p).map(|why| (p.name.clone(), why))).collect();
    if !stale.is_empty() {
        return Err(RunError::Stale { set_dir: set_dir.into(), fitted: fitted.len(), runs: stale }.into());
    }
    Ok(())
}

/// The run of the one pose with role centre, at x = z = theta_x = theta_z = 0.
fn centre_run(runs: &FeRuns<'_>, spec_path: &Path, fitted: &[PoseSpec]) -> Result<Run> {
    let centres: Vec<&PoseSpec> = fitted.iter().filter(|p| p.role == Role::Centre).collect();
    let centre_pose = match centres.as_slice() {
        [one] => (*one).clone(),
        _ => bail!("{}: {} poses with role centre, expected exactly one", spec_path.display(), centres.len()),
    };
    if centre_pose.x_mm != 0.0 || centre_pose.z_mm != 0.0 || centre_pose.theta_x_deg != 0.0 || centre_pose.theta_z_deg != 0.0 {
        bail!("{}: pose {:?} (role centre) is not at x = z = theta_x = theta_z = 0", spec_path.display(), centre_pose.name);
    }
    runs.read(&centre_pose)
}

/// Each sweep's points (the centre run at 0 first), sorted by the swept value: every
/// sweep pose varies only its own input, within (0, half range], and each sweep has at
/// least [`NCOEF`] distinct values.
fn sweep_points(runs: &FeRuns<'_>, spec_path: &Path, fitted: &[PoseSpec], centre: &Run) -> Result<[Vec<SweepPoint>; 4]> {
    let mut sweeps: [Vec<SweepPoint>; 4] = Default::default();
    for k in Sweep::ALL {
        sweeps[k.index()].push(SweepPoint { value: 0.0, run: centre.clone() });
    }
    for pose in fitted {
        let Some(k) = sweep_of(pose.role) else { continue };
        let (v, others) = sweep_value(pose, k);
        if others != 0.0 {
            bail!(
                "{}: pose {:?} (role sweep-{}) has another input nonzero: a sweep varies only its own input",
                spec_path.display(),
                pose.name,
                k.name().replace('_', "-")
            );
        }
        if !(v > 0.0 && v <= k.half_range()) {
            bail!(
                "{}: pose {:?}: swept value {v} {} must be > 0 and <= {}; negative values are mirror runs (role mirror), not fitted",
                spec_path.display(),
                pose.name,
                k.unit(),
                k.half_range()
            );
        }
        let run = runs.read(pose)?;
        sweeps[k.index()].push(SweepPoint { value: v, run });
    }
    for k in Sweep::ALL {
        let pts = &mut sweeps[k.index()];
        pts.sort_by(|a, b| a.value.total_cmp(&b.value).then_with(|| a.run.file_name.cmp(&b.run.file_name)));
        let mut distinct: Vec<f64> = pts.iter().map(|p| p.value).collect();
        distinct.dedup();
        if distinct.len() < NCOEF {
            bail!(
                "sweep {}: {} distinct values ({}) with the centre run, need at least {NCOEF} for a 4th-order fit",
                k.name(),
                distinct.len(),
                distinct.iter().map(|v| format!("{v}")).collect::<Vec<_>>().join(", ")
            );
        }
    }
    Ok(sweeps)
}

/// `fe_sha256` of the runs of `poses` in `set_dir` (their `<pose>.csv` files).
///
/// # Errors
/// A file cannot be read.
pub fn fitted_fe_sha256(set_dir: &Path, poses: &[PoseSpec]) -> Result<String> {
    let mut files: Vec<(String, PathBuf)> = poses.iter().map(|p| (format!("{}.csv", p.name), run_path(set_dir, p))).collect();
    fe_sha256(&mut files)
}

/// `fe_sha256` of coeffs/README.md: SHA-256 over, for each file in byte order of its
/// name, the name (e.g. `x+02.csv`), a `\n`, and the file's bytes. Sorts `files`.
///
/// # Errors
/// A file cannot be read.
pub fn fe_sha256(files: &mut [(String, PathBuf)]) -> Result<String> {
    files.sort_by(|a, b| a.0.as_bytes().cmp(b.0.as_bytes()));
    let mut h = Sha256::new();
    for (name, path) in files.iter() {
        let bytes = std::fs::read(path).with_context(|| format!("{}: cannot read", path.display()))?;
        h.update(name.as_bytes());
        h.update(b"\n");
        h.update(&bytes);
    }
    Ok(hex(&h.finalize()))
}

/// A validation run that cannot be compared: its pose and why (no result file, or a
/// stale one, see [`stale_reason`]).
#[derive(Debug, Clone)]
pub struct Unusable {
    /// The pose.
    pub pose: PoseSpec,
    /// Why, e.g. `no result file`.
    pub why: String,
}

/// The validation runs of a set: roles table2, lhs and mirror, in spec order, and those
/// that cannot be used (missing or stale).
///
/// # Errors
/// The spec or the manifest cannot be loaded, or a present run cannot be read or has the
/// wrong depths.
pub fn load_validation_runs(set: &SetFolder) -> Result<(Campaign, Vec<Run>, Vec<Unusable>)> {
    load_runs_where(set, |r| r.is_validation() || r == Role::Mirror)
}

/// The training runs of a set (role train, in spec order: `train-01`, ...) and those that
/// cannot be used (missing or stale); a training pose replaced in the design
/// (`campaign.train_replaced`) is in neither, as in the fit.
///
/// # Errors
/// As [`load_validation_runs`].
pub fn load_training_runs(set: &SetFolder) -> Result<(Campaign, Vec<Run>, Vec<Unusable>)> {
    let (campaign, mut runs, mut unusable) = load_runs_where(set, |r| r == Role::Train)?;
    runs.retain(|r| !campaign.is_replaced(&r.pose.name));
    unusable.retain(|u| !campaign.is_replaced(&u.pose.name));
    Ok((campaign, runs, unusable))
}

/// How [`Unusable::why`] starts for a pose that failed every attempt (it has a partial
/// record).
pub const FAILED_PREFIX: &str = "no result;";

/// Why a pose has no result when the campaign kept a record of it (issue 42, item 4:
/// `<set>/fe/<pose>.partial.toml`, written when every attempt failed): the depth reached
/// and its attempts by class; `None` without a record of the current spec.
fn failed_record(set_dir: &Path, campaign: &Campaign, pose: &PoseSpec) -> Option<String> {
    use needle_set::failures;
    let (_, path) = needle_set::partial::paths(&set_dir.join("fe"), &pose.name);
    let r: needle_set::partial::PartialRecord = toml::from_str(&std::fs::read_to_string(path).ok()?).ok()?;
    if r.spec_hash != campaign.run_hash(pose, &campaign.campaign.mesh) {
        return None;
    }
    Some(format!(
        "{FAILED_PREFIX} its furthest failed attempt reached {} of {} mm; {}",
        r.reached_depth_mm,
        r.depth_mm,
        failures::summary(&failures::failures_from_record(&r.failure), "mm")
    ))
}

fn load_runs_where(set: &SetFolder, keep: impl Fn(Role) -> bool) -> Result<(Campaign, Vec<Run>, Vec<Unusable>)> {
    let (campaign, set_dir) = (set.campaign().clone(), set.dir());
    let fe = FeRuns::new(set, &campaign);
    let mut runs = Vec::new();
    let mut unusable = Vec::new();
    for pose in campaign.poses() {
        if !keep(pose.role) {
            continue;
        }
        if !run_path(set_dir, &pose).is_file() {
            let why = failed_record(set_dir, &campaign, &pose).unwrap_or_else(|| "no result file".into());
            unusable.push(Unusable { pose, why });
        } else if let Some(why) = stale_reason(fe.manifest(), &campaign, &pose) {
            unusable.push(Unusable { pose, why });
        } else {
            runs.push(fe.read(&pose)?);
        }
    }
    Ok((campaign, runs, unusable))
}

#[cfg(test)]
mod tests {
    use super::*;
    use needle_set::spec;

    /// Issue 42, item 4: a validation run that cannot be solved says how far its furthest
    /// attempt got and why, from the campaign's partial record (of the current spec only).
    #[test]
    fn an_unsolved_run_reports_its_partial_record() {
        let dir = std::env::temp_dir().join(format!("needle-fit-partial-{}", std::process::id()));
        let fe = dir.join("fe");
        std::fs::create_dir_all(&fe).expect("temp set");
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        std::fs::copy(root.join("coeffs/default/campaign.toml"), dir.join("campaign.toml")).expect("copy the default spec");
        let (campaign, _) = spec::load(&dir).expect("spec");
        let pose = campaign.poses().into_iter().find(|p| p.name == "t2-b").expect("t2-b");
        let failure = "solver exit code 1 after 6 of 20 steps (t = 1.95 mm): Max nr of reformations reached. (failed to converge at time : 1.95); retry 1 (first increment 1): solver exit code 1 after 0 of 20 steps (t = 0.2 mm): 9 negative jacobians detected. (failed to converge at time : 0.21)";
        let failed = needle_set::partial::Failed {
            campaign: &campaign,
            pose: &pose,
            mesh: &campaign.campaign.mesh,
            engine: ("febio", "4.11.0"),
            failure,
        };
        let reached: Vec<[f64; 6]> = (1..=6).map(|k| [0.0, 0.001 * f64::from(k), 0.0, 0.0, 0.0, 0.0]).collect();
        needle_set::partial::write(&fe, &failed, &reached).expect("partial record");
        let (_, _, unusable) = load_validation_runs(&SetFolder::open(&dir).expect("open")).expect("load");
        let why = |name: &str| unusable.iter().find(|u| u.pose.name == name).map(|u| u.why.clone()).unwrap_or_default();
        let t2b = why("t2-b");
        let _ = std::fs::remove_dir_all(&dir);
        assert_eq!(
            t2b,
            "no result; its furthest failed attempt reached 1.8 of 6 mm; 2 failed attempt(s), furthest 1.95 mm: max reformations x1 (1.95 mm); negative jacobian x1 (0.21 mm)"
        );
        assert_eq!(why("lhs-04"), "no result file", "no record: as before");
    }
}
