//! What a campaign command works on (`needle fe run`, `fe status`, `fe run-one`): the
//! set, its engine, mesh level, steps, poses and output folder, and the campaign runs
//! they ask for (`--family`, `--visco`).
use clap::Args;
use needle_fe::campaign::RunOptions;
use needle_set::set_folder::SetFolder;
use std::path::PathBuf;

/// What a campaign command works on: the set, its engine, mesh level, steps, poses and
/// output folder (shared by `fe run` and `fe status`).
#[derive(Args, Debug)]
// The fields' doc comments are the --help text, written for the terminal: <set>, <pose>
// and [section] are placeholders and campaign.toml sections there, not HTML or links.
#[allow(rustdoc::invalid_html_tags, rustdoc::broken_intra_doc_links)]
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
    /// (the paper's terms x family.weight plus a soft term x (1 - weight)) to family.depth_mm on family.mesh, then
    /// family.check_poses at family.check_weight, into <set>/fe/family/.
    #[arg(long, conflicts_with_all = ["deep", "visco"])]
    pub family: bool,
}

/// The run options of `spec`, the others at their defaults.
pub fn spec_options(spec: SpecArgs) -> anyhow::Result<RunOptions> {
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

/// The campaign runs `opts` asks for of the set `set` (opened once by the command): one
/// per member run with `family`, one per speed with `visco`, else `opts` itself.
pub fn variants(set: &SetFolder, opts: RunOptions) -> anyhow::Result<Vec<RunOptions>> {
    if opts.family {
        family_variants(set, opts)
    } else {
        visco_variants(set, opts)
    }
}

/// One run per run of `[family]` (`needle_fe::family::FamilyRun::all`), in order, then
/// `[family.fitted]`'s (`FamilyRun::fitted`); the runs `--only` selects nothing of are left
/// out.
fn family_variants(set: &SetFolder, opts: RunOptions) -> anyhow::Result<Vec<RunOptions>> {
    let (c, path) = (set.campaign(), set.spec_path());
    let f = c.family.clone().ok_or_else(|| anyhow::anyhow!("{}: --family: the spec has no [family] section", path.display()))?;
    let mut out = Vec::new();
    let fitted = needle_fe::family::FamilyRun::fitted(&f, set.dir())?;
    for run in needle_fe::family::FamilyRun::all(&f).into_iter().chain(fitted) {
        let (_, runs, _) = needle_fe::family::apply(c, &f, run);
        if needle_set::spec::select(&runs, opts.only.as_deref()).is_ok_and(|r| !r.is_empty()) {
            out.push(RunOptions { family_run: Some(run), ..opts.clone() });
        }
    }
    if out.is_empty() {
        anyhow::bail!(
            "--family --only {:?}: matches no run (names: centre_paper, the paper's tissue; <pose>_w<weight>, e.g. centre_w0p05, x+04_w0p2; fitted_<stack>_l<layer>)",
            opts.only.as_deref().unwrap_or("")
        );
    }
    Ok(out)
}

/// `opts` as it is, or with `visco`: once per speed of `[viscoelastic]`, in order; with
/// `[viscoelastic] frictionless` then the frictionless elastic companions and once per
/// speed frictionless. Variants whose runs `--only` does not select are left out.
fn visco_variants(set: &SetFolder, opts: RunOptions) -> anyhow::Result<Vec<RunOptions>> {
    use needle_fe::visco::Friction;
    if !opts.visco {
        return Ok(vec![opts]);
    }
    let (c, path) = (set.campaign(), set.spec_path());
    let v = c.viscoelastic.clone().ok_or_else(|| anyhow::anyhow!("{}: --visco: the spec has no [viscoelastic] section", path.display()))?;
    let selects = |runs: &[needle_set::spec::PoseSpec]| needle_set::spec::select(runs, opts.only.as_deref()).is_ok_and(|r| !r.is_empty());
    let mut out = Vec::new();
    for friction in Friction::cases(&v) {
        let frictionless = friction == Friction::None;
        if let Some((_, runs)) = needle_fe::visco::apply_frictionless_elastic(c, &v).filter(|_| frictionless) {
            if selects(&runs) {
                out.push(RunOptions { visco_frictionless: true, ..opts.clone() });
            }
        }
        for &speed in &v.speeds_mm_per_s {
            let (_, runs) = needle_fe::visco::apply(c, &v, speed, c.loading.steps, friction);
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
