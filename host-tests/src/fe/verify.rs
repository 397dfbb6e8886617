//! `needle fe verify`: checks of the FE setup against theory and against itself.
//!
//! 1. **Flat punch (Sneddon)**: a rigid flat-ended cylindrical punch of radius `a` (the
//!    needle's radius) bonded to the top surface is pressed `delta = a / 100` into the
//!    block, whose tissue is replaced by a near-incompressible neo-Hookean material
//!    (Ogden N = 1, alpha = 2, mu = 1 N/mm^2, the tissue's K0/mu0). Sneddon's
//!    half-space solution is `F = 4 mu a delta / (1 - nu)` (= `8 mu a delta` when
//!    nu = 1/2; for nu -> 1/2 bonded and frictionless punches give the same force).
//!    The block is finite (30 mm deep on a rigid base, 50 mm wide), which stiffens it by
//!    a factor `1 + k a / h + O((a/h)^2)`. The check solves the punch on the block and
//!    on a block scaled 2x in every direction, and extrapolates linearly in `a / h` to
//!    the half-space: `F_inf = 2 F_2x - F_1x`. That is compared with Sneddon (goal 5%).
//! 2. **Mesh convergence**: the centred vertical needle on the committed mesh and on the
//!    `fine` mesh level (2x refined near the needle), Fy at full depth (goal 2%).
//! 3. **Mirror runs**: each `mirror` pose against its mirrored counterpart from the
//!    committed data, with the sign flips of coeffs/README.md (goal 1% of peak |Fy|).

use super::ccx;
use super::dat;
use super::deck::{self, Deck};
use super::mesh;
use super::results::{self, Row};
use super::spec::{self, Campaign, PoseSpec, Role, Symmetry};
use super::wrench;
use anyhow::{bail, Context, Result};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// What to verify.
#[derive(Debug, Clone)]
pub struct VerifyOptions {
    /// The set folder (with campaign.toml and fe/).
    pub set_dir: PathBuf,
    /// Run the flat-punch check.
    pub punch: bool,
    /// Run the mesh-convergence check (two needle solves, the fine one is slow).
    pub mesh: bool,
    /// Check the mirror runs (no solve).
    pub mirror: bool,
    /// Where to keep work folders (default `<set>/fe/.work/verify`).
    pub work_dir: Option<PathBuf>,
}

/// Flat-punch result.
#[derive(Debug, Clone, Serialize)]
pub struct PunchReport {
    /// Punch radius, mm.
    pub radius_mm: f64,
    /// Indentation, mm.
    pub delta_mm: f64,
    /// Shear modulus of the neo-Hookean block, N/mm^2.
    pub mu_n_per_mm2: f64,
    /// Poisson's ratio from K0/mu0.
    pub nu: f64,
    /// Force on the block as specified, N.
    pub force_block_n: f64,
    /// Force on the block scaled 2x, N.
    pub force_block_2x_n: f64,
    /// Linear extrapolation to the half-space, N.
    pub force_half_space_n: f64,
    /// Sneddon: 4 mu a delta / (1 - nu), N.
    pub force_sneddon_n: f64,
    /// (F_inf - F_Sneddon) / F_Sneddon, %.
    pub error_percent: f64,
}

/// Mesh-convergence result.
#[derive(Debug, Clone, Serialize)]
pub struct MeshReport {
    /// Mesh level of the committed data.
    pub committed: String,
    /// Fy at full depth on it, N.
    pub fy_committed_n: f64,
    /// Fy at full depth on the fine level, N.
    pub fy_fine_n: f64,
    /// (committed - fine) / fine, %.
    pub difference_percent: f64,
    /// Wall time of the committed-mesh run, s.
    pub wall_committed_s: f64,
    /// Wall time of the fine-mesh run, s.
    pub wall_fine_s: f64,
}

/// Mirror-run result of one pose.
#[derive(Debug, Clone, Serialize)]
pub struct MirrorReport {
    /// The mirror pose.
    pub pose: String,
    /// Its counterpart on the positive side.
    pub counterpart: String,
    /// Largest difference over depths and components after the sign flips, N or N*mm.
    pub max_difference: f64,
    /// Component of that difference.
    pub component: String,
    /// That difference as % of the counterpart's peak |Fy| (forces) or of peak |Fy| times
    /// `needle.reference_from_tip_mm` (moments: the moment the peak axial force would make
    /// on the hub's lever arm).
    pub percent_of_peak_fy: f64,
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
}

/// Components in file order.
pub const COMPONENTS: [&str; 6] = ["fx_n", "fy_n", "fz_n", "mx_nmm", "my_nmm", "mz_nmm"];

/// Shear modulus of the flat-punch block, N/mm^2.
pub const PUNCH_MU_N_PER_MM2: f64 = 1.0;

/// Run the checks, print the table, write `<set>/fe/verify.toml`.
///
/// # Errors
/// ccx missing or failing, missing FE files for the mirror check.
pub fn run(opts: &VerifyOptions) -> Result<(VerifyReport, bool)> {
    let (c, _) = spec::load(&opts.set_dir)?;
    let work = opts.work_dir.clone().unwrap_or_else(|| opts.set_dir.join("fe").join(".work").join("verify"));
    let mut report = VerifyReport::default();
    let mut ok = true;
    if opts.mirror {
        report.mirror = mirror_checks(&c, &opts.set_dir.join("fe"))?;
        for m in &report.mirror {
            println!(
                "mirror {:>6} vs {:>6}: max difference {:.3e} ({}) = {:.3}% of peak |Fy| (goal <= 1%)",
                m.pose, m.counterpart, m.max_difference, m.component, m.percent_of_peak_fy
            );
            ok &= m.percent_of_peak_fy <= 1.0;
        }
    }
    if opts.punch {
        let p = punch(&c, &work)?;
        println!(
            "flat punch a = {} mm, delta = {} mm, nu = {:.4}: F(block) = {:.5e} N, F(2x block) = {:.5e} N, \
             F(half-space, extrapolated) = {:.5e} N, Sneddon {:.5e} N: error {:+.2}% (goal within 5%)",
            p.radius_mm, p.delta_mm, p.nu, p.force_block_n, p.force_block_2x_n, p.force_half_space_n, p.force_sneddon_n, p.error_percent
        );
        ok &= p.error_percent.abs() <= 5.0;
        report.punch = Some(p);
    }
    if opts.mesh {
        let m = mesh_convergence(&c, &work)?;
        println!(
            "mesh convergence, centred vertical needle: Fy(6 mm) = {:.5e} N on {:?} ({:.0} s), {:.5e} N on \"fine\" ({:.0} s): {:+.2}% (goal within 2%)",
            m.fy_committed_n, m.committed, m.wall_committed_s, m.fy_fine_n, m.wall_fine_s, m.difference_percent
        );
        ok &= m.difference_percent.abs() <= 2.0;
        report.mesh = Some(m);
    }
    let path = opts.set_dir.join("fe").join("verify.toml");
    let mut old: toml::Table = std::fs::read_to_string(&path).ok().and_then(|t| t.parse().ok()).unwrap_or_default();
    let new: toml::Table = toml::Table::try_from(&report).context("cannot serialise the verify report")?;
    for (k, v) in new {
        old.insert(k, v);
    }
    let text = format!("# written by `needle fe verify`; do not edit\n{}", toml::to_string(&old)?);
    results::write_atomic(&path, text.as_bytes())?;
    println!("wrote {}", path.display());
    Ok((report, ok))
}

/// Solve a deck in `work/<name>` and return the wrench rows (depth 0 row included).
///
/// # Errors
/// ccx missing, failing (with the tail of its output), or output without the printed set.
pub fn solve(c: &Campaign, pose: &PoseSpec, d: &Deck, work: &Path, name: &str) -> Result<(Vec<Row>, f64)> {
    let dir = work.join(name);
    std::fs::create_dir_all(&dir).with_context(|| format!("{}: cannot create", dir.display()))?;
    std::fs::write(dir.join(format!("{name}.inp")), &d.text)?;
    let exe = ccx::find_ccx()?;
    let job = ccx::run_job(&exe, &dir, name, None)?;
    if !job.success() {
        bail!("{name}: ccx failed ({}); last lines of {}:\n{}", job.exit, job.log_path.display(), job.log_tail);
    }
    let dat_path = dir.join(format!("{name}.dat"));
    let text = std::fs::read_to_string(&dat_path).with_context(|| format!("{}: cannot read", dat_path.display()))?;
    let steps = dat::parse_rf(&text, &d.print_set).with_context(|| format!("{}", dat_path.display()))?;
    if steps.len() != d.steps as usize {
        bail!("{name}: {} result blocks in {}, expected {}", steps.len(), dat_path.display(), d.steps);
    }
    let mut rows = vec![Row { depth_mm: 0.0, wrench: [0.0; 6] }];
    for (k, s) in steps.iter().enumerate() {
        rows.push(Row {
            depth_mm: c.loading.depth_mm * (k as f64 + 1.0) / f64::from(d.steps),
            wrench: wrench::reduce(d, pose, c, &s.nodes)?,
        });
    }
    Ok((rows, job.wall.as_secs_f64()))
}

fn mesh_convergence(c: &Campaign, work: &Path) -> Result<MeshReport> {
    let centre = c.pose.iter().find(|p| p.role == Role::Centre).context("no pose with role centre in the spec")?;
    let committed = c.campaign.mesh.clone();
    let mut out = Vec::new();
    for level in [committed.as_str(), "fine"] {
        let m = c.mesh_level(level)?;
        let d = deck::write_deck(c, centre, m, c.loading.steps)?;
        println!("solving the centred needle on mesh {level:?} ({} tissue elements) ...", d.summary.tissue_elements);
        let (rows, wall) = solve(c, centre, &d, work, &format!("mesh-{level}"))?;
        let fy = rows.last().map(|r| r.wrench[1]).unwrap_or(f64::NAN);
        out.push((fy, wall));
    }
    let (a, b) = (out[0], out[1]);
    Ok(MeshReport {
        committed,
        fy_committed_n: a.0,
        fy_fine_n: b.0,
        difference_percent: 100.0 * (a.0 - b.0) / b.0,
        wall_committed_s: a.1,
        wall_fine_s: b.1,
    })
}

/// The punch mesh: core disc of the punch radius, 12 x 12 elements, fine 0.06 mm.
fn punch_mesh(radius_mm: f64) -> spec::MeshLevel {
    spec::MeshLevel {
        core_half_mm: radius_mm,
        core_elements: 12,
        fine_size_mm: radius_mm / 6.0,
        fine_depth_mm: radius_mm,
        growth: 1.3,
        needle_facets_per_quarter: 4,
        needle_axial_mm: 0.3,
    }
}

fn punch(c: &Campaign, work: &Path) -> Result<PunchReport> {
    let a = c.needle.diameter_mm / 2.0;
    let delta = a / 100.0;
    // Sneddon's force is linear in mu; the punch uses mu = 1 N/mm^2 (the tissue's K0/mu0)
    // because ccx's convergence tests have absolute floors that forces of 1e-6 N (the
    // tissue's own mu at 1% indentation) sit below.
    let mu = PUNCH_MU_N_PER_MM2;
    let k0 = c.tissue.bulk_to_shear * mu;
    let nu = (3.0 * k0 - 2.0 * mu) / (2.0 * (3.0 * k0 + mu));
    let mut forces = Vec::new();
    for scale in [1.0, 2.0] {
        let name = format!("punch-{scale}x");
        let text = punch_deck(c, a, delta, scale)?;
        let dir = work.join(&name);
        std::fs::create_dir_all(&dir)?;
        std::fs::write(dir.join(format!("{name}.inp")), &text)?;
        println!("solving the flat punch on the block scaled {scale}x ...");
        let exe = ccx::find_ccx()?;
        let job = ccx::run_job(&exe, &dir, &name, None)?;
        if !job.success() {
            bail!("{name}: ccx failed ({}); last lines:\n{}", job.exit, job.log_tail);
        }
        let dat_text = std::fs::read_to_string(dir.join(format!("{name}.dat")))?;
        let steps = dat::parse_rf(&dat_text, "PUNCH")?;
        let last = steps.last().context("punch: no result block")?;
        // quarter model: the whole punch carries 4x; the tissue pushes the punch up (+y)
        let fy: f64 = -4.0 * last.nodes.iter().map(|(_, f)| f[1]).sum::<f64>();
        forces.push(fy);
    }
    let f_inf = 2.0 * forces[1] - forces[0];
    let f_sneddon = 4.0 * mu * a * delta / (1.0 - nu);
    Ok(PunchReport {
        radius_mm: a,
        delta_mm: delta,
        mu_n_per_mm2: mu,
        nu,
        force_block_n: forces[0],
        force_block_2x_n: forces[1],
        force_half_space_n: f_inf,
        force_sneddon_n: f_sneddon,
        error_percent: 100.0 * (f_inf - f_sneddon) / f_sneddon,
    })
}

/// Deck of the bonded flat punch on a quarter model of the block scaled by `scale`.
fn punch_deck(c: &Campaign, a: f64, delta: f64, scale: f64) -> Result<String> {
    let mut block = c.block.clone();
    block.size_x_mm *= scale;
    block.size_z_mm *= scale;
    block.depth_mm *= scale;
    let pose = PoseSpec { name: "punch".into(), role: Role::Centre, x_mm: 0.0, z_mm: 0.0, theta_x_deg: 0.0, theta_z_deg: 0.0 };
    let sym = Symmetry { plane_x: true, plane_z: true };
    let t = mesh::tissue_shaped(&block, &punch_mesh(a), &pose, sym, 0.0, true);
    let under: Vec<usize> = t
        .nodes
        .iter()
        .enumerate()
        .filter(|(_, p)| p[1].abs() < 1e-9 && (p[0] * p[0] + p[2] * p[2]).sqrt() <= a * (1.0 + 1e-6))
        .map(|(i, _)| i)
        .collect();
    if under.len() < 4 {
        bail!("punch: only {} nodes under the punch", under.len());
    }
    let mu = PUNCH_MU_N_PER_MM2;
    let d1 = 2.0 / (c.tissue.bulk_to_shear * mu);
    let mut s = String::new();
    let _ = writeln!(s, "** needle-haptics flat-punch verification: radius {a} mm, indentation {delta} mm, block scaled {scale}x");
    let _ = writeln!(s, "** quarter model, bonded rigid punch (prescribed displacement of the nodes under it)");
    deck::write_tissue(&mut s, &t);
    let _ = writeln!(s, "*NSET, NSET=PUNCH");
    for chunk in under.chunks(12) {
        let ids: Vec<String> = chunk.iter().map(|i| (i + 1).to_string()).collect();
        let _ = writeln!(s, "{},", ids.join(","));
    }
    let _ = writeln!(s, "** neo-Hookean as Ogden N=1, alpha=2: mu = {mu:e} N/mm^2, D1 = 2/K0");
    let _ = writeln!(s, "*MATERIAL, NAME=TISSUE\n*HYPERELASTIC, OGDEN, N=1\n{mu:e}, 2., {d1:e}");
    let _ = writeln!(s, "*SOLID SECTION, ELSET=TISSUE, MATERIAL=TISSUE");
    deck::write_boundary(&mut s, &t);
    let _ = writeln!(s, "*STEP, NLGEOM, INC=100\n*STATIC\n0.5, 1., 1e-4, 0.5");
    let _ = writeln!(s, "*BOUNDARY\nPUNCH, 1, 1, 0.\nPUNCH, 2, 2, {:.9}\nPUNCH, 3, 3, 0.", -delta);
    let _ = writeln!(s, "*NODE PRINT, NSET=PUNCH\nRF\n*END STEP");
    Ok(s)
}

/// Each mirror pose against its counterpart: x -> -x flips (Fx, My, Mz), z -> -z flips
/// (Fz, Mx, My).
fn mirror_checks(c: &Campaign, fe: &Path) -> Result<Vec<MirrorReport>> {
    let poses = c.poses();
    let mut out = Vec::new();
    for m in poses.iter().filter(|p| p.role == Role::Mirror) {
        let (flip_x, flip_z) = (m.x_mm < 0.0 || m.theta_z_deg < 0.0, m.z_mm < 0.0 || m.theta_x_deg < 0.0);
        let want = PoseSpec {
            name: String::new(),
            role: m.role,
            x_mm: m.x_mm.abs(),
            z_mm: m.z_mm.abs(),
            theta_x_deg: m.theta_x_deg.abs(),
            theta_z_deg: m.theta_z_deg.abs(),
        };
        let Some(cp) = poses.iter().find(|p| {
            p.role != Role::Mirror
                && p.x_mm == want.x_mm
                && p.z_mm == want.z_mm
                && p.theta_x_deg == want.theta_x_deg
                && p.theta_z_deg == want.theta_z_deg
        }) else {
            bail!("mirror pose {}: no counterpart pose with the mirrored values in the spec", m.name);
        };
        let a = results::read_csv(&fe.join(format!("{}.csv", m.name)))?;
        let b = results::read_csv(&fe.join(format!("{}.csv", cp.name)))?;
        if a.len() != b.len() {
            bail!("mirror pose {}: {} rows, counterpart {} has {}", m.name, a.len(), cp.name, b.len());
        }
        let mut sign = [1.0f64; 6];
        if flip_x {
            for i in [0, 4, 5] {
                sign[i] = -sign[i];
            }
        }
        if flip_z {
            for i in [2, 3, 4] {
                sign[i] = -sign[i];
            }
        }
        let peak = b.iter().map(|r| r.wrench[1].abs()).fold(0.0, f64::max);
        // forces against peak |Fy|; moments against peak |Fy| times the hub's lever arm
        let lever = c.needle.reference_from_tip_mm;
        let (mut worst, mut worst_rel, mut comp) = (0.0f64, 0.0f64, 0usize);
        for (ra, rb) in a.iter().zip(&b) {
            for i in 0..6 {
                let d = (ra.wrench[i] - sign[i] * rb.wrench[i]).abs();
                let rel = if i < 3 { d } else { d / lever };
                if rel > worst_rel {
                    worst_rel = rel;
                    worst = d;
                    comp = i;
                }
            }
        }
        out.push(MirrorReport {
            pose: m.name.clone(),
            counterpart: cp.name.clone(),
            max_difference: worst,
            component: COMPONENTS[comp].to_string(),
            percent_of_peak_fy: if peak > 0.0 { 100.0 * worst_rel / peak } else { f64::INFINITY },
        });
    }
    Ok(out)
}
