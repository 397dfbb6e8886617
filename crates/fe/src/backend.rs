//! The solver side of a campaign: the [`Backend`] trait (one pose in, wrenches out) and
//! the types it speaks ([`Job`], [`Solved`], [`SolveFailure`]). The engines are
//! `fe::ccx::CcxBackend` and `fe::febio::FebioBackend` (the engine of a run:
//! [`engines::backend_for`](crate::engines::backend_for)); tests inject other backends.

use crate::mesh::summary::MeshSummary;
use crate::spec::{Campaign, MeshLevel, PoseSpec};
use anyhow::Result;
use needle_contract::COMPONENT_COUNT;
use std::path::Path;
use std::time::Duration;

/// The first increment of every load step, as a fraction of the step, when the step is
/// not tried in one increment: the campaign's retry of a failed or stalled run (see
/// `campaign`) uses it ([`Backend::first_increment`]); the solver cuts back from there
/// as usual.
pub const RETRY_FIRST_INCREMENT: f64 = 0.25;

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
    /// attempt, [`RETRY_FIRST_INCREMENT`] on the retries).
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

/// The solver side of a campaign; `fe::ccx::CcxBackend` and `fe::febio::FebioBackend`
/// are the real ones, tests inject others.
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
    /// whole step on the first attempt, [`RETRY_FIRST_INCREMENT`] on the retries.
    fn first_increment(&self, attempt: u32) -> f64 {
        if attempt == 0 {
            1.0
        } else {
            RETRY_FIRST_INCREMENT
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
