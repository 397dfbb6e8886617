//! `needle fe ...`: the FE campaign commands.
use clap::{Args, Subcommand};
use needle_fe::campaign::{self, RunOptions};
use needle_fe::launcher::slurm::{self, SlurmOptions};
use needle_set::manifest::Launched;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

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

/// What a campaign command works on: the set, its engine, mesh level, steps, poses and
/// output folder (shared by `fe run` and `fe status`).
#[derive(Args, Debug)]
pub struct SpecArgs {
    /// Set folder holding campaign.toml, e.g. coeffs/default.
    #[arg(long, value_name = "DIR")]
    pub set: PathBuf,
    /// FE engine instead of campaign.toml's [solver] engine: febio or ccx.
    #[arg(long, value_name = "ENGINE", value_parser = ["febio", "ccx"])]
    pub solver: Option<String>,
    /// Only the poses whose name matches this glob, e.g. 'x+*' or 'centre' (quote it), or
    /// any of several comma-separated globs, e.g. 'lhs-09,lhs-1*'.
    #[arg(long, value_name = "PATTERN")]
    pub only: Option<String>,
    /// Mesh level of campaign.toml ([mesh.<LEVEL>]); default: campaign.mesh.
    #[arg(long, value_name = "LEVEL")]
    pub mesh: Option<String>,
    /// Load steps instead of loading.steps, for smoke runs (part of the spec hash).
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=10_000))]
    pub steps: Option<u32>,
    /// Output folder for <pose>.csv, manifest.toml and .work/; default: <set>/fe (with
    /// --deep: <set>/fe/deep).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// The runs of campaign.toml's [deep] section (to deep.depth_mm on deep.mesh), into <set>/fe/deep/.
    #[arg(long)]
    pub deep: bool,
    /// The viscoelastic ramp-and-hold runs of campaign.toml's [viscoelastic] section (each
    /// pose at each speed, --steps must points on the ramp), into <set>/fe/visco/.
    #[arg(long, conflicts_with = "deep")]
    pub visco: bool,
    /// The material family of campaign.toml's [family] section: the centre of each member
    /// (one-term Ogden, exponent family.alpha) to family.depth_mm on family.mesh, then
    /// family.check_poses at family.check_alpha, into <set>/fe/family/.
    #[arg(long, conflicts_with_all = ["deep", "visco"])]
    pub family: bool,
}

/// How each pose is solved (shared by `fe run` and the array tasks' `fe run-one`).
#[derive(Args, Debug)]
pub struct SolveArgs {
    /// Rerun the selected poses even when their results are up to date; an interrupted
    /// pose starts afresh instead of resuming.
    #[arg(long)]
    pub force: bool,
    /// Do not run again a pose whose attempts all failed with the same spec, engine and
    /// mesh (its <out>/.work/<pose>/progress.toml says so): report it failed with the
    /// recorded failures. For a long campaign resumed in pieces.
    #[arg(long, conflicts_with = "force")]
    pub skip_failed: bool,
    /// Keep the work folder (<out>/.work/<pose>: solver input and logs) of successful
    /// runs too; failed runs always keep theirs.
    #[arg(long)]
    pub keep_work: bool,
    /// Wall-clock limit of one solver attempt, seconds; a longer attempt is killed and counted failed.
    #[arg(long, value_name = "S", allow_negative_numbers = true, value_parser = positive_seconds)]
    pub timeout_s: Option<f64>,
    /// Seconds without solver output (log, result files) after which a job is killed as stalled.
    #[arg(long, value_name = "S", default_value_t = campaign::DEFAULT_STALL.as_secs_f64(), allow_negative_numbers = true, value_parser = positive_seconds)]
    pub stall_s: f64,
}

/// The solve options of `a` applied to `opts`.
fn with_solve(opts: RunOptions, a: &SolveArgs) -> RunOptions {
    RunOptions {
        force: a.force,
        skip_failed: a.skip_failed,
        keep_work: a.keep_work,
        timeout: a.timeout_s.map(Duration::from_secs_f64),
        stall: Some(Duration::from_secs_f64(a.stall_s)),
        ..opts
    }
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

/// Arguments of `needle fe status`.
#[derive(Args, Debug)]
pub struct StatusArgs {
    #[command(flatten)]
    pub spec: SpecArgs,
    /// Project the selected poses' campaign wall time on these node counts, e.g. 1,4,16,
    /// from the measured wall time of each pose (or the median of its model kind).
    #[arg(long, value_name = "N,N,...", value_delimiter = ',', value_parser = clap::value_parser!(u32).range(1..=100_000))]
    pub project_nodes: Vec<u32>,
    /// Tasks at once per node for the projection (cores per node / --cpus-per-task);
    /// default: this machine's cores.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub tasks_per_node: Option<u32>,
}

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
    /// Run the mesh study: each level against its refinement (goal 2% RMS, 4% largest after the best scale).
    #[arg(long)]
    pub mesh: bool,
    /// Run the edge study: the centre with each needle edge radius of
    /// campaign.edge_study_radii_mm on every mesh-study level, into fe/edge/ (not part of
    /// the default checks: its fine runs take tens of minutes).
    #[arg(long)]
    pub edge: bool,
    /// Check the mirror runs against their counterparts (goal 1% of peak |Fy|).
    #[arg(long)]
    pub mirror: bool,
    /// Check every FE result for a must point off its neighbours' mean (goal 3% of peak |Fy|).
    #[arg(long)]
    pub smooth: bool,
    /// Check the scaling law: every Ogden mu_i x 0.5 and x 2 scales the wrench (goal 0.5% of peak |Fy|).
    #[arg(long)]
    pub scaling: bool,
    /// Poses of the scaling check, comma-separated exact names.
    #[arg(long, value_name = "NAME,...", value_delimiter = ',', default_values_t = needle_fe::verify::scaling::SCALING_POSES.map(String::from))]
    pub scaling_poses: Vec<String>,
    /// Mesh level of the scaling check's runs and of the s = 1 runs it reads from fe/
    /// (default: campaign.mesh).
    #[arg(long, value_name = "LEVEL")]
    pub scaling_mesh: Option<String>,
    /// Load steps of the scaling check's runs and of the s = 1 runs (default: loading.steps).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=10_000))]
    pub scaling_steps: Option<u32>,
    /// Compare the viscoelastic ramp-and-hold runs ([viscoelastic], fe/visco/) with the
    /// library's QLV filter on the elastic runs (goal RMS 3%, must 5%, largest 6% of peak |Fy|).
    #[arg(long)]
    pub qlv: bool,
    /// Poses of the QLV check, comma-separated exact names (default: viscoelastic.poses).
    #[arg(long, value_name = "NAME,...", value_delimiter = ',')]
    pub qlv_poses: Vec<String>,
    /// Mesh level of the QLV check's runs, viscoelastic and elastic (default: viscoelastic.mesh).
    #[arg(long, value_name = "LEVEL")]
    pub qlv_mesh: Option<String>,
    /// Must points on the ramp of the QLV check's runs and load steps of the elastic ones
    /// (default: loading.steps).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=10_000))]
    pub qlv_steps: Option<u32>,
    /// Solve none of the scaling, mesh-study and QLV runs: compare the results already
    /// there and name the missing ones.
    #[arg(long)]
    pub no_solve: bool,
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
        FeCommand::Status(a) => run_status(a),
        FeCommand::RunOne(a) => run_one(a),
    }
}

fn run_campaign(a: RunArgs) -> anyhow::Result<ExitCode> {
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
    if a.launcher == LauncherArg::Slurm {
        let slurm = SlurmOptions {
            partition: a.partition,
            time: a.time,
            mem: a.mem,
            cpus_per_task: a.cpus_per_task,
            extra: a.sbatch_arg,
            needle: None,
        };
        let r = slurm::submit(&opts, &slurm)?;
        print!("{}", submit_summary(&r));
        return Ok(ExitCode::SUCCESS);
    }
    needle_fe::process::stop_jobs_on_termination()?;
    let mut failed = 0;
    for opts in variants(opts)? {
        let report = campaign::run(&opts)?;
        print!("{}", report.table());
        if needle_fe::process::interrupted() {
            return Ok(ExitCode::from(needle_fe::process::EXIT_INTERRUPTED));
        }
        failed += report.failed();
    }
    Ok(if failed > 0 { ExitCode::from(1) } else { ExitCode::SUCCESS })
}

/// The campaign runs `opts` asks for: one per member run with `family`, one per speed
/// with `visco`, else `opts` itself.
fn variants(opts: RunOptions) -> anyhow::Result<Vec<RunOptions>> {
    if opts.family {
        family_variants(opts)
    } else {
        visco_variants(opts)
    }
}

/// One run per run of `[family]` (`needle_fe::family::FamilyRun::all`), in order; the
/// runs `--only` selects nothing of are left out.
fn family_variants(opts: RunOptions) -> anyhow::Result<Vec<RunOptions>> {
    let (c, path) = needle_set::spec::load(&opts.set_dir)?;
    let f = c.family.clone().ok_or_else(|| anyhow::anyhow!("{}: --family: the spec has no [family] section", path.display()))?;
    let mut out = Vec::new();
    for run in needle_fe::family::FamilyRun::all(&f) {
        let (_, runs, _) = needle_fe::family::apply(&c, &f, run);
        if needle_set::spec::select(&runs, opts.only.as_deref()).is_ok_and(|r| !r.is_empty()) {
            out.push(RunOptions { family_run: Some(run), ..opts.clone() });
        }
    }
    if out.is_empty() {
        anyhow::bail!(
            "--family --only {:?}: matches no run (names: <pose>_a<alpha>, e.g. centre_a2, x+04_a20, centre_a0p5)",
            opts.only.as_deref().unwrap_or("")
        );
    }
    Ok(out)
}

/// `opts` as it is, or with `visco`: once per speed of `[viscoelastic]`, in order; with
/// `[viscoelastic] frictionless` then the frictionless elastic companions and once per
/// speed frictionless. Variants whose runs `--only` does not select are left out.
fn visco_variants(opts: RunOptions) -> anyhow::Result<Vec<RunOptions>> {
    use needle_fe::visco::Friction;
    if !opts.visco {
        return Ok(vec![opts]);
    }
    let (c, path) = needle_set::spec::load(&opts.set_dir)?;
    let v = c.viscoelastic.clone().ok_or_else(|| anyhow::anyhow!("{}: --visco: the spec has no [viscoelastic] section", path.display()))?;
    let selects = |runs: &[needle_set::spec::PoseSpec]| needle_set::spec::select(runs, opts.only.as_deref()).is_ok_and(|r| !r.is_empty());
    let mut out = Vec::new();
    for friction in Friction::cases(&v) {
        let frictionless = friction == Friction::None;
        if let Some((_, runs)) = needle_fe::visco::apply_frictionless_elastic(&c, &v).filter(|_| frictionless) {
            if selects(&runs) {
                out.push(RunOptions { visco_frictionless: true, ..opts.clone() });
            }
        }
        for &speed in &v.speeds_mm_per_s {
            let (_, runs) = needle_fe::visco::apply(&c, &v, speed, c.loading.steps, friction);
            if selects(&runs) {
                out.push(RunOptions { visco_speed_mm_per_s: Some(speed), visco_frictionless: frictionless, ..opts.clone() });
            }
        }
    }
    if out.is_empty() {
        anyhow::bail!(
            "--visco --only {:?}: matches no run (names: <pose>_<speed>mm-s, e.g. centre_10mm-s; frictionless: centre_10mm-s_mu0 and the elastic centre_mu0)",
            opts.only.as_deref().unwrap_or("")
        );
    }
    Ok(out)
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

fn run_status(a: StatusArgs) -> anyhow::Result<ExitCode> {
    let variants = variants(spec_options(a.spec)?)?;
    for extra in variants.iter().skip(1) {
        let plan = campaign::plan(extra)?;
        print!("{}", needle_fe::launcher::status::status(&plan)?.table());
    }
    let Some(first) = variants.first() else { return Ok(ExitCode::SUCCESS) };
    let plan = campaign::plan(first)?;
    let r = needle_fe::launcher::status::status(&plan)?;
    print!("{}", r.table());
    print!("{}", needle_fe::launcher::status::attempts_by_class(&plan));
    if plan.selected.iter().any(|p| p.role == needle_set::spec::Role::Train) {
        if let Some(t) = needle_fe::launcher::status::training_coverage(&plan) {
            println!("{t}");
        }
    }
    if !a.project_nodes.is_empty() {
        let per_node =
            a.tasks_per_node.map(|n| n as usize).unwrap_or_else(|| std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1));
        let nodes: Vec<usize> = a.project_nodes.iter().map(|&n| n as usize).collect();
        print!("{}", needle_fe::launcher::projection::table(&plan, &nodes, per_node));
    }
    Ok(ExitCode::SUCCESS)
}

/// The run options of `spec`, the others at their defaults.
fn spec_options(spec: SpecArgs) -> anyhow::Result<RunOptions> {
    Ok(RunOptions {
        solver: spec.solver.as_deref().map(needle_set::spec::Engine::parse).transpose()?,
        only: spec.only,
        mesh: spec.mesh,
        steps: spec.steps,
        out_dir: spec.out,
        deep: spec.deep,
        visco: spec.visco,
        family: spec.family,
        ..RunOptions::new(spec.set)
    })
}

fn run_one(a: RunOneArgs) -> anyhow::Result<ExitCode> {
    if a.pose.contains(',') || a.pose.chars().any(|c| matches!(c, '*' | '?' | '[' | ']')) || a.spec.only.is_some() {
        anyhow::bail!("--pose {:?}: one pose name, not a pattern (and no --only)", a.pose);
    }
    let threads = std::env::var("SLURM_CPUS_PER_TASK").ok().and_then(|v| v.trim().parse::<usize>().ok()).unwrap_or(1).max(1);
    let only = Some(a.pose.clone());
    let opts = with_solve(RunOptions { jobs: 1, threads, only, launcher: Launched::from_env(), ..spec_options(a.spec)? }, &a.solve);
    needle_fe::process::stop_jobs_on_termination()?;
    let report = campaign::run(&opts)?;
    print!("{}", report.table());
    if needle_fe::process::interrupted() {
        return Ok(ExitCode::from(needle_fe::process::EXIT_INTERRUPTED));
    }
    Ok(if report.failed() > 0 { ExitCode::from(1) } else { ExitCode::SUCCESS })
}

fn run_verify(a: VerifyArgs) -> anyhow::Result<ExitCode> {
    if !(a.punch_mesh_scale.is_finite() && a.punch_mesh_scale >= 1.0) {
        anyhow::bail!("--punch-mesh-scale {}: must be a number >= 1", a.punch_mesh_scale);
    }
    if a.qlv && !(a.punch || a.mesh || a.edge || a.mirror || a.smooth || a.scaling) {
        // the QLV check alone (it is not part of the default five: its runs are the
        // viscoelastic campaign's, `needle fe run --visco`)
        needle_fe::process::stop_jobs_on_termination()?;
        let threads = a.threads.map(|t| t as usize).unwrap_or(1);
        let opts = needle_fe::visco::qlv::QlvOptions {
            set_dir: a.set.clone(),
            steps: a.qlv_steps,
            mesh: a.qlv_mesh.clone(),
            poses: a.qlv_poses.clone(),
            threads,
            solve: !a.no_solve,
        };
        let ok = crate::fe_qlv::check(&opts)?;
        if !ok {
            eprintln!("needle fe verify --qlv: a run missed its bound or has no comparison");
        }
        return Ok(if ok { ExitCode::SUCCESS } else { ExitCode::from(1) });
    }
    if a.qlv {
        anyhow::bail!("--qlv runs alone (not with --punch, --mesh, --edge, --mirror, --smooth, --scaling)");
    }
    let all = !(a.punch || a.mesh || a.edge || a.mirror || a.smooth || a.scaling);
    let threads = a.threads.map(|t| t as usize).unwrap_or_else(|| std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1));
    let work = a.work.clone().unwrap_or_else(|| a.set.join("fe").join(".work").join("verify"));
    let scaling = (a.scaling || all).then(|| needle_fe::verify::scaling::ScalingOptions {
        set_dir: a.set.clone(),
        work_dir: work,
        poses: a.scaling_poses.clone(),
        mesh: a.scaling_mesh.clone(),
        steps: a.scaling_steps,
        threads,
        solve: !a.no_solve,
    });
    let study = needle_fe::verify::mesh_check::MeshOptions { set_dir: a.set.clone(), threads, solve: !a.no_solve, edge_radius_mm: None };
    let mesh = (a.mesh || all).then(|| study.clone());
    let edge = a.edge.then_some(study);
    let opts = needle_fe::verify::VerifyOptions {
        scaling,
        mesh,
        edge,
        set_dir: a.set,
        punch: a.punch || all,
        mirror: a.mirror || all,
        smooth: a.smooth || all,
        work_dir: a.work,
        punch_mesh_scale: a.punch_mesh_scale,
        punch_campaign_element: !a.no_campaign_element,
        threads,
        engine: a.solver.as_deref().map(needle_set::spec::Engine::parse).transpose()?,
    };
    needle_fe::process::stop_jobs_on_termination()?;
    let (_, ok) = needle_fe::verify::run(&opts)?;
    if !ok {
        eprintln!("needle fe verify: a check missed its goal");
    }
    Ok(if ok { ExitCode::SUCCESS } else { ExitCode::from(1) })
}
