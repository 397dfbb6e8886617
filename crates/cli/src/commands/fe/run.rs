//! `needle fe run`: solve the set's FE campaign, locally or as a SLURM job array.
use super::solve::{with_solve, SolveArgs};
use super::spec::{spec_options, variants, SpecArgs};
use clap::Args;
use needle_fe::campaign::{self, RunOptions};
use needle_fe::launcher::slurm::{self, SlurmOptions};
use needle_set::set_folder::SetFolder;
use std::process::ExitCode;

/// Where the solver jobs run.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum LauncherArg {
    // Plain comments, not doc comments: clap would list them as the values' help and
    // turn `--help` into its long layout.
    // Worker threads of this process (--jobs at once).
    Local,
    // One SLURM job array (sbatch), one task per pose still to solve.
    Slurm,
}

/// Arguments of `needle fe run`.
#[derive(Args, Debug)]
pub struct RunArgs {
    #[command(flatten)]
    pub spec: SpecArgs,
    /// Number of solver jobs at the same time (memory: about 2.5 GB per ccx job on the
    /// committed mesh).
    #[arg(long, value_name = "N", default_value_t = 1, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=256))]
    pub jobs: u32,
    /// Solver threads per job (FEBio's Pardiso and assembly; ccx always runs on one).
    /// Default: the machine's cores divided by --jobs.
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=256))]
    pub threads: Option<u32>,
    #[command(flatten)]
    pub solve: SolveArgs,
    /// Where the solver jobs run: local (this machine) or slurm (one sbatch job array; docs/cluster.md).
    #[arg(long, value_enum, default_value_t = LauncherArg::Local)]
    pub launcher: LauncherArg,
    /// slurm: sbatch --partition (default: the cluster's default partition).
    #[arg(long, value_name = "NAME")]
    pub partition: Option<String>,
    /// slurm: sbatch --time per task (default: attempts x longest measured run x 1.5, >= 10 min).
    #[arg(long, value_name = "TIME")]
    pub time: Option<String>,
    /// slurm: sbatch --mem per task, e.g. 4G (default: largest measured peak x 1.5 + 256 MiB).
    #[arg(long, value_name = "SIZE")]
    pub mem: Option<String>,
    /// slurm: sbatch --cpus-per-task, also the solver threads of each task (default 1).
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub cpus_per_task: Option<u32>,
    /// slurm: one more sbatch argument, passed as given (repeatable), e.g.
    /// --sbatch-arg=--account=abc.
    #[arg(long, value_name = "ARG", allow_hyphen_values = true)]
    pub sbatch_arg: Vec<String>,
}

/// `needle fe run`.
pub fn run(a: RunArgs) -> anyhow::Result<ExitCode> {
    let cores = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    let jobs = a.jobs as usize;
    if a.launcher == LauncherArg::Local
        && (a.partition.is_some() || a.time.is_some() || a.mem.is_some() || a.cpus_per_task.is_some() || !a.sbatch_arg.is_empty())
    {
        anyhow::bail!("--partition, --time, --mem, --cpus-per-task and --sbatch-arg are options of --launcher slurm");
    }
    let opts = with_solve(
        RunOptions { jobs, threads: a.threads.map(|t| t as usize).unwrap_or((cores / jobs).max(1)), ..spec_options(a.spec)? },
        &a.solve,
    );
    if a.launcher == LauncherArg::Slurm && (opts.visco || opts.family) {
        anyhow::bail!("--visco and --family run locally only (--launcher local): each speed or member is its own campaign run");
    }
    let set = SetFolder::open(&opts.set_dir)?;
    if a.launcher == LauncherArg::Slurm {
        let slurm = SlurmOptions {
            partition: a.partition,
            time: a.time,
            mem: a.mem,
            cpus_per_task: a.cpus_per_task,
            extra: a.sbatch_arg,
            needle: None,
        };
        let r = slurm::submit(&set, &opts, &slurm)?;
        print!("{}", submit_summary(&r));
        return Ok(ExitCode::SUCCESS);
    }
    needle_fe::process::stop_jobs_on_termination()?;
    let mut failed = 0;
    for opts in variants(&set, opts)? {
        let report = campaign::run(&set, &opts)?;
        print!("{}", report.table());
        if needle_fe::process::interrupted() {
            return Ok(ExitCode::from(needle_fe::process::EXIT_INTERRUPTED));
        }
        failed += report.failed();
    }
    Ok(if failed > 0 { ExitCode::from(1) } else { ExitCode::SUCCESS })
}

/// What `needle fe run --launcher slurm` prints.
fn submit_summary(r: &slurm::SubmitReport) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let _ = writeln!(s, "{} pose(s) selected: {} up to date, {} still in the queue", r.selected, r.up_to_date.len(), r.in_queue.len());
    for (pose, task, state) in &r.in_queue {
        let _ = writeln!(s, "  {pose}: task {task} {}", state.to_lowercase());
    }
    match (&r.submission, &r.resources) {
        (Some(sub), Some(res)) => {
            let _ = writeln!(s, "submitted job array {} with {} task(s): {}", sub.job_id, sub.poses.len(), sub.poses.join(", "));
            for w in &res.why {
                let _ = writeln!(s, "  {w}");
            }
            let _ = writeln!(
                s,
                "follow it with: needle fe status (same --set/--out/--mesh/--steps); rerun this command to resubmit what fails"
            );
        }
        _ => {
            let _ = writeln!(s, "nothing to submit");
        }
    }
    s
}
