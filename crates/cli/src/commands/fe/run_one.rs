//! The hidden `needle fe run-one`: one pose solved as a local job would, what each
//! array task of `needle fe run --launcher slurm` runs.
use super::solve::{with_solve, SolveArgs};
use super::spec::{spec_options, SpecArgs};
use clap::Args;
use needle_fe::campaign::{self, RunOptions};
use needle_set::manifest::Launched;
use needle_set::set_folder::SetFolder;
use std::process::ExitCode;

/// Arguments of the hidden `needle fe run-one`: the spec options of `fe run` (the batch
/// script passes them all) and the one pose.
#[derive(Args, Debug)]
pub struct RunOneArgs {
    #[command(flatten)]
    pub spec: SpecArgs,
    #[command(flatten)]
    pub solve: SolveArgs,
    /// The pose, by its exact name.
    #[arg(long, value_name = "NAME")]
    pub pose: String,
}

/// `needle fe run-one`.
pub fn run(a: RunOneArgs) -> anyhow::Result<ExitCode> {
    if a.pose.contains(',') || a.pose.chars().any(|c| matches!(c, '*' | '?' | '[' | ']')) || a.spec.only.is_some() {
        anyhow::bail!("--pose {:?}: one pose name, not a pattern (and no --only)", a.pose);
    }
    let threads = std::env::var("SLURM_CPUS_PER_TASK").ok().and_then(|v| v.trim().parse::<usize>().ok()).unwrap_or(1).max(1);
    let only = Some(a.pose.clone());
    let opts = with_solve(RunOptions { jobs: 1, threads, only, launcher: Launched::from_env(), ..spec_options(a.spec)? }, &a.solve);
    let set = SetFolder::open(&opts.set_dir)?;
    needle_fe::process::stop_jobs_on_termination()?;
    let report = campaign::run(&set, &opts)?;
    print!("{}", report.table());
    if needle_fe::process::interrupted() {
        return Ok(ExitCode::from(needle_fe::process::EXIT_INTERRUPTED));
    }
    Ok(if report.failed() > 0 { ExitCode::from(1) } else { ExitCode::SUCCESS })
}
