//! The solver side of a campaign: the [`Backend`] trait (one pose in, wrenches out),
//! [`CcxBackend`], which writes the deck, runs CalculiX, reads the `.dat` back and reduces
//! the needle's nodal reactions to the wrench, (the engine of a run: [`engines::backend_for`](crate::engines::backend_for)).
//! FEBio's backend is `fe::febio::FebioBackend`. Tests inject other backends.

use crate::ccx;
use crate::dat;
use crate::deck::{self, MeshSummary};
use crate::spec::{Campaign, MeshLevel, PoseSpec};
use crate::wrench;
use anyhow::{bail, Context, Result};
use needle_contract::COMPONENT_COUNT;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The ccx job name inside a pose's work folder (`pose.inp`, `pose.dat`, `pose.sta`...).
pub const JOB: &str = "pose";

/// One pose to solve, as given to a [`Backend`].
#[derive(Debug, Clone, Copy)]
pub struct Job<'a> {
    /// The spec, with `loading.steps` already set to the steps of this run.
    pub campaign: &'a Campaign,
    /// The pose.
    pub pose: &'a PoseSpec,
    /// Name of the mesh level.
    pub mesh_name: &'a str,
    /// The mesh level.
    pub mesh: &'a MeshLevel,
    /// Load steps (= `campaign.loading.steps`).
    pub steps: u32,
    /// The solver's folder, emptied before a pose's first attempt (the retry reuses it;
    /// a failed attempt's log is kept there as `failed-first-increment-<r>.*`); not
    /// emptied when a killed run resumes in it (`crate::resume`): then it holds what the
    /// interrupted attempt left, which the engine may go on from (FEBio) or ignore.
    pub work_dir: &'a Path,
    /// Wall-clock limit of the solve.
    pub timeout: Option<Duration>,
    /// Output-silence limit of the solve.
    pub stall: Option<Duration>,
    /// First increment of each load step, as a fraction of the step (1 on the first
    /// attempt, [`deck::RETRY_FIRST_INCREMENT`] on the retries).
    pub first_increment: f64,
    /// Which attempt at the pose this is: 0 first, 1 the retry, 2.. further retries of
    /// engines that have them ([`Backend::attempts`]).
    pub attempt: u32,
}

/// A solved pose.
#[derive(Debug, Clone)]
pub struct Solved {
    /// The wrench on the needle about its reference point after each step, `steps`
    /// entries: fx, fy, fz (N), mx, my, mz (N·mm).
    pub wrenches: Vec<[f64; COMPONENT_COUNT]>,
    /// Size of the model.
    pub summary: MeshSummary,
    /// Converged increments.
    pub increments: u32,
    /// Newton iterations.
    pub iterations: u32,
    /// First increment of each step, as a fraction of the step (1: whole step).
    pub first_increment: f64,
    /// Why an earlier attempt failed, when this is the retry.
    pub retry: Option<String>,
    /// The tissue element and formulation, e.g. "C3D8, full integration".
    pub element: String,
    /// The solver settings that shaped the result, one line (contact enforcement,
    /// threads...).
    pub settings: String,
    /// The solver process's peak resident memory, MiB (0: not measured).
    pub peak_rss_mib: f64,
}

/// Why a pose could not be solved.
#[derive(Debug, Clone)]
pub struct SolveFailure {
    /// One line: what failed (exit status, steps done, or the error).
    pub message: String,
    /// The end of the solver's output, if it ran.
    pub log_tail: String,
    /// The wrench at the must points the attempt reached, from step 1 on without a gap
    /// (the campaign keeps the furthest attempt's as the pose's partial record); empty
    /// when the engine does not report them.
    pub reached: Vec<[f64; COMPONENT_COUNT]>,
}

impl From<anyhow::Error> for SolveFailure {
    fn from(e: anyhow::Error) -> Self {
        SolveFailure { message: format!("{e:#}"), log_tail: String::new(), reached: Vec::new() }
    }
}

/// The solver side of a campaign; [`CcxBackend`] is the real one, tests inject others.
pub trait Backend: Sync {
    /// Get ready to solve (find the solver) and return its version. Called once, before
    /// the first solve, and only when there is something to solve.
    ///
    /// # Errors
    /// The solver is missing or unusable: the campaign stops before any solve.
    fn prepare(&mut self) -> Result<String>;

    /// The engine's name as the manifest records it (`ccx`, `febio`).
    fn engine(&self) -> &'static str;

    /// How many attempts a pose gets before it is failed (the first and the retries);
    /// what each attempt changes is the engine's ([`Backend::first_increment`] and the
    /// engine's own settings).
    fn attempts(&self) -> u32 {
        2
    }

    /// The first increment of each load step on `attempt`, as a fraction of the step: the
    /// whole step on the first attempt, [`deck::RETRY_FIRST_INCREMENT`] on the retries.
    fn first_increment(&self, attempt: u32) -> f64 {
        if attempt == 0 {
            1.0
        } else {
            deck::RETRY_FIRST_INCREMENT
        }
    }

    /// The first increment of `attempt` for the pose whose work folder is `work_dir`
    /// (`full_block`: its model has no mirror plane): engines whose ladder depends on
    /// what the earlier attempts left there (FEBio's continuation of the furthest attempt)
    /// decide here; the others as [`Backend::first_increment`].
    fn first_increment_in(&self, work_dir: &Path, attempt: u32, full_block: bool) -> f64 {
        let _ = (work_dir, full_block);
        self.first_increment(attempt)
    }

    /// What `attempt` changes, one phrase for the campaign's log (the insertion:
    /// `depth_mm` in `steps` load steps).
    fn describe_attempt(&self, work_dir: &Path, attempt: u32, full_block: bool, depth_mm: f64, steps: u32) -> String {
        let _ = (depth_mm, steps);
        format!("with each step's first increment at {} of the step", self.first_increment_in(work_dir, attempt, full_block))
    }

    /// Solve one pose in `job.work_dir`.
    ///
    /// # Errors
    /// Any failure of the solve, with the end of the solver's output.
    fn solve(&self, job: &Job<'_>) -> std::result::Result<Solved, SolveFailure>;

    /// Steps completed so far by the job running in `work_dir` (for the progress bar).
    fn steps_done(&self, work_dir: &Path) -> u32;
}

/// The real backend: the project's deck writer, CalculiX, the `.dat` reader and the
/// wrench reduction.
#[derive(Debug, Default)]
pub struct CcxBackend {
    ccx: Option<PathBuf>,
}

impl Backend for CcxBackend {
    fn prepare(&mut self) -> Result<String> {
        let path = ccx::find_ccx()?;
        let version = ccx::ccx_version(&path)?;
        self.ccx = Some(path);
        Ok(version)
    }

    fn engine(&self) -> &'static str {
        "ccx"
    }

    fn solve(&self, job: &Job<'_>) -> std::result::Result<Solved, SolveFailure> {
        let first_increment = job.first_increment;
        let ccx_path = self.ccx.as_deref().context("CcxBackend::solve before prepare")?;
        let deck =
            deck::write_deck_first_increment(job.campaign, job.pose, job.mesh, job.steps, first_increment).context("writing the deck")?;
        if deck.steps != job.steps {
            return Err(anyhow::anyhow!("the deck has {} steps, {} were asked for", deck.steps, job.steps).into());
        }
        let inp = job.work_dir.join(format!("{JOB}.inp"));
        std::fs::write(&inp, &deck.text).with_context(|| format!("{}: cannot write", inp.display()))?;
        let r = ccx::run_job(ccx_path, job.work_dir, JOB, job.timeout, job.stall)?;
        let done = r.sta.steps_done();
        if !r.success() || done < job.steps {
            let how = if r.success() { "finished (exit code 0)".to_string() } else { r.exit.to_string() };
            let kept = keep_failed_attempt(job);
            return Err(SolveFailure {
                message: format!(
                    "ccx {how} after {done} of {} steps, {} increments, {:.1} s{}{kept}",
                    job.steps,
                    r.sta.increments,
                    r.wall.as_secs_f64(),
                    r.cause.as_deref().map(|c| format!(": {c}")).unwrap_or_default(),
                ),
                log_tail: r.log_tail,
                reached: Vec::new(),
            });
        }
        let fail = |e: anyhow::Error| SolveFailure { message: format!("{e:#}"), log_tail: r.log_tail.clone(), reached: Vec::new() };
        let dat_path = job.work_dir.join(format!("{JOB}.dat"));
        let text = std::fs::read_to_string(&dat_path).with_context(|| format!("{}: cannot read", dat_path.display())).map_err(fail)?;
        let blocks = dat::parse_rf(&text, &deck.print_set).with_context(|| format!("{}", dat_path.display())).map_err(fail)?;
        check_step_times(&blocks, job.steps).with_context(|| format!("{}", dat_path.display())).map_err(fail)?;
        let wrenches = blocks
            .iter()
            .enumerate()
            .map(|(k, b)| {
                wrench::reduce(&deck, job.pose, job.campaign, &b.nodes).with_context(|| format!("reducing the reactions of step {}", k + 1))
            })
            .collect::<Result<Vec<_>>>()
            .map_err(fail)?;
        Ok(Solved {
            wrenches,
            summary: deck.summary,
            increments: r.sta.increments,
            iterations: r.sta.iterations,
            first_increment,
            retry: None,
            element: "C3D8 (fully integrated hexahedron)".into(),
            peak_rss_mib: r.peak_rss_mib,
            settings: format!(
                "surface-to-surface penalty contact {} N/mm^3, friction {} (stick slope {} N/mm^3); SPOOLES, 1 thread",
                job.campaign.contact.penalty_slope_n_per_mm3, job.campaign.contact.friction, job.campaign.contact.stick_slope_n_per_mm3
            ),
        })
    }

    fn steps_done(&self, work_dir: &Path) -> u32 {
        ccx::steps_done(work_dir, JOB)
    }
}

/// The deck prints the reactions once at the end of each step; step k ends at total
/// time k. Check that there is exactly one block per step, in order.
fn check_step_times(blocks: &[dat::StepRf], steps: u32) -> Result<()> {
    if blocks.len() != steps as usize {
        bail!(
            "{} reaction force blocks (times {}), expected one per step ({steps})",
            blocks.len(),
            blocks.iter().map(|b| b.total_time.to_string()).collect::<Vec<_>>().join(", ")
        );
    }
    for (k, b) in (1u32..).zip(blocks) {
        let want = f64::from(k);
        if (b.total_time - want).abs() > 1e-5 * want {
            bail!("reaction force block {k} is at time {}, expected {want} (end of step {k})", b.total_time);
        }
    }
    Ok(())
}

/// Keep a failed ccx attempt's log, status and SPOOLES files (see
/// [`process::keep_failed_attempt`](crate::process::keep_failed_attempt)).
fn keep_failed_attempt(job: &Job<'_>) -> String {
    let files = [(format!("{JOB}.log"), "log"), (format!("{JOB}.sta"), "sta"), ("spooles.out".to_string(), "spooles.out")];
    crate::process::keep_failed_attempt(job.work_dir, &format!("first-increment-{}", job.first_increment), &files)
}
