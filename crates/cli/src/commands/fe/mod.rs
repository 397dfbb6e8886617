//! `needle fe ...`: the FE campaign commands, one module per subcommand; `spec` and
//! `solve` hold the options `run`, `status` and `run-one` share.
pub mod run;
pub mod run_one;
pub mod solve;
pub mod spec;
pub mod status;
pub mod verify;

use clap::Subcommand;
use run::RunArgs;
use run_one::RunOneArgs;
use status::StatusArgs;
use std::process::ExitCode;
use verify::VerifyArgs;

/// `needle fe` subcommands.
#[derive(Subcommand)]
pub enum FeCommand {
    /// Solve the set's FE campaign, one solver job per pose; resumable, an interrupted pose where it was.
    #[command(after_help = "Each pose's result goes to <set>/fe/<pose>.csv (depth in mm, forces in N, moments in N*mm \
about the needle hub) and its record to <set>/fe/manifest.toml. Poses whose result matches the current spec are \
skipped; a failed attempt is retried on the engine's retry ladder (docs/usage.md). A run killed in the middle of a \
pose (Ctrl-C, kill -9, the end of a session) resumes it on the rerun at the attempt it was in \
(<out>/.work/<pose>/progress.toml): FEBio goes on from the attempt's last dump (its last must point), ccx reruns the \
attempt from its start; --force, another spec or a pose whose attempts all failed start afresh (--skip-failed \
leaves the last). Exit status 1 when a run failed (the others are kept), 2 on an error before any run.")]
    Run(RunArgs),
    /// Verify the FE setup: flat punch, mesh study, mirror runs, smoothness, scaling law.
    #[command(after_help = "Without --punch, --mesh, --mirror, --smooth or --scaling all five run (the mesh study's \
fine level is slow). Prints the table and writes <set>/fe/verify.toml. Exit status 1 when a check misses its goal, \
2 on an error.")]
    Verify(VerifyArgs),
    /// Each pose's state: up to date or why not, its SLURM task, projected wall time.
    #[command(after_help = "For --launcher slurm submissions: the queue state of each pose's latest array task \
(squeue), or the cause a task that ended without a result states (docs/cluster.md).")]
    Status(StatusArgs),
    /// Solve one pose as a local job would (one job; threads from SLURM_CPUS_PER_TASK):
    /// what each array task of `needle fe run --launcher slurm` runs.
    #[command(hide = true)]
    RunOne(RunOneArgs),
}

/// Run an `fe` subcommand.
///
/// # Errors
/// Any failure before the runs start (spec, material check, ccx missing, output folder),
/// with its context. Failed runs are reported and give exit status 1, not an error.
pub fn run(c: FeCommand) -> anyhow::Result<ExitCode> {
    match c {
        FeCommand::Run(a) => run::run(a),
        FeCommand::Verify(a) => verify::run(a),
        FeCommand::Status(a) => status::run(a),
        FeCommand::RunOne(a) => run_one::run(a),
    }
}
