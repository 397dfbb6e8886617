//! `needle fe status`: each pose's state, its SLURM task, the projected wall time.
use super::spec::{spec_options, variants, SpecArgs};
use clap::Args;
use needle_fe::campaign;
use needle_set::set_folder::SetFolder;
use std::process::ExitCode;

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

/// `needle fe status`.
pub fn run(a: StatusArgs) -> anyhow::Result<ExitCode> {
    let opts = spec_options(a.spec)?;
    let set = SetFolder::open(&opts.set_dir)?;
    let variants = variants(&set, opts)?;
    for extra in variants.iter().skip(1) {
        let plan = campaign::plan(&set, extra)?;
        print!("{}", needle_fe::launcher::status::status(&plan)?.table());
    }
    let Some(first) = variants.first() else { return Ok(ExitCode::SUCCESS) };
    let plan = campaign::plan(&set, first)?;
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
