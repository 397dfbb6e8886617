//! `needle fe ...`: the FE campaign commands.
use crate::fe::campaign::{self, RunOptions};
use clap::{Args, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

/// `needle fe` subcommands.
#[derive(Subcommand)]
pub enum FeCommand {
    /// Run the FE campaign of a set on its engine (FEBio or CalculiX, campaign.toml's
    /// [solver] engine or --solver): one input and one solver job per pose,
    /// results in <set>/fe/<pose>.csv (depth in mm, forces in N, moments in N*mm about the
    /// needle hub) and <set>/fe/manifest.toml. Poses whose result matches the current
    /// spec are skipped; a killed campaign resumes where it stopped. Exit status 1 when a
    /// run failed (the others are still written), 2 on an error before any run.
    Run(RunArgs),
    /// Verify the FE setup: flat punch against Sneddon (four small solves), mesh
    /// convergence of the centred needle (two needle solves, the fine one is slow) and
    /// the mirror runs against their counterparts (no solve). Without --punch, --mesh or
    /// --mirror all three run. Prints the table and writes <set>/fe/verify.toml. Exit
    /// status 1 when a check misses its goal, 2 on an error.
    Verify(VerifyArgs),
}

/// Arguments of `needle fe run`.
#[derive(Args, Debug)]
pub struct RunArgs {
    /// Set folder holding campaign.toml, e.g. coeffs/default.
    #[arg(long, value_name = "DIR")]
    pub set: PathBuf,
    /// FE engine of this run instead of campaign.toml's [solver] engine: febio or ccx.
    #[arg(long, value_name = "ENGINE", value_parser = ["febio", "ccx"])]
    pub solver: Option<String>,
    /// Number of solver jobs at the same time (memory: about 2.5 GB per ccx job on the
    /// committed mesh).
    #[arg(long, value_name = "N", default_value_t = 1, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=256))]
    pub jobs: u32,
    /// Solver threads per job (FEBio's Pardiso and assembly; ccx always runs on one).
    /// Default: the machine's cores divided by --jobs.
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=256))]
    pub threads: Option<u32>,
    /// Only the poses whose name matches this glob, e.g. 'x+*' or 'centre' (quote it), or
    /// any of several comma-separated globs, e.g. 'lhs-09,lhs-1*'.
    #[arg(long, value_name = "PATTERN")]
    pub only: Option<String>,
    /// Mesh level of campaign.toml ([mesh.<LEVEL>]); default: campaign.mesh.
    #[arg(long, value_name = "LEVEL")]
    pub mesh: Option<String>,
    /// Number of load steps instead of loading.steps (smoke runs: rows at N+1 depths from 0
    /// to loading.depth_mm). Part of the spec hash: results of other step counts are rerun.
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=10_000))]
    pub steps: Option<u32>,
    /// Output folder for <pose>.csv, manifest.toml and .work/; default: <set>/fe.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Rerun the selected poses even when their results are up to date.
    #[arg(long)]
    pub force: bool,
    /// Keep the work folder (<out>/.work/<pose>: solver input and logs) of successful
    /// runs too; failed runs always keep theirs.
    #[arg(long)]
    pub keep_work: bool,
    /// Wall-clock limit of one ccx job, in seconds; a job running longer is killed and
    /// reported failed.
    #[arg(long, value_name = "S", allow_negative_numbers = true, value_parser = positive_seconds)]
    pub timeout_s: Option<f64>,
    /// A ccx job that writes no output (log, .sta, .cvg) for this many seconds is killed as stalled; a failed or stalled job is retried once with a smaller first increment per step
    #[arg(long, value_name = "S", default_value_t = campaign::DEFAULT_STALL.as_secs_f64(), allow_negative_numbers = true, value_parser = positive_seconds)]
    pub stall_s: f64,
}

/// A duration in seconds on the command line: finite and > 0 (at most 30 days).
fn positive_seconds(text: &str) -> Result<f64, String> {
    let v: f64 = text.trim().parse().map_err(|_| format!("{text:?} is not a number of seconds"))?;
    if v.is_finite() && v > 0.0 && v <= 30.0 * 86_400.0 {
        Ok(v)
    } else {
        Err(format!("{v} s: must be > 0 s and at most 30 days (2592000 s)"))
    }
}

/// Arguments of `needle fe verify`.
#[derive(Args, Debug)]
pub struct VerifyArgs {
    /// Set folder holding campaign.toml and fe/, e.g. coeffs/default.
    #[arg(long, value_name = "DIR")]
    pub set: PathBuf,
    /// Run the flat-punch check (Sneddon, goal 5%).
    #[arg(long)]
    pub punch: bool,
    /// Run the mesh-convergence check (Fy at full depth on the levels of campaign.mesh_study: committed level against its 2x refinement, goal 2%; Richardson estimate).
    #[arg(long)]
    pub mesh: bool,
    /// Check the mirror runs against their counterparts (goal 1% of peak |Fy|).
    #[arg(long)]
    pub mirror: bool,
    /// Coarsen the flat-punch mesh by this factor (1 = the verification mesh; the goal
    /// applies to 1).
    #[arg(long, value_name = "F", default_value_t = 1.0)]
    pub punch_mesh_scale: f64,
    /// Skip the flat punch with the campaign's element (C3D8), which is solved and
    /// reported by default to measure its volumetric locking.
    #[arg(long)]
    pub no_campaign_element: bool,
    /// Work folder for the solves; default: <set>/fe/.work/verify.
    #[arg(long, value_name = "DIR")]
    pub work: Option<PathBuf>,
    /// Solver threads of each solve (FEBio); default: all cores.
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=256))]
    pub threads: Option<u32>,
    /// FE engine of the checks instead of campaign.toml's [solver] engine: febio or ccx.
    #[arg(long, value_name = "ENGINE", value_parser = ["febio", "ccx"])]
    pub solver: Option<String>,
}

/// Run an `fe` subcommand.
///
/// # Errors
/// Any failure before the runs start (spec, material check, ccx missing, output folder),
/// with its context. Failed runs are reported and give exit status 1, not an error.
pub fn run(c: FeCommand) -> anyhow::Result<ExitCode> {
    match c {
        FeCommand::Run(a) => run_campaign(a),
        FeCommand::Verify(a) => run_verify(a),
    }
}

fn run_campaign(a: RunArgs) -> anyhow::Result<ExitCode> {
    let timeout = match a.timeout_s {
        None => None,
        Some(s) if s.is_finite() && s > 0.0 => Some(Duration::from_secs_f64(s)),
        Some(s) => anyhow::bail!("--timeout-s {s}: must be a number of seconds > 0"),
    };
    if !(a.stall_s.is_finite() && a.stall_s > 0.0) {
        anyhow::bail!("--stall-s {}: must be a number of seconds > 0", a.stall_s);
    }
    let cores = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    let jobs = a.jobs as usize;
    let opts = RunOptions {
        set_dir: a.set,
        jobs,
        threads: a.threads.map(|t| t as usize).unwrap_or((cores / jobs).max(1)),
        solver: a.solver.as_deref().map(crate::fe::spec::Engine::parse).transpose()?,
        only: a.only,
        mesh: a.mesh,
        steps: a.steps,
        out_dir: a.out,
        force: a.force,
        keep_work: a.keep_work,
        timeout,
        stall: Some(Duration::from_secs_f64(a.stall_s)),
    };
    crate::fe::process::stop_jobs_on_termination()?;
    let report = campaign::run(&opts)?;
    print!("{}", report.table());
    if crate::fe::process::interrupted() {
        return Ok(ExitCode::from(crate::fe::process::EXIT_INTERRUPTED));
    }
    Ok(if report.failed() > 0 { ExitCode::from(1) } else { ExitCode::SUCCESS })
}

fn run_verify(a: VerifyArgs) -> anyhow::Result<ExitCode> {
    if !(a.punch_mesh_scale.is_finite() && a.punch_mesh_scale >= 1.0) {
        anyhow::bail!("--punch-mesh-scale {}: must be a number >= 1", a.punch_mesh_scale);
    }
    let all = !(a.punch || a.mesh || a.mirror);
    let opts = crate::fe::verify::VerifyOptions {
        set_dir: a.set,
        punch: a.punch || all,
        mesh: a.mesh || all,
        mirror: a.mirror || all,
        work_dir: a.work,
        punch_mesh_scale: a.punch_mesh_scale,
        punch_campaign_element: !a.no_campaign_element,
        threads: a.threads.map(|t| t as usize).unwrap_or_else(|| std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)),
        engine: a.solver.as_deref().map(crate::fe::spec::Engine::parse).transpose()?,
    };
    crate::fe::process::stop_jobs_on_termination()?;
    let (_, ok) = crate::fe::verify::run(&opts)?;
    if !ok {
        eprintln!("needle fe verify: a check missed its goal");
    }
    Ok(if ok { ExitCode::SUCCESS } else { ExitCode::from(1) })
}
