//! `needle fe verify`: checks of the FE setup against theory and against itself.
//!
//! 1. **Flat punch (Sneddon)** ([`punch`]): a rigid flat-ended punch of the needle's
//!    radius pressed into the block, against Sneddon's half-space force (goal: within 5%).
//! 2. **Mesh study** ([`crate::mesh::study`]): the centre on the levels of `campaign.mesh_study`
//!    and the poses of `campaign.mesh_study_poses` on the committed level and its
//!    refinement (the next level, or `campaign.mesh_reference`); the shape after the best scale ([`crate::mesh::shape`]: goal 2 % RMS, 4 % largest),
//!    the absolute change of Fy and Richardson's estimate when in the asymptotic range.
//! 3. **Mirror runs**: each `mirror` pose against its mirrored counterpart from the
//!    committed data, with the sign flips of coeffs/README.md (goal 1% of peak |Fy|).
//! 4. **Smoothness** ([`smooth`]): in every result present, the must point furthest from
//!    its neighbours' mean (goal [`SMOOTH_GOAL_PERCENT`] of peak |Fy|): a state the
//!    solver accepted off the equilibrium path shows as such a point.
//! 5. **Scaling law** ([`scaling`]): the centre and a half-model pose with every Ogden
//!    mu_i scaled by 0.5 and 2 against s times the committed run (goal 0.5 % of peak |Fy|).
//! 6. **Viscoelastic ramp and hold** ([`qlv`](crate::visco::qlv)): the `[viscoelastic]` runs against the
//!    library's QLV filter on the elastic run (run by the CLI, `needle fe verify --qlv`;
//!    goal RMS 3 %, must 5 %, largest 6 % of peak |Fy|), written with [`write_tables`].

pub mod edge;
mod mirror;
pub mod punch;
pub mod punch_febio;
pub mod scaling;
pub mod smooth;

pub use crate::mesh::study::{richardson, LevelRun, MeshReport};
pub use mirror::{MirrorReport, MIRROR_GOAL_PERCENT};
pub use punch::{
    bonded_punch_force, poisson, punch_deck, punch_mesh, sneddon_force, PunchDeck, PunchElement, PunchReport, PunchRun,
    PUNCH_CORE_ELEMENTS_C3D20R, PUNCH_CORE_ELEMENTS_C3D8, PUNCH_GOAL_PERCENT, PUNCH_GROWTH, PUNCH_MU_N_PER_MM2,
};
pub use smooth::{SmoothReport, SMOOTH_GOAL_PERCENT};

use super::spec;
use crate::campaign;
use crate::set_folder::SetFolder;
use anyhow::{Context, Result};
use serde::Serialize;
use std::path::PathBuf;

/// What to verify.
#[derive(Debug, Clone)]
pub struct VerifyOptions {
    /// The set folder (with campaign.toml and fe/).
    pub set_dir: PathBuf,
    /// Run the flat-punch check.
    pub punch: bool,
    /// Run the mesh study with these options (`None`: not run; the fine runs are slow).
    pub mesh: Option<crate::mesh::study::MeshOptions>,
    /// Run the edge study (`campaign.edge_study_radii_mm`) with these options (their
    /// `edge_radius_mm` is set per radius; `None`: not run).
    pub edge: Option<crate::mesh::study::MeshOptions>,
    /// Check the mirror runs (no solve).
    pub mirror: bool,
    /// Check every result present for a must point off its neighbours (no solve).
    pub smooth: bool,
    /// Run the scaling-law check with these options (`None`: not run).
    pub scaling: Option<scaling::ScalingOptions>,
    /// Coarsening of the flat-punch mesh: 1 = the verification mesh; 2 = half the
    /// elements across the punch and twice the fine size (quick tests).
    pub punch_mesh_scale: f64,
    /// Also solve the flat punch with the campaign's element (C3D8) and report its
    /// error (no goal: it measures the element's volumetric locking).
    pub punch_campaign_element: bool,
    /// Where to keep work folders (default `<set>/fe/.work/verify`).
    pub work_dir: Option<PathBuf>,
    /// Solver threads of each solve (FEBio; ccx always runs on one).
    pub threads: usize,
    /// The engine instead of the spec's `[solver] engine`.
    pub engine: Option<spec::Engine>,
}

/// Everything `needle fe verify` measured.
#[derive(Debug, Clone, Default, Serialize)]
pub struct VerifyReport {
    /// Flat punch against Sneddon.
    pub punch: Option<PunchReport>,
    /// Committed mesh against the fine one.
    pub mesh: Option<MeshReport>,
    /// Mirror runs.
    pub mirror: Vec<MirrorReport>,
    /// Each result's must point furthest from its neighbours' mean.
    pub smooth: Vec<SmoothReport>,
    /// The scaling law.
    pub scaling: Option<scaling::ScalingReport>,
    /// The edge study, one per radius.
    pub edge: Vec<edge::EdgeStudy>,
}

/// Prints each report's line and says whether every one is within `goal_percent`.
fn print_judged<R: std::fmt::Display>(reports: &[R], percent: impl Fn(&R) -> f64, goal_percent: f64) -> bool {
    let mut ok = true;
    for r in reports {
        needle_stdx::outln!("{r}");
        ok &= percent(r) <= goal_percent;
    }
    ok
}

/// Run the checks on the set `set` (opened once by the caller; `opts.set_dir` is its
/// folder), print the table, write `<set>/fe/verify.toml`.
///
/// # Errors
/// ccx missing or failing, missing FE files for the mirror check.
pub fn run(set: &SetFolder, opts: &VerifyOptions) -> Result<(VerifyReport, bool)> {
    let mut c = set.campaign().clone();
    if let Some(e) = opts.engine {
        c.solver.engine = e;
    }
    let work = opts.work_dir.clone().unwrap_or_else(|| opts.set_dir.join("fe").join(".work").join("verify"));
    let mut report = VerifyReport::default();
    let mut ok = true;
    if opts.mirror {
        report.mirror = mirror::mirror_checks(&c, &opts.set_dir.join("fe"))?;
        ok &= print_judged(&report.mirror, |m| m.percent_of_peak_fy, MIRROR_GOAL_PERCENT);
    }
    if opts.smooth {
        report.smooth = smooth::smooth_checks(&c, &opts.set_dir.join("fe"))?;
        ok &= print_judged(&report.smooth, |s| s.percent_of_peak_fy, SMOOTH_GOAL_PERCENT);
    }
    if let Some(o) = &opts.scaling {
        let s = scaling::scaling_check(set, &c, o)?;
        ok &= s.ok();
        report.scaling = Some(s);
    }
    if opts.punch {
        let p = match c.solver.engine {
            crate::spec::Engine::Febio => punch_febio::punch(&c, &work, opts)?,
            crate::spec::Engine::Ccx => punch::punch(&c, &work, opts)?,
        };
        print_punch(&p);
        ok &= p.check.error_percent.abs() <= p.goal_percent;
        report.punch = Some(p);
    }
    if let Some(o) = &opts.mesh {
        let m = mesh_study(set, &c, o)?;
        print_mesh_study(&m);
        ok &= m.ok();
        report.mesh = Some(m);
    }
    if let Some(o) = &opts.edge {
        report.edge = edge::edge_study(set, &c, o)?;
    }
    let mut new: toml::Table = toml::Table::try_from(&report).context("cannot serialise the verify report")?;
    // only the checks that ran replace their part of an earlier verify.toml
    if !opts.mirror {
        new.remove("mirror");
    }
    if !opts.smooth {
        new.remove("smooth");
    }
    if opts.edge.is_none() {
        new.remove("edge");
    }
    write_tables(&opts.set_dir, new)?;
    Ok((report, ok))
}

/// The mesh study of `o` ([`crate::mesh::study::mesh_convergence`]) with the campaign's
/// runner: each level's runs solved (when the study asks) and read through
/// `campaign::runs` on `set`, `o.threads` solver threads each.
///
/// # Errors
/// As [`crate::mesh::study::mesh_convergence`] and [`campaign::runs::solve_and_read`].
pub fn mesh_study(set: &SetFolder, c: &spec::Campaign, o: &crate::mesh::study::MeshOptions) -> Result<MeshReport> {
    crate::mesh::study::mesh_convergence(c, o, &mut |l| {
        let opts = campaign::RunOptions {
            only: Some(l.poses.join(",")),
            mesh: Some(l.level.to_string()),
            out_dir: Some(l.out_dir.to_path_buf()),
            threads: o.threads,
            edge_radius_mm: o.edge_radius_mm,
            ..campaign::RunOptions::new(&o.set_dir)
        };
        if l.solve {
            campaign::runs::solve_and_read(set, &opts)
        } else {
            campaign::runs::read_current(set, &opts)
        }
    })
}

/// The flat-punch check's lines: the block, twice the block, the half-space extrapolated
/// against Sneddon, and the campaign element's (no goal) when it ran.
fn print_punch(p: &PunchReport) {
    needle_stdx::outln!(
        "flat punch a = {} mm, delta = {} mm, nu = {:.4}, {}: F(block) = {:.5e} N, F(2x block) = {:.5e} N, \
         F(half-space, extrapolated) = {:.5e} N, Sneddon {:.5e} N: error {:+.2}% (goal within {}%); {} {:.0} s + {:.0} s",
        p.radius_mm,
        p.delta_mm,
        p.nu,
        p.check.element,
        p.check.force_block_n,
        p.check.force_block_2x_n,
        p.check.force_half_space_n,
        p.force_sneddon_n,
        p.check.error_percent,
        p.goal_percent,
        p.solver,
        p.check.wall_s[0],
        p.check.wall_s[1]
    );
    if let Some(r) = &p.campaign_element {
        needle_stdx::outln!(
            "  campaign element {}: F(block) = {:.5e} N, F(2x block) = {:.5e} N, F(half-space) = {:.5e} N: {:+.2}% \
             (no goal: volumetric locking of the fully integrated C3D8 at K0/mu0 = {}); ccx {:.0} s + {:.0} s",
            r.element,
            r.force_block_n,
            r.force_block_2x_n,
            r.force_half_space_n,
            r.error_percent,
            p.bulk_to_shear,
            r.wall_s[0],
            r.wall_s[1]
        );
    }
}

/// The mesh study's lines: the committed and refined centre Fy, and Richardson's estimate
/// when three levels are in the asymptotic range.
fn print_mesh_study(m: &MeshReport) {
    needle_stdx::outln!(
        "mesh study, centre Fy({} mm): {} vs {} {}; {}{}",
        m.depth_mm,
        m.committed,
        m.refined,
        m.difference_percent.map(|d| format!("{d:+.2}% (absolute level: reported, not judged)")).unwrap_or_else(|| "no comparison".into()),
        m.asymptotic,
        m.ratio_of_changes.map(|r| format!(" (ratio of successive changes {r:.3})")).unwrap_or_default()
    );
    if let (Some(f), Some(p), Some(d)) = (m.richardson_fy_n, m.richardson_order, m.committed_vs_richardson_percent) {
        needle_stdx::outln!(
            "  Richardson estimate of the converged Fy: {f:.5e} N (observed order {p:.2}); committed level {d:+.2}% from it"
        );
    }
}

/// Replace the table `name` of `<set>/fe/verify.toml` with `value` ([`write_tables`]).
///
/// # Errors
/// `value` does not serialise as TOML, or the file cannot be written.
pub fn write_table(set_dir: &std::path::Path, name: &str, value: &impl Serialize) -> Result<()> {
    let mut t = toml::Table::new();
    t.insert(name.to_string(), toml::Value::try_from(value).with_context(|| format!("cannot serialise verify.toml's [{name}]"))?);
    write_tables(set_dir, t)
}

/// Replace the tables of `new` in `<set>/fe/verify.toml` (atomically), keeping the
/// others: a check that did not run keeps its table from the last run that did.
///
/// # Errors
/// The file cannot be written.
pub fn write_tables(set_dir: &std::path::Path, new: toml::Table) -> Result<()> {
    let path = set_dir.join("fe").join("verify.toml");
    let mut old: toml::Table = std::fs::read_to_string(&path).ok().and_then(|t| t.parse().ok()).unwrap_or_default();
    for (k, v) in new {
        old.insert(k, v);
    }
    let text = format!("# written by `needle fe verify`; do not edit\n{}", toml::to_string(&old)?);
    needle_stdx::fs::write_atomic(&path, text.as_bytes())?;
    needle_stdx::outln!("wrote {}", path.display());
    Ok(())
}
