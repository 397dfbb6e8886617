//! The FE campaign driver behind `needle fe run`: select the poses, skip the ones whose
//! result is up to date, solve the others in parallel on the set's engine (a
//! [`Backend`]: FEBio or CalculiX; `jobs` at once, `threads` solver threads each), write
//! `fe/<pose>.csv` and the manifest atomically, and report.
//!
//! Files, in the output folder (default `<set>/fe/`):
//! - `<pose>.csv`: the wrench at `steps + 1` depths (format: coeffs/README.md). Written
//!   with [`results::write_atomic`]: a killed run never leaves a half-written CSV.
//! - `manifest.toml`: one table per finished pose (see [`ManifestEntry`]), sorted by
//!   pose name, rewritten atomically after each pose.
//! - `manifest.toml.lock`: the lock ([`lock_manifest`]) under which every process
//!   (this one's jobs, SLURM array tasks, another `needle fe run`) rewrites the manifest.
//! - `.work/<pose>/`: the solver's input and files of a run; removed when the run
//!   succeeds (unless `keep_work`), kept for debugging when it fails. Its
//!   `progress.toml` ([`resume`]) records the attempt running, the finished attempts'
//!   failures and the furthest must points: a run killed in the middle of a pose (a
//!   session's end) resumes on the rerun at the attempt it was in, which the engine
//!   continues from its last dump (FEBio) or reruns from its start (ccx), with
//!   `<pose>: resuming attempt K of N (interrupted at X mm)` on stderr. Another run's
//!   record (spec hash, engine and version, mesh, steps), an unreadable one, one whose
//!   attempts all failed, or `--force`: the folder is cleared and attempt 1 starts, with
//!   the reason on stderr.
//!
//! A pose is up to date, and skipped, when its CSV exists with `steps + 1` rows and its
//! manifest entry has the spec hash of the current run ([`Campaign::run_hash`] of the
//! spec with the `--steps` override applied, the pose and the mesh level). A rerun
//! (stale spec, `--force`) leaves the earlier CSV and its entry alone until it succeeds:
//! then the new CSV is renamed over the old one and the new entry replaces the old. A
//! failed or interrupted rerun therefore keeps the earlier result usable. Killed between
//! the two renames, the new CSV sits beside the old entry: with a stale spec the entry's
//! hash is not the current one and the pose is rerun; with `--force` both come from the
//! same spec.
//!
//! A run that fails (solver error, no convergence, timeout) or stalls (no output for
//! [`RunOptions::stall`]: ccx 2.20 was seen spinning without output at the start of a
//! step, deterministically, e.g. theta_z = 15 degrees at 5.4 mm) is rerun with every load
//! step starting at [`RETRY_FIRST_INCREMENT`](crate::backend::RETRY_FIRST_INCREMENT) of the step instead of the whole step,
//! up to the engine's [`Backend::attempts`] in all (ccx: one retry; FEBio: four, decided
//! by its ladder, `febio/ladder.rs`: a retry may continue the furthest attempt from its
//! last converged must point). The manifest entry records it (`first_increment`,
//! `retry`, `solver_settings`). Only when the last attempt fails too is the pose failed.
//!
//! The pieces: [`backend`](crate::backend) solves one pose, [`manifest`](crate::manifest)
//! records how each CSV was made, [`report`](crate::report) is the outcome and
//! `progress` the display.

use crate::backend::{Backend, Job, SolveFailure, Solved};
use crate::engines::backend_for;
use crate::manifest::{manifest_text, read_manifest, rfc3339_utc, Launched, Manifest, ManifestEntry, MANIFEST};
use crate::mesh_summary;
use crate::partial;
use crate::process;
use crate::progress::Progress;
use crate::report::{PoseReport, Report, Status};
use crate::results::{self, Row};
use crate::resume;
use crate::spec::{self, Campaign, Engine, MeshLevel, PoseSpec};
use anyhow::{bail, Context, Result};
use needle_contract::COMPONENT_COUNT;
use std::collections::BTreeMap;
use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::sync::{mpsc, Mutex};
use std::time::{Duration, Instant, SystemTime};

/// What `needle fe run` was asked to do.
#[derive(Debug, Clone)]
pub struct RunOptions {
    /// The set folder, holding `campaign.toml`.
    pub set_dir: PathBuf,
    /// Number of solver jobs run at the same time; 0 counts as 1.
    pub jobs: usize,
    /// Solver threads per job (FEBio: OpenMP threads of Pardiso and the assembly; ccx
    /// always runs on one); 0 counts as 1.
    pub threads: usize,
    /// The engine instead of the spec's `[solver] engine`; part of the spec hash.
    pub solver: Option<Engine>,
    /// Keep the work folder of a successful run too (inputs and solver logs, for study).
    pub keep_work: bool,
    /// Glob over pose names (`*`, `?`, `[..]`); `None`: every pose.
    pub only: Option<String>,
    /// Mesh level; `None`: `campaign.mesh` of the spec.
    pub mesh: Option<String>,
    /// Number of load steps instead of `loading.steps` (smoke runs); part of the hash.
    pub steps: Option<u32>,
    /// Output folder; `None`: `<set_dir>/fe`.
    pub out_dir: Option<PathBuf>,
    /// Solve every selected pose, even when its result is up to date.
    pub force: bool,
    /// Wall-clock limit of one solver attempt (FEBio or ccx); the attempt is killed and counted failed after it.
    pub timeout: Option<Duration>,
    /// A solver job that writes no output for this long is killed as stalled (then retried).
    pub stall: Option<Duration>,
    /// How this process was started, recorded in the manifest entries it writes.
    pub launcher: Launched,
    /// The deep runs of `[deep]` (`crate::deep`): its depth, steps, mesh level and poses
    /// (`only` then selects among them), output in `<set>/fe/deep/` unless `out_dir`.
    pub deep: bool,
    /// Every Ogden mu_i times this factor (the bulk modulus follows): the scaling check of
    /// `needle fe verify --scaling`. Part of the run hash through the tissue; needs `out_dir`
    /// (scaled runs never go into `<set>/fe/`).
    pub tissue_scale: Option<f64>,
    /// `needle.tip_edge_radius_mm` set to this, mm: the edge study of `needle fe verify
    /// --edge` (`campaign.edge_study_radii_mm`). Part of the run hash through the needle;
    /// needs `out_dir` (these runs never go into `<set>/fe/`).
    pub edge_radius_mm: Option<f64>,
    /// The ramp-and-hold runs of `[viscoelastic]` at this speed, mm/s (`crate::visco`):
    /// its poses, mesh and Prony series, `--steps` must points on the ramp, output in
    /// `<set>/fe/visco/` unless `out_dir`.
    pub visco_speed_mm_per_s: Option<f64>,
    /// The ramp-and-hold runs (with `visco_speed_mm_per_s`) are the frictionless ones of
    /// `[viscoelastic] frictionless` (`<run>_mu0`); without a speed, their elastic
    /// companions (`<pose>_mu0`, friction 0, in `<set>/fe/visco/`).
    pub visco_frictionless: bool,
    /// Every speed of `[viscoelastic]` is meant (the CLI's `--visco`: one run of the
    /// campaign per speed, each with `visco_speed_mm_per_s`); not read by [`run`].
    pub visco: bool,
}

impl RunOptions {
    /// Options for the whole campaign of `set_dir` with the spec's settings, one job.
    pub fn new(set_dir: impl Into<PathBuf>) -> Self {
        RunOptions {
            set_dir: set_dir.into(),
            jobs: 1,
            threads: 1,
            solver: None,
            keep_work: false,
            only: None,
            mesh: None,
            steps: None,
            out_dir: None,
            force: false,
            timeout: None,
            stall: Some(DEFAULT_STALL),
            launcher: Launched::Local,
            deep: false,
            tissue_scale: None,
            edge_radius_mm: None,
            visco_speed_mm_per_s: None,
            visco_frictionless: false,
            visco: false,
        }
    }
}

/// Default [`RunOptions::stall`]: ccx writes its log in 4 KiB blocks, a few Newton
/// iterations each (an iteration takes seconds on the committed mesh); ten minutes of
/// silence is not progress.
pub const DEFAULT_STALL: Duration = Duration::from_secs(600);

/// Run the campaign on its engine (`opts.solver`, else the spec's `[solver] engine`).
/// See the module docs.
///
/// # Errors
/// The spec cannot be loaded or is invalid, the tissue fails the material check,
/// `--mesh` names no level, `--only` matches no pose or is not a glob, `--steps 0`,
/// ccx is missing, the manifest is corrupt or the output folder cannot be written.
/// Failed solves are not errors: they are in the [`Report`].
pub fn run(opts: &RunOptions) -> Result<Report> {
    // the spec is read once, by the plan; its engine (with `opts.solver` applied) picks
    // the backend
    let plan = plan(opts)?;
    let engine = plan.campaign.solver.engine;
    run_planned(opts, plan, backend_for(engine, opts.threads).as_mut())
}

/// Everything shared by the workers.
struct Ctx<'a> {
    campaign: &'a Campaign,
    mesh_name: &'a str,
    mesh: &'a MeshLevel,
    steps: u32,
    out_dir: &'a Path,
    timeout: Option<Duration>,
    stall: Option<Duration>,
    backend: &'a dyn Backend,
    solver_version: String,
    manifest_lock: Mutex<()>,
    keep_work: bool,
    /// `--force`: a pose's progress record is not resumed.
    force: bool,
    launcher: &'a Launched,
}

/// What a campaign run will do, worked out before anything is solved or submitted:
/// the spec (with the `--solver` and `--steps` overrides applied), the mesh level, the
/// output folder and, per selected pose, whether its result is up to date. Shared by the
/// local run ([`run_with`]), the SLURM submission
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
    /// manifest's figures) or a placeholder for the poses in `to_run`.
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
}

/// Work out what `opts` asks for without changing any file: load and check the spec, pick
/// the mesh level and the poses, read the manifest, and sort the poses into up to date
/// and to solve (module docs).
///
/// # Errors
/// As [`run`], except solver problems (nothing is solved here).
pub fn plan(opts: &RunOptions) -> Result<Plan> {
    let (mut campaign, spec_path) = spec::load(&opts.set_dir)?;
    let stability = crate::material::check(&campaign.tissue)
        .with_context(|| format!("{}: the tissue fails the material stability check; nothing was run", spec_path.display()))?;
    eprintln!("material check passed: {}", stability.to_string().replace('\n', "\n  "));
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
        match (entry, rows) {
            (Some(e), Some(rows)) if !opts.force => {
                report.wall_s = Some(e.wall_s);
                report.increments = Some(e.increments);
                report.fy_final_n = rows.last().map(Row::fy_n);
            }
            _ => to_run.push(reports.len()),
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
                let friction = if opts.visco_frictionless { crate::visco::Friction::None } else { crate::visco::Friction::Campaign };
                crate::visco::apply(campaign, &v, speed, campaign.loading.steps, friction)
            }
            None => crate::visco::apply_frictionless_elastic(campaign, &v).with_context(|| {
                format!("{}: the frictionless elastic companions: [viscoelastic] frictionless is not set", spec_path.display())
            })?,
        };
        *campaign = run;
        return Ok(Variant { mesh: v.mesh, poses: Some(poses), out_dir: opts.set_dir.join("fe").join(crate::visco::VISCO_DIR) });
    }
    if let Some(s) = opts.tissue_scale {
        if !(s.is_finite() && s > 0.0) || opts.out_dir.is_none() {
            bail!("tissue scale {s}: must be finite and > 0, with its own output folder (never <set>/fe)");
        }
        campaign.tissue.mu_n_per_mm2.iter_mut().for_each(|mu| *mu *= s);
    }
    if let Some(r) = opts.edge_radius_mm {
        if !campaign.needle.fits_edge_radius(r) || opts.out_dir.is_none() {
            bail!("edge radius {r} mm: must be > 0 and below the needle's radius, with its own output folder (never <set>/fe)");
        }
        campaign.needle.tip_edge_radius_mm = r;
    }
    Ok(v)
}

/// [`run`] with a given solver backend (tests use a fake one).
///
/// # Errors
/// As [`run`].
pub fn run_with(opts: &RunOptions, backend: &mut dyn Backend) -> Result<Report> {
    run_planned(opts, plan(opts)?, backend)
}

/// [`run_with`] of a plan already made for `opts`.
fn run_planned(opts: &RunOptions, plan: Plan, backend: &mut dyn Backend) -> Result<Report> {
    let start = Instant::now();
    let Plan { campaign, mesh_name, steps, out_dir, mut reports, to_run, selected, all, .. } = plan;
    let mesh = campaign.mesh_level(&mesh_name)?.clone();
    std::fs::create_dir_all(&out_dir).with_context(|| format!("{}: cannot create", out_dir.display()))?;
    let manifest_path = out_dir.join(MANIFEST);
    let manifest = {
        let _lock = lock_manifest(&out_dir)?;
        // read again under the lock: another process may have written it since the plan
        let mut m = read_manifest(&manifest_path)?;
        let recorded = m.record_first_attempts(&campaign, &all, &mesh_name);
        if recorded > 0 {
            results::write_atomic(&manifest_path, manifest_text(&m)?.as_bytes())?;
            eprintln!(
                "recorded the first attempt's hash of {recorded} run(s) solved by their first attempt in {}",
                manifest_path.display()
            );
        }
        m
    };
    let to_run: Vec<(usize, &PoseSpec)> = to_run.iter().filter_map(|&i| selected.get(i).map(|p| (i, p))).collect();
    let skipped = reports.len() - to_run.len();
    let jobs = opts.jobs.clamp(1, to_run.len().max(1));
    eprintln!(
        "needle fe run: {} pose(s) selected; skipped {skipped} up to date; {} to run with {jobs} job(s) (mesh {mesh_name}, {steps} steps to {} mm) -> {}",
        reports.len(),
        to_run.len(),
        campaign.loading.depth_mm,
        out_dir.display()
    );
    if !to_run.is_empty() {
        let solver_version = backend.prepare()?;
        let backend: &dyn Backend = backend;
        let ctx = Ctx {
            campaign: &campaign,
            mesh_name: &mesh_name,
            mesh: &mesh,
            steps,
            out_dir: &out_dir,
            timeout: opts.timeout,
            stall: opts.stall,
            backend,
            solver_version,
            manifest_lock: Mutex::new(()),
            keep_work: opts.keep_work,
            force: opts.force,
            launcher: &opts.launcher,
        };
        let earlier_walls_s = manifest.wall_times_s(ctx.campaign.solver.engine.name(), &mesh_name, steps);
        run_workers(&ctx, &to_run, jobs, earlier_walls_s, &mut reports);
    }
    Ok(Report { poses: reports, mesh: mesh_name, steps, depth_mm: campaign.loading.depth_mm, out_dir, wall: start.elapsed() })
}

/// Name of the lock file beside the manifest: campaigns in other processes (SLURM array
/// tasks on other nodes, a second `needle fe run`) update the same manifest.
pub const MANIFEST_LOCK: &str = "manifest.toml.lock";

/// Hold an exclusive lock on `<out_dir>/manifest.toml.lock` (`flock`; on a shared
/// filesystem it needs the filesystem's lock support, which NFSv4 and Lustre give) for
/// the read-change-write of the manifest. Released when the returned file is dropped.
///
/// # Errors
/// The lock file cannot be created or locked.
pub fn lock_manifest(out_dir: &Path) -> Result<std::fs::File> {
    let path = out_dir.join(MANIFEST_LOCK);
    let f = std::fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(&path)
        .with_context(|| format!("{}: cannot create the manifest's lock file", path.display()))?;
    f.lock().with_context(|| format!("{}: cannot lock", path.display()))?;
    Ok(f)
}

enum Event {
    Started(usize),
    Finished(usize, PoseReport),
}

/// Solve `to_run` (report index, pose) with `jobs` worker threads, filling `reports`.
/// `earlier_walls_s`: the manifest's measured wall times by model, for the ETA.
fn run_workers(
    ctx: &Ctx<'_>,
    to_run: &[(usize, &PoseSpec)],
    jobs: usize,
    earlier_walls_s: BTreeMap<String, Vec<f64>>,
    reports: &mut [PoseReport],
) {
    let queue: Mutex<VecDeque<usize>> = Mutex::new((0..to_run.len()).collect());
    let (tx, rx) = mpsc::channel::<Event>();
    let runs = to_run.iter().map(|(_, p)| (p.name.clone(), mesh_summary::model_name(p.symmetry()).to_string())).collect();
    let mut progress = Progress::new(runs, ctx.steps, jobs, earlier_walls_s);
    std::thread::scope(|s| {
        for _ in 0..jobs {
            let tx = tx.clone();
            let queue = &queue;
            s.spawn(move || loop {
                if process::interrupted() {
                    break;
                }
                let next = queue.lock().map(|mut q| q.pop_front()).unwrap_or(None);
                let Some(i) = next else { break };
                let Some(&(_, pose)) = to_run.get(i) else { break };
                if tx.send(Event::Started(i)).is_err() {
                    break;
                }
                let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| solve_pose(ctx, pose))).unwrap_or_else(|panic| {
                    let what = panic
                        .downcast_ref::<String>()
                        .cloned()
                        .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                        .unwrap_or_default();
                    failed_report(pose, ctx, format!("panic while solving: {what}"), String::new())
                });
                if tx.send(Event::Finished(i, r)).is_err() {
                    break;
                }
            });
        }
        drop(tx);
        loop {
            match rx.recv_timeout(Duration::from_millis(500)) {
                Ok(Event::Started(i)) => progress.started(i),
                Ok(Event::Finished(i, r)) => {
                    progress.finished(i, &r);
                    if let Some(dst) = to_run.get(i).and_then(|&(slot, _)| reports.get_mut(slot)) {
                        *dst = r;
                    }
                }
                Err(mpsc::RecvTimeoutError::Timeout) => {}
                Err(mpsc::RecvTimeoutError::Disconnected) => break,
            }
            progress.tick(|i| to_run.get(i).map(|(_, p)| ctx.backend.steps_done(&work_dir(ctx.out_dir, &p.name))).unwrap_or(0));
        }
    });
    progress.finish();
}

/// `<out_dir>/.work/<pose>/`
fn work_dir(out_dir: &Path, pose: &str) -> PathBuf {
    out_dir.join(".work").join(pose)
}

fn failed_report(pose: &PoseSpec, ctx: &Ctx<'_>, message: String, log_tail: String) -> PoseReport {
    PoseReport {
        pose: pose.name.clone(),
        status: Status::Failed { message, log_tail },
        wall_s: None,
        increments: None,
        fy_final_n: None,
        work_dir: Some(work_dir(ctx.out_dir, &pose.name)),
    }
}

/// Solve one pose and write its results; never returns an error, a failure is a report.
fn solve_pose(ctx: &Ctx<'_>, pose: &PoseSpec) -> PoseReport {
    let start = Instant::now();
    let wd = work_dir(ctx.out_dir, &pose.name);
    let fail = |message: String, log_tail: String| failed_report(pose, ctx, message, log_tail);
    let run = resume::Identity {
        spec_hash: ctx.campaign.run_hash(pose, ctx.mesh_name),
        engine: ctx.backend.engine().to_string(),
        engine_version: ctx.solver_version.clone(),
        mesh: ctx.mesh_name.to_string(),
        steps: ctx.steps,
    };
    let attempts = ctx.backend.attempts().max(1);
    let from = match starting_point(ctx, pose, &wd, &run, attempts) {
        Ok(from) => from,
        Err(e) => return fail(format!("{e:#}"), String::new()),
    };
    let job = Job {
        campaign: ctx.campaign,
        pose,
        mesh_name: ctx.mesh_name,
        mesh: ctx.mesh,
        steps: ctx.steps,
        work_dir: &wd,
        timeout: ctx.timeout,
        stall: ctx.stall,
        first_increment: 1.0,
        attempt: 0,
    };
    // the furthest failed attempt so far is kept as the pose's partial record at once, so
    // that it is there while the later attempts run
    let mut keep = |reached: &[[f64; COMPONENT_COUNT]], failure: &str| {
        let failed = partial::Failed {
            campaign: ctx.campaign,
            pose,
            mesh: ctx.mesh_name,
            engine: (ctx.backend.engine(), &ctx.solver_version),
            failure,
        };
        match partial::write(ctx.out_dir, &failed, reached) {
            Ok(()) => format!(" (the {} must point(s) reached are kept in {}.partial.csv)", reached.len(), pose.name),
            Err(e) => format!(" (the partial record could not be written: {e:#})"),
        }
    };
    // a record that cannot be written costs the resumability only, not the run
    let mut record = |at: &resume::Start| {
        if let Err(e) = resume::write(&wd, &run, attempts, at) {
            eprintln!("{}: {e:#} (an interruption would restart this pose from attempt 1)", pose.name);
        }
    };
    let solved = match solve_with_retry(ctx.backend, &job, from, &mut keep, &mut record) {
        // solved: nothing to resume, even if its results cannot be written below
        Ok(s) => {
            resume::remove(&wd);
            s
        }
        Err(f) => {
            let kept = if f.reached.is_empty() { String::new() } else { keep(&f.reached, &f.message) };
            return fail(format!("{}{kept}", f.message), f.log_tail);
        }
    };
    let wall_s = (start.elapsed().as_secs_f64() * 1000.0).round() / 1000.0;
    match write_results(ctx, pose, &solved, wall_s) {
        Ok(fy) => {
            partial::remove(ctx.out_dir, &pose.name);
            // the work folder is only for debugging failed runs; a leftover is harmless
            if !ctx.keep_work {
                let _ = std::fs::remove_dir_all(&wd);
            }
            PoseReport {
                pose: pose.name.clone(),
                status: Status::Done,
                wall_s: Some(wall_s),
                increments: Some(solved.increments),
                fy_final_n: Some(fy),
                work_dir: None,
            }
        }
        Err(e) => fail(format!("{e:#}"), String::new()),
    }
}

/// Where `pose` starts: an interrupted run of the same pose resumes at its attempt
/// ([`resume`]); anything else starts afresh in an empty work folder `wd`. The earlier
/// result and its entry stay until the new ones replace them: a failed or interrupted
/// rerun (`--force`) costs nothing (module docs).
///
/// # Errors
/// The work folder cannot be cleared or made.
fn starting_point(ctx: &Ctx<'_>, pose: &PoseSpec, wd: &Path, run: &resume::Identity, attempts: u32) -> Result<resume::Start> {
    let decision = if wd.exists() { resume::decide(wd, run, attempts, ctx.force) } else { resume::Decision::Fresh(None) };
    match decision {
        resume::Decision::Resume(start) => {
            let reached = ctx.backend.steps_done(wd);
            eprintln!(
                "{}: resuming attempt {} of {attempts} (interrupted at {} mm)",
                pose.name,
                start.attempt + 1,
                ctx.campaign.loading.depth_at(reached.min(ctx.steps))
            );
            Ok(start)
        }
        resume::Decision::Fresh(why) => {
            if let Some(why) = why {
                eprintln!("{}: starting afresh: {why}", pose.name);
            }
            if wd.exists() {
                std::fs::remove_dir_all(wd).with_context(|| format!("{}: cannot clear", wd.display()))?;
            }
            std::fs::create_dir_all(wd).with_context(|| format!("{}: cannot create", wd.display()))?;
            Ok(resume::Start::default())
        }
    }
}

/// Solve `job`; when that fails, again with [`RETRY_FIRST_INCREMENT`](crate::backend::RETRY_FIRST_INCREMENT), up to the
/// backend's [`Backend::attempts`] (module docs), starting at `start` (attempt 0 with no
/// failures, or where an interrupted run was: [`resume`]). The failures so far go into
/// the result's `retry` (or the final failure's message). `keep` gets the must points of
/// each failed attempt that reached further than the ones before, with the failures so
/// far (the final failure carries the furthest in `reached`). `record` gets where the
/// pose stands at the start of each attempt and after each failed one (the attempt to
/// run next; `attempts` once all failed).
pub(crate) fn solve_with_retry(
    backend: &dyn Backend,
    job: &Job<'_>,
    start: resume::Start,
    keep: &mut dyn FnMut(&[[f64; COMPONENT_COUNT]], &str) -> String,
    record: &mut dyn FnMut(&resume::Start),
) -> std::result::Result<Solved, SolveFailure> {
    let resume::Start { attempt: first, mut failures, mut furthest } = start;
    let attempts = backend.attempts().max(1);
    let sym = job.pose.symmetry();
    let full_block = !sym.plane_x && !sym.plane_z;
    for attempt in first..attempts {
        let r = backend.first_increment_in(job.work_dir, attempt, full_block);
        let this = Job { first_increment: r, attempt, ..*job };
        record(&resume::Start { attempt, failures: failures.clone(), furthest: furthest.clone() });
        match backend.solve(&this) {
            Ok(s) => return Ok(Solved { retry: (!failures.is_empty()).then(|| failures.join("; ")), ..s }),
            Err(f) => {
                let message = if attempt == 0 { f.message } else { format!("retry {attempt} (first increment {r}): {}", f.message) };
                failures.push(message);
                if f.reached.len() > furthest.len() {
                    furthest = f.reached;
                    if attempt + 1 < attempts {
                        let _ = keep(&furthest, &failures.join("; "));
                    }
                }
                // an interrupted attempt (Ctrl-C) is not finished: a rerun runs it again
                if !process::interrupted() {
                    record(&resume::Start { attempt: attempt + 1, failures: failures.clone(), furthest: furthest.clone() });
                }
                if attempt + 1 == attempts || process::interrupted() {
                    return Err(SolveFailure { message: failures.join("; "), log_tail: f.log_tail, reached: furthest });
                }
                eprintln!(
                    "{}: {}; retry {} of {} {}",
                    job.pose.name,
                    failures.last().map(String::as_str).unwrap_or_default(),
                    attempt + 1,
                    attempts - 1,
                    backend.describe_attempt(job.work_dir, attempt + 1, full_block, job.campaign.loading.depth_mm, job.steps)
                );
            }
        }
    }
    Err(SolveFailure { message: failures.join("; "), log_tail: String::new(), reached: furthest })
}

/// Why training pose `r.pose` was replaced: the spec's words, then the record of its
/// furthest failed attempt (`<out>/<pose>.partial.toml`) when there is one.
fn replaced_because(out_dir: &Path, r: &crate::spec::TrainReplacement) -> String {
    let (_, record) = crate::partial::paths(out_dir, &r.pose);
    let partial = std::fs::read_to_string(&record).ok().and_then(|t| toml::from_str::<crate::partial::PartialRecord>(&t).ok());
    match partial {
        Some(p) => format!("{} (its record: reached {} mm of {}; {})", r.why, p.reached_depth_mm, p.depth_mm, p.failure),
        None => r.why.clone(),
    }
}

/// Check the wrenches, write the CSV, then the manifest entry. Returns Fy at the final depth.
fn write_results(ctx: &Ctx<'_>, pose: &PoseSpec, s: &Solved, wall_s: f64) -> Result<f64> {
    if s.wrenches.len() != ctx.steps as usize {
        bail!("the solver returned {} wrenches for {} steps", s.wrenches.len(), ctx.steps);
    }
    let mut rows = vec![Row { depth_mm: 0.0, wrench: [0.0; COMPONENT_COUNT] }];
    for (k, w) in (1u32..).zip(&s.wrenches) {
        if w.iter().any(|v| !v.is_finite()) {
            bail!("step {k}: the wrench is not finite: {w:?}");
        }
        rows.push(Row { depth_mm: ctx.campaign.loading.depth_at(k), wrench: *w });
    }
    let csv = ctx.out_dir.join(format!("{}.csv", pose.name));
    let text = match ctx.campaign.loading.ramp_hold {
        Some(_) => results::to_timed_csv(&(0..=ctx.steps).map(|k| ctx.campaign.loading.time_at(k)).collect::<Vec<_>>(), &rows),
        None => results::to_csv(&rows),
    };
    results::write_atomic(&csv, text.as_bytes())?;
    let entry = ManifestEntry {
        spec_hash: ctx.campaign.run_hash(pose, ctx.mesh_name),
        first_attempt_hash: s.retry.is_none().then(|| ctx.campaign.first_attempt_hash(pose, ctx.mesh_name)),
        engine: ctx.backend.engine().to_string(),
        engine_version: ctx.solver_version.clone(),
        element: s.element.clone(),
        solver_settings: s.settings.clone(),
        mesh: ctx.mesh_name.to_string(),
        csv_sha256: Some(results::content_sha256(text.as_bytes())),
        model: s.summary.model.clone(),
        tissue_mesh: s.summary.tissue_mesh.clone(),
        tissue_nodes: s.summary.tissue_nodes as u64,
        tissue_elements: s.summary.tissue_elements as u64,
        needle_nodes: s.summary.needle_nodes as u64,
        needle_elements: s.summary.needle_elements as u64,
        steps: ctx.steps,
        depth_mm: ctx.campaign.loading.depth_mm,
        increments: s.increments,
        iterations: s.iterations,
        wall_s,
        peak_rss_mib: (s.peak_rss_mib > 0.0).then(|| (s.peak_rss_mib * 10.0).round() / 10.0),
        date: rfc3339_utc(SystemTime::now()),
        role: pose.role,
        x_mm: pose.x_mm,
        z_mm: pose.z_mm,
        theta_x_deg: pose.theta_x_deg,
        theta_z_deg: pose.theta_z_deg,
        first_increment: (s.first_increment != 1.0).then_some(s.first_increment),
        retry: s.retry.clone(),
        launcher: Some(ctx.launcher.name().to_string()),
        batch_job: ctx.launcher.batch_job(),
        replaces: ctx.campaign.replaced_by(&pose.name).map(|r| r.pose.clone()),
        replaced_because: ctx.campaign.replaced_by(&pose.name).map(|r| replaced_because(ctx.out_dir, r)),
        viscoelastic: crate::visco::describe(ctx.campaign),
    };
    update_manifest(ctx, |m| {
        m.pose.insert(pose.name.clone(), entry);
    })?;
    Ok(rows.last().map(Row::fy_n).unwrap_or(0.0))
}

/// Read the manifest from disk (another `needle fe run` may have written it), change it,
/// write it back atomically; under the campaign's manifest lock.
fn update_manifest(ctx: &Ctx<'_>, f: impl FnOnce(&mut Manifest)) -> Result<()> {
    let _guard = ctx.manifest_lock.lock().unwrap_or_else(|p| p.into_inner());
    let _lock = lock_manifest(ctx.out_dir)?;
    let path = ctx.out_dir.join(MANIFEST);
    let mut m = read_manifest(&path)?;
    let before = m.clone();
    f(&mut m);
    if m == before && path.exists() {
        return Ok(());
    }
    results::write_atomic(&path, manifest_text(&m)?.as_bytes())
}

#[cfg(test)]
#[path = "campaign_resume_tests.rs"]
mod resume_tests;

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::mesh_summary::MeshSummary;
    use crate::spec::Role;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// A solver that returns a made-up wrench (bookkeeping tests only, no physics), can
    /// fail or panic on one pose, and counts its solves.
    #[derive(Default)]
    pub(crate) struct Fake {
        pub(crate) fail: Option<String>,
        /// Fails this pose's first attempt only (whole-step first increment).
        pub(crate) fail_first: Option<String>,
        pub(crate) panic_on: Option<String>,
        /// Fails this pose on every attempt after the first must point (attempt 2: two).
        pub(crate) fail_reached: Option<String>,
        pub(crate) solves: AtomicUsize,
        pub(crate) prepared: usize,
    }

    impl Backend for Fake {
        fn prepare(&mut self) -> Result<String> {
            self.prepared += 1;
            Ok("fake-1".into())
        }
        fn engine(&self) -> &'static str {
            "fake"
        }
        fn solve(&self, job: &Job<'_>) -> std::result::Result<Solved, SolveFailure> {
            self.solves.fetch_add(1, Ordering::SeqCst);
            assert!(job.work_dir.is_dir(), "work dir exists");
            if job.first_increment == 1.0 {
                let others = std::fs::read_dir(job.work_dir)
                    .map(|d| d.flatten().filter(|e| e.file_name() != resume::RECORD_FILE).count())
                    .unwrap_or(9);
                assert_eq!(others, 0, "work dir is empty but for the progress record");
            }
            // a panic leaves the folder as a killed run does: only the progress record, so
            // that the rerun's resumed first attempt finds it empty too
            if self.panic_on.as_deref() == Some(job.pose.name.as_str()) {
                panic!("fake panic");
            }
            std::fs::write(job.work_dir.join("pose.log"), "fake log\n").map_err(anyhow::Error::from)?;
            if self.fail.as_deref() == Some(job.pose.name.as_str()) {
                return Err(SolveFailure { message: "fake exit code 201".into(), log_tail: "*ERROR fake".into(), reached: Vec::new() });
            }
            if self.fail_reached.as_deref() == Some(job.pose.name.as_str()) {
                let reached = (1..=job.attempt.min(1) + 1).map(|k| [0.0, f64::from(k), 0.0, 0.0, 0.0, 0.0]).collect();
                return Err(SolveFailure { message: format!("fake stop {}", job.attempt), log_tail: String::new(), reached });
            }
            if self.fail_first.as_deref() == Some(job.pose.name.as_str()) && job.first_increment == 1.0 {
                return Err(SolveFailure { message: "fake stall".into(), log_tail: String::new(), reached: Vec::new() });
            }
            let wrenches = (1..=job.steps)
                .map(|k| {
                    let d = job.campaign.loading.depth_at(k);
                    [job.pose.x_mm * d, d * d, job.pose.z_mm, 0.0, 0.0, 0.0]
                })
                .collect();
            let summary = MeshSummary {
                tissue_nodes: 1,
                tissue_elements: 2,
                needle_nodes: 3,
                needle_elements: 4,
                model: "fake".into(),
                tissue_mesh: "fake".into(),
            };
            Ok(Solved {
                wrenches,
                summary,
                increments: job.steps,
                iterations: 2 * job.steps,
                first_increment: job.first_increment,
                retry: None,
                element: "fake".into(),
                settings: "fake".into(),
                peak_rss_mib: 0.0,
            })
        }
        fn steps_done(&self, _work_dir: &Path) -> u32 {
            0
        }
    }

    pub(crate) fn set_dir() -> tempfile::TempDir {
        let d = tempfile::tempdir().expect("tempdir");
        let src = crate::workspace_root().join("coeffs/default/campaign.toml");
        std::fs::copy(&src, d.path().join("campaign.toml")).expect("copy the default spec");
        d
    }

    pub(crate) fn opts(dir: &Path, only: &str, steps: u32) -> RunOptions {
        RunOptions { only: Some(only.into()), steps: Some(steps), mesh: Some("smoke".into()), jobs: 2, ..RunOptions::new(dir) }
    }

    /// Issue 42, item 3: the replacement of a training pose that failed every attempt
    /// records which pose it replaces and why (the spec's words and the partial record).
    #[test]
    fn a_replacement_records_what_it_replaces_and_the_status_counts_the_slots() {
        let d = set_dir();
        let (c, _) = spec::load(d.path()).expect("spec");
        let r = c.campaign.train_replaced.first().expect("the default set replaces a training pose").clone();
        let by = c.replacement_of(&r.pose).expect("its replacement");
        let mut fake = Fake { fail_reached: Some(r.pose.clone()), ..Fake::default() };
        let failed = run_with(&opts(d.path(), &r.pose, 4), &mut fake).expect("run");
        assert_eq!(failed.failed(), 1, "{}", failed.table());
        let solved = run_with(&opts(d.path(), &by, 4), &mut Fake::default()).expect("run");
        assert_eq!(solved.done(), 1, "{}", solved.table());
        let m = read_manifest(&d.path().join("fe").join(MANIFEST)).expect("manifest");
        let e = &m.pose[&by];
        assert_eq!(e.replaces.as_deref(), Some(r.pose.as_str()));
        let because = e.replaced_because.clone().unwrap_or_default();
        assert!(
            because.starts_with(&r.why) && because.contains("its record: reached 3 mm of 6") && because.contains("fake stop"),
            "{because}"
        );
        // the status's counts of the same runs: launcher::status's tests
    }

    #[test]
    fn writes_results_and_skips_up_to_date_poses() {
        let d = set_dir();
        let mut fake = Fake::default();
        let o = opts(d.path(), "x+0[24]", 2);
        let r = run_with(&o, &mut fake).expect("run");
        assert_eq!((r.done(), r.up_to_date(), r.failed()), (2, 0, 0), "{}", r.table());
        let fe = d.path().join("fe");
        for name in ["x+02", "x+04"] {
            let rows = results::read_csv(&fe.join(format!("{name}.csv"))).expect("csv");
            assert_eq!(rows.len(), 3);
            assert_eq!(rows[0], Row { depth_mm: 0.0, wrench: [0.0; COMPONENT_COUNT] });
            assert_eq!(rows.iter().map(|r| r.depth_mm).collect::<Vec<_>>(), [0.0, 3.0, 6.0]);
            assert_eq!(rows[2].wrench[1], 36.0);
            assert!(!fe.join(".work").join(name).exists(), "work dir removed on success");
        }
        let text = std::fs::read_to_string(fe.join(MANIFEST)).expect("manifest");
        let m = read_manifest(&fe.join(MANIFEST)).expect("parse");
        assert_eq!(m.pose.keys().cloned().collect::<Vec<_>>(), ["x+02", "x+04"]);
        assert!(text.find("[pose.\"x+02\"]") < text.find("[pose.\"x+04\"]"), "sorted:\n{text}");
        let (mut c, _) = spec::load(d.path()).expect("spec");
        c.loading.steps = 2;
        let p4 = c.poses().into_iter().find(|p| p.name == "x+04").expect("x+04");
        let e = &m.pose["x+04"];
        assert_eq!(e.spec_hash, c.run_hash(&p4, "smoke"));
        assert_eq!((e.engine_version.as_str(), e.mesh.as_str(), e.steps, e.increments, e.iterations), ("fake-1", "smoke", 2, 2, 4));
        assert_eq!((e.x_mm, e.role), (4.0, Role::SweepX));
        assert_eq!(e.date.len(), "2025-01-01T00:00:00Z".len());
        assert_eq!(fake.solves.load(Ordering::SeqCst), 2);

        // rerun: nothing to do, the solver is not even prepared, files untouched
        let mut again = Fake::default();
        let r = run_with(&o, &mut again).expect("rerun");
        assert_eq!((r.done(), r.up_to_date()), (0, 2));
        assert_eq!((again.prepared, again.solves.load(Ordering::SeqCst)), (0, 0));
        assert_eq!(std::fs::read_to_string(fe.join(MANIFEST)).expect("manifest"), text);
        assert!(r.table().contains("up to date"));
        assert_eq!(r.poses[0].fy_final_n, Some(36.0));

        // another step count is another spec: rerun
        let r = run_with(&opts(d.path(), "x+02", 3), &mut again).expect("steps 3");
        assert_eq!(r.done(), 1);
        assert_eq!(results::read_csv(&fe.join("x+02.csv")).expect("csv").len(), 4);
        // --force reruns an up-to-date pose
        let r = run_with(&RunOptions { force: true, ..opts(d.path(), "x+04", 2) }, &mut again).expect("force");
        assert_eq!(r.done(), 1);
        // a CSV deleted by hand is rerun even though the manifest has its entry
        std::fs::remove_file(fe.join("x+04.csv")).expect("rm");
        let r = run_with(&o, &mut again).expect("missing csv");
        assert_eq!((r.done(), r.up_to_date()), (2, 0), "x+02 has 4 rows (3 steps), x+04 has no CSV");
    }

    /// The bytes of every CSV and the manifest in `fe`.
    fn snapshot(fe: &Path) -> Vec<(String, Vec<u8>)> {
        let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(fe)
            .expect("fe folder")
            .flatten()
            .filter(|e| e.path().is_file())
            .map(|e| (e.file_name().to_string_lossy().into_owned(), std::fs::read(e.path()).expect("read")))
            .collect();
        files.sort();
        files
    }

    /// Issue 18: a solver killed mid-run, an unwritable result file and a corrupted
    /// manifest each leave every earlier result intact, and the next run completes the set.
    #[test]
    fn faults_leave_earlier_results_intact_and_the_next_run_completes_the_set() {
        let d = set_dir();
        let fe = d.path().join("fe");
        run_with(&opts(d.path(), "x+0[24]", 2), &mut Fake::default()).expect("first results");
        let before = snapshot(&fe);
        let all = "x+0[2468]";

        // 1. the solver is killed while solving x+06 (and x+08 in the same run finishes)
        let mut killed = Fake { fail: Some("x+06".into()), ..Fake::default() };
        let r = run_with(&opts(d.path(), all, 2), &mut killed).expect("run");
        assert_eq!((r.done(), r.up_to_date(), r.failed()), (1, 2, 1), "{}", r.table());
        let after: Vec<_> = snapshot(&fe).into_iter().filter(|(n, _)| n != "x+08.csv" && n != MANIFEST).collect();
        assert_eq!(after, before.iter().filter(|(n, _)| n != MANIFEST).cloned().collect::<Vec<_>>(), "earlier CSVs intact");
        let m = read_manifest(&fe.join(MANIFEST)).expect("manifest");
        assert_eq!(m.pose.keys().cloned().collect::<Vec<_>>(), ["x+02", "x+04", "x+08"], "no entry for the killed x+06");

        // 2. x+06's result file cannot be written (a folder is in its place)
        std::fs::create_dir(fe.join("x+06.csv")).expect("block the CSV path");
        let r = run_with(&opts(d.path(), all, 2), &mut Fake::default()).expect("run");
        assert_eq!((r.done(), r.up_to_date(), r.failed()), (0, 3, 1), "{}", r.table());
        assert!(r.table().contains("x+06.csv"), "the failure names the file:\n{}", r.table());
        let intact = snapshot(&fe);
        std::fs::remove_dir(fe.join("x+06.csv")).expect("unblock");

        // 3. the manifest is corrupted: refused before anything is solved or written
        let manifest = fe.join(MANIFEST);
        let good = std::fs::read(&manifest).expect("manifest");
        std::fs::write(&manifest, b"[pose.x+02\nspec_hash = ").expect("corrupt");
        let mut untouched = Fake::default();
        let e = run_with(&opts(d.path(), all, 2), &mut untouched).expect_err("corrupt manifest");
        assert!(format!("{e:#}").contains(MANIFEST), "{e:#}");
        assert_eq!(untouched.solves.load(Ordering::SeqCst), 0);
        std::fs::write(&manifest, &good).expect("restore the manifest (from git, say)");
        assert_eq!(snapshot(&fe), intact, "every result as before the faults");

        // temporaries a killed campaign left beside its targets (a pid that is gone)
        let stale = [fe.join(".x+06.csv.4194303.tmp"), fe.join(format!(".{MANIFEST}.4194303.tmp"))];
        for t in &stale {
            std::fs::write(t, b"half").expect("stale temporary");
        }
        let mut intact = intact;
        intact
            .extend(stale.iter().map(|t| (t.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default(), b"half".to_vec())));
        intact.sort();
        assert_eq!(snapshot(&fe), intact);

        // the next run completes the set, solving only x+06, and removes the temporaries
        let mut last = Fake::default();
        let r = run_with(&opts(d.path(), all, 2), &mut last).expect("run");
        assert_eq!((r.done(), r.up_to_date(), r.failed()), (1, 3, 0), "{}", r.table());
        assert_eq!(last.solves.load(Ordering::SeqCst), 1);
        assert!(stale.iter().all(|t| !t.exists()), "stale temporaries removed");
        for (name, bytes) in &before {
            if name != MANIFEST {
                assert_eq!(&std::fs::read(fe.join(name)).expect("read"), bytes, "{name} unchanged through the faults");
            }
        }
    }

    #[test]
    fn a_failed_pose_keeps_its_work_dir_and_the_others_finish() {
        let d = set_dir();
        let fe = d.path().join("fe");
        // a first, good result of x+04
        run_with(&opts(d.path(), "x+04", 2), &mut Fake::default()).expect("first");
        assert!(fe.join("x+04.csv").exists());

        let mut fake = Fake { fail: Some("x+04".into()), panic_on: Some("x+06".into()), ..Fake::default() };
        let r = run_with(&RunOptions { force: true, ..opts(d.path(), "x+0[246]", 2) }, &mut fake).expect("run");
        assert_eq!((r.done(), r.failed()), (1, 2), "{}", r.table());
        let t = r.table();
        assert!(t.contains("FAILED x+04: fake exit code 201") && t.contains("| *ERROR fake"), "{t}");
        assert!(t.contains("FAILED x+06: panic while solving: fake panic"), "{t}");
        assert!(fe.join(".work/x+04/pose.log").exists(), "work dir kept on failure");
        assert!(!fe.join("x+06.csv").exists());
        // the failed --force rerun cost nothing: x+04's first CSV and its entry are intact
        // (issue 18: the entry used to be deleted, and `needle fit` then refused the set)
        let m = read_manifest(&fe.join(MANIFEST)).expect("manifest");
        assert_eq!(m.pose.keys().cloned().collect::<Vec<_>>(), ["x+02", "x+04"]);
        assert_eq!(results::read_csv(&fe.join("x+04.csv")).expect("csv").len(), 3, "the first result's CSV");
        // so the next run only solves x+06
        let mut ok = Fake::default();
        let r = run_with(&opts(d.path(), "x+0[246]", 2), &mut ok).expect("resume");
        assert_eq!((r.done(), r.up_to_date(), r.failed()), (1, 2, 0), "{}", r.table());
        assert!(fe.join("x+06.csv").exists());
    }

    #[test]
    fn a_failed_run_is_retried_once_with_a_smaller_first_increment_and_the_manifest_says_so() {
        let d = set_dir();
        let mut fake = Fake { fail_first: Some("x+04".into()), ..Fake::default() };
        let r = run_with(&opts(d.path(), "x+0[24]", 2), &mut fake).expect("run");
        assert_eq!((r.done(), r.failed()), (2, 0), "{}", r.table());
        assert_eq!(fake.solves.load(Ordering::SeqCst), 3, "x+02 once, x+04 twice");
        let m = read_manifest(&d.path().join("fe").join(MANIFEST)).expect("manifest");
        let (x2, x4) = (&m.pose["x+02"], &m.pose["x+04"]);
        assert_eq!((x2.first_increment, x2.retry.as_deref()), (None, None));
        assert_eq!((x4.first_increment, x4.retry.as_deref()), (Some(crate::backend::RETRY_FIRST_INCREMENT), Some("fake stall")));
        let text = std::fs::read_to_string(d.path().join("fe").join(MANIFEST)).expect("manifest text");
        assert_eq!(text.matches("first_increment = 0.25").count(), 1, "{text}");
        assert_eq!(text.matches("retry = \"fake stall\"").count(), 1, "{text}");
    }

    /// Issue 42: a run its first attempt solved stays current when only settings of the
    /// retry ladder's later attempts change (`retry_dtol`); a run a retry solved is solved
    /// again; an entry from before the first attempt's hash gets it on the next run.
    #[test]
    fn a_change_of_the_later_attempts_settings_reruns_only_the_runs_they_solved() {
        let d = set_dir();
        let mut fake = Fake { fail_first: Some("x+04".into()), ..Fake::default() };
        let r = run_with(&opts(d.path(), "x+0[24]", 2), &mut fake).expect("run");
        assert_eq!((r.done(), r.failed()), (2, 0), "{}", r.table());
        let path = d.path().join("fe").join(MANIFEST);
        let m = read_manifest(&path).expect("manifest");
        let first = m.pose["x+02"].first_attempt_hash.clone();
        assert!(first.is_some() && m.pose["x+04"].first_attempt_hash.is_none(), "{m:?}");
        // an entry written before the hash existed gets it from the next run
        let mut old = m.clone();
        if let Some(e) = old.pose.get_mut("x+02") {
            e.first_attempt_hash = None;
        }
        std::fs::write(&path, manifest_text(&old).expect("text")).expect("write");
        let r = run_with(&opts(d.path(), "x+04", 2), &mut Fake::default()).expect("run");
        assert_eq!(r.up_to_date(), 1, "{}", r.table());
        assert_eq!(read_manifest(&path).expect("manifest").pose["x+02"].first_attempt_hash, first);
        // the retry's displacement tolerance changes: x+04 (solved by the retry) is stale
        let spec_path = d.path().join("campaign.toml");
        let text = std::fs::read_to_string(&spec_path).expect("spec");
        assert!(text.contains("[solver.febio]\n") && !text.contains("\nretry_dtol"), "the default set's [solver.febio]");
        std::fs::write(&spec_path, text.replacen("[solver.febio]\n", "[solver.febio]\nretry_dtol = 0.0005\n", 1)).expect("write");
        let mut fake = Fake::default();
        let r = run_with(&opts(d.path(), "x+0[24]", 2), &mut fake).expect("run");
        assert_eq!((r.done(), r.up_to_date()), (1, 1), "{}", r.table());
        assert_eq!(fake.solves.load(Ordering::SeqCst), 1, "x+04 only");
        let m = read_manifest(&path).expect("manifest");
        assert_eq!(m.pose["x+02"].first_attempt_hash, first, "x+02 kept");
        assert!(m.pose["x+04"].first_attempt_hash.is_some(), "x+04 solved again, by its first attempt now");
    }

    /// `--deep`: the [deep] poses only, to the deep depth, into fe/deep/ with its own
    /// manifest; the shallow results are not touched.
    #[test]
    fn deep_runs_go_to_their_own_folder_at_the_deep_depth() {
        let d = set_dir();
        let deep = |only: &str| RunOptions {
            deep: true,
            only: Some(only.into()),
            mesh: Some("smoke".into()),
            steps: Some(5),
            ..RunOptions::new(d.path())
        };
        let (c, _) = spec::load(d.path()).expect("spec");
        let depth_mm = c.deep.as_ref().map(|d| d.depth_mm).expect("a [deep] section");
        let r = run_with(&deep("centre"), &mut Fake::default()).expect("deep run");
        assert_eq!((r.done(), r.depth_mm), (1, depth_mm), "{}", r.table());
        let rows = results::read_csv(&d.path().join("fe/deep/centre.csv")).expect("deep csv");
        let want: Vec<f64> = (0..=5).map(|k| depth_mm * f64::from(k) / 5.0).collect();
        assert_eq!(rows.iter().map(|r| r.depth_mm).collect::<Vec<_>>(), want);
        assert_eq!(rows[5].wrench[1], depth_mm * depth_mm, "the fake's depth squared at the deep depth");
        assert!(!d.path().join("fe/centre.csv").exists(), "nothing written beside the shallow runs");
        let m = read_manifest(&d.path().join("fe/deep").join(MANIFEST)).expect("deep manifest");
        assert_eq!((m.pose["centre"].depth_mm, m.pose["centre"].steps), (depth_mm, 5));
        let again = run_with(&deep("centre"), &mut Fake::default()).expect("rerun");
        assert_eq!(again.up_to_date(), 1, "resumes like the campaign");
        let e = run_with(&deep("x+02"), &mut Fake::default()).err().map(|e| e.to_string()).unwrap_or_default();
        assert!(e.contains("matches no pose (poses: centre, x+04, tz+08, z+04)"), "{e}");
    }

    /// A pose that fails every attempt keeps the furthest attempt's must points as its
    /// partial record; solving it later removes the record.
    #[test]
    fn a_pose_failing_every_attempt_keeps_its_furthest_must_points() {
        let d = set_dir();
        let fe = d.path().join("fe");
        let mut fake = Fake { fail_reached: Some("x+04".into()), ..Fake::default() };
        let r = run_with(&opts(d.path(), "x+04", 4), &mut fake).expect("run");
        assert_eq!(r.failed(), 1, "{}", r.table());
        assert!(r.table().contains("the 2 must point(s) reached are kept in x+04.partial.csv"), "{}", r.table());
        let (csv, rec) = partial::paths(&fe, "x+04");
        let rows = results::read_csv(&csv).expect("partial csv");
        assert_eq!(rows.iter().map(|r| (r.depth_mm, r.fy_n())).collect::<Vec<_>>(), [(0.0, 0.0), (1.5, 1.0), (3.0, 2.0)]);
        let text = std::fs::read_to_string(&rec).expect("record");
        assert!(text.contains("reached_depth_mm = 3.0") && text.contains("fake stop 0; retry 1"), "{text}");
        assert!(!fe.join("x+04.csv").exists(), "no result");
        let r = run_with(&opts(d.path(), "x+04", 4), &mut Fake::default()).expect("solved");
        assert_eq!(r.done(), 1);
        assert!(!csv.exists() && !rec.exists(), "the record goes once the pose solves");
    }

    #[test]
    fn refuses_bad_options_and_a_corrupt_manifest_before_solving() {
        let d = set_dir();
        let mut fake = Fake::default();
        let e = run_with(&opts(d.path(), "nothing*", 2), &mut fake).expect_err("no pose").to_string();
        assert!(e.contains("matches no pose"), "{e}");
        let e = run_with(&RunOptions { mesh: Some("huge".into()), ..opts(d.path(), "x+02", 2) }, &mut fake).expect_err("mesh").to_string();
        assert!(e.contains("huge"), "{e}");
        let e = run_with(&opts(d.path(), "x+02", 0), &mut fake).expect_err("steps").to_string();
        assert!(e.contains("--steps 0"), "{e}");
        std::fs::create_dir_all(d.path().join("fe")).expect("mkdir");
        std::fs::write(d.path().join("fe").join(MANIFEST), "[pose.x]\nspec_hash = 1\n").expect("write");
        let e = run_with(&opts(d.path(), "x+02", 2), &mut fake).expect_err("manifest").to_string();
        assert!(e.contains("delete it"), "{e}");
        assert_eq!((fake.prepared, fake.solves.load(Ordering::SeqCst)), (0, 0));
    }
}
