//! Where the campaign's solver jobs run, chosen apart from the solver (`--launcher`):
//! - `local` (the default): worker threads of `needle fe run` on this machine
//!   ([`campaign::run`](crate::campaign::run)).
//! - `slurm`: one SLURM job array per `needle fe run --launcher slurm`, one array task
//!   per pose still to solve ([`slurm`]); each task is `needle fe run-one`, which solves
//!   its pose through the same code path as a local job (deck, solver, retries, CSV and
//!   manifest entry written atomically, the manifest under a file lock) on the shared
//!   filesystem. `needle fe status` ([`status`]) puts the queue beside the manifest;
//!   [`projection`] estimates a campaign's wall time on N nodes from measured runs.
//!
//! How a run was launched is part of its manifest entry:
//! [`manifest::Launched`](crate::manifest::Launched).

pub mod projection;
pub mod slurm;
pub mod status;
