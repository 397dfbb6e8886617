//! The FE campaign driver behind `needle fe run`: select the poses, skip the ones whose
//! result is up to date, solve the others in parallel on the set's engine (a
//! [`Backend`]: FEBio or CalculiX; `jobs` at once, `threads` solver threads each), write
//! `fe/<pose>.csv` and the manifest atomically, and report.
//!
//! Files, in the output folder (default `<set>/fe/`):
//! - `<pose>.csv`: the wrench at `steps + 1` depths (format: coeffs/README.md). Written
//!   with [`needle_stdx::fs::write_atomic`]: a killed run never leaves a half-written CSV.
//! - `manifest.toml`: one table per finished pose (see [`ManifestEntry`](crate::manifest::ManifestEntry)), sorted by
//!   pose name, rewritten atomically after each pose.
//! - `manifest.toml.lock`: the lock ([`lock_manifest`]) under which every process
//!   (this one's jobs, SLURM array tasks, another `needle fe run`) rewrites the manifest.
//! - `.work/<pose>/`: the solver's input and files of a run; removed when the run
//!   succeeds (unless `keep_work`), kept for debugging when it fails. Its
//!   `progress.toml` ([`resume`](crate::resume)) records the attempt running, the finished attempts'
//!   failures and the furthest must points: a run killed in the middle of a pose (a
//!   session's end) resumes on the rerun at the attempt it was in, which the engine
//!   continues from its last dump (FEBio) or reruns from its start (ccx), with
//!   `<pose>: resuming attempt K of N (interrupted at X mm)` on stderr. Another run's
//!   record (spec hash, engine and version, mesh, steps), an unreadable one, one whose
//!   attempts all failed, or `--force`: the folder is cleared and attempt 1 starts, with
//!   the reason on stderr. With `skip_failed` a record of exactly this run whose
//!   attempts all failed is not run again (a solver that does not converge fails the
//!   same way on the same spec; a campaign resumed session after session would spend the
//!   attempts' hours each time): the pose is reported failed with the recorded failures
//!   and its folder stays.
//!
//! A pose is up to date, and skipped, when its CSV exists with `steps + 1` rows and its
//! manifest entry has the spec hash of the current run ([`Campaign::run_hash`] of the
//! spec with the `--steps` override applied, the pose and the mesh level), unless its
//! work folder holds the record of an interrupted `--force` rerun of that same run
//! ([`crate::resume::unfinished`]): then the rerun resumes it. A rerun
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

mod plan;
pub mod runs;
mod solve;

pub use plan::{plan, Plan};
use solve::{failed_report, solve_pose, work_dir};

use crate::backend::Backend;
use crate::engines::backend_for;
use crate::manifest::{manifest_text, read_manifest, Launched, MANIFEST};
use crate::mesh::summary as mesh_summary;
use crate::process;
use crate::progress_bar::Progress;
use crate::report::{PoseReport, Report};
use crate::set_folder::SetFolder;
use crate::spec::{Campaign, Engine, MeshLevel, PoseSpec};
use anyhow::{Context, Result};
use std::collections::BTreeMap;
use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::sync::{mpsc, Mutex};
use std::time::{Duration, Instant};

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
    /// Do not run again a pose whose attempts all failed with exactly this run (its
    /// progress record says so): report it failed with the recorded failures.
    pub skip_failed: bool,
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
    /// One run of the material family of `[family]` (`crate::family`): the member's tissue,
    /// its poses, depth and mesh, output in `<set>/fe/family/` unless `out_dir`.
    pub family_run: Option<crate::family::FamilyRun>,
    /// Every run of `[family]` is meant (the CLI's `--family`: one campaign run each, with
    /// `family_run`); not read by [`run`].
    pub family: bool,
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
            skip_failed: false,
            timeout: None,
            stall: Some(DEFAULT_STALL),
            launcher: Launched::Local,
            deep: false,
            tissue_scale: None,
            edge_radius_mm: None,
            visco_speed_mm_per_s: None,
            visco_frictionless: false,
            visco: false,
            family_run: None,
            family: false,
        }
    }
}

/// Default [`RunOptions::stall`]: ccx writes its log in 4 KiB blocks, a few Newton
/// iterations each (an iteration takes seconds on the committed mesh); ten minutes of
/// silence is not progress.
pub const DEFAULT_STALL: Duration = Duration::from_secs(600);

/// Run the campaign of the set `set` (opened once by the caller; `opts.set_dir` is its
/// folder) on its engine (`opts.solver`, else the spec's `[solver] engine`). See the
/// module docs.
///
/// # Errors
/// The spec is invalid for the run, `opts.set_dir` is not `set`'s folder, the tissue fails the material check,
/// `--mesh` names no level, `--only` matches no pose or is not a glob, `--steps 0`,
/// ccx is missing, the manifest is corrupt or the output folder cannot be written.
/// Failed solves are not errors: they are in the [`Report`].
pub fn run(set: &SetFolder, opts: &RunOptions) -> Result<Report> {
    // the spec was read once, when `set` was opened; its engine (with `opts.solver`
    // applied) picks the backend
    let plan = plan(set, opts)?;
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
    /// `--skip-failed` ([`RunOptions::skip_failed`]).
    skip_failed: bool,
    launcher: &'a Launched,
}

/// [`run`] with a given solver backend (tests use a fake one).
///
/// # Errors
/// As [`run`].
pub fn run_with(set: &SetFolder, opts: &RunOptions, backend: &mut dyn Backend) -> Result<Report> {
    run_planned(opts, plan(set, opts)?, backend)
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
            needle_stdx::fs::write_atomic(&manifest_path, manifest_text(&m)?.as_bytes())?;
            needle_stdx::noteln!(
                "recorded the first attempt's hash of {recorded} run(s) solved by their first attempt in {}",
                manifest_path.display()
            );
        }
        m
    };
    let to_run: Vec<(usize, &PoseSpec)> = to_run.iter().filter_map(|&i| selected.get(i).map(|p| (i, p))).collect();
    let skipped = reports.len() - to_run.len();
    let jobs = opts.jobs.clamp(1, to_run.len().max(1));
    needle_stdx::noteln!(
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
            skip_failed: opts.skip_failed,
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

#[cfg(test)]
mod resume_tests;

#[cfg(test)]
pub(crate) mod tests;
