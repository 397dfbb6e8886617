//! Where the campaign's solver jobs run, chosen apart from the solver (`--launcher`):
//! - `local` (the default): worker threads of `needle fe run` on this machine
//!   ([`campaign::run`](crate::campaign::run)).
//! - `slurm`: one SLURM job array per `needle fe run --launcher slurm`, one array task
//!   per pose still to solve ([`slurm`]); each task is `needle fe run-one`, which solves
//!   its pose through the same code path as a local job (deck, solver, retries, CSV and
//!   manifest entry written atomically, the manifest under a file lock) on the shared
//!   filesystem. `needle fe status` ([`status`]) puts the queue beside the manifest;
//!   [`projection`] estimates a campaign's wall time on N nodes from measured runs.

pub mod projection;
pub mod slurm;
pub mod status;

/// How the process that solved a pose was started; recorded in its manifest entry
/// (`launcher`, `batch_job`).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum Launched {
    /// `needle fe run` on this machine.
    #[default]
    Local,
    /// A SLURM array task; `job` is `<array job id>_<task id>`.
    Slurm {
        /// `SLURM_ARRAY_JOB_ID_SLURM_ARRAY_TASK_ID`, e.g. `1234_5`.
        job: String,
    },
}

impl Launched {
    /// `"local"` or `"slurm"`: the manifest's `launcher`.
    pub fn name(&self) -> &'static str {
        match self {
            Launched::Local => "local",
            Launched::Slurm { .. } => "slurm",
        }
    }

    /// The manifest's `batch_job`: the SLURM array task, none for a local run.
    pub fn batch_job(&self) -> Option<String> {
        match self {
            Launched::Local => None,
            Launched::Slurm { job } => Some(job.clone()),
        }
    }

    /// The launcher of this process: a SLURM array task when `SLURM_ARRAY_JOB_ID` and
    /// `SLURM_ARRAY_TASK_ID` are set, else local.
    pub fn from_env() -> Self {
        match (std::env::var("SLURM_ARRAY_JOB_ID"), std::env::var("SLURM_ARRAY_TASK_ID")) {
            (Ok(j), Ok(t)) if !j.is_empty() && !t.is_empty() => Launched::Slurm { job: format!("{j}_{t}") },
            _ => Launched::Local,
        }
    }
}
