//! `needle fe verify`: the FE setup's checks (flat punch, mesh study, mirror runs,
//! smoothness, scaling law) and, alone, the viscoelastic runs against the library's QLV
//! filter ([`qlv`]).
pub mod qlv;

use clap::Args;
use needle_set::set_folder::SetFolder;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `needle fe verify`.
#[derive(Args, Debug)]
// The fields' doc comments are the --help text, written for the terminal: <set>, <pose>
// and [section] are placeholders and campaign.toml sections there, not HTML or links.
#[allow(rustdoc::invalid_html_tags, rustdoc::broken_intra_doc_links)]
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

/// `needle fe verify`.
pub fn run(a: VerifyArgs) -> anyhow::Result<ExitCode> {
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
        let ok = qlv::check(&SetFolder::open(&a.set)?, &opts)?;
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
    let study = needle_fe::mesh::study::MeshOptions { set_dir: a.set.clone(), threads, solve: !a.no_solve, edge_radius_mm: None };
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
    let set = SetFolder::open(&opts.set_dir)?;
    needle_fe::process::stop_jobs_on_termination()?;
    let (_, ok) = needle_fe::verify::run(&set, &opts)?;
    if !ok {
        eprintln!("needle fe verify: a check missed its goal");
    }
    Ok(if ok { ExitCode::SUCCESS } else { ExitCode::from(1) })
}
