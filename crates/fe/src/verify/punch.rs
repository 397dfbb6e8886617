//! The flat-punch check of `needle fe verify`: a rigid flat-ended cylindrical punch of
//! radius `a` (the needle's radius, 0.5 mm) bonded to the top surface is pressed
//! `delta = a / 100` into the block; the reference is Sneddon's half-space force
//! `F = 4 mu a delta / (1 - nu)` (goal: within 5%). The choices, each measured with
//! ccx 2.20 (quarter model, one thread; numbers are `(F_inf - F_Sneddon) / F_Sneddon`):
//! - **Model**: quarter of the 50 x 50 x 30 mm block (mirror planes x = 0 and z = 0),
//!   sides pinned, bottom encastred as in the campaign; the punch is rigid and bonded:
//!   every node under it (on and inside the rim) gets the displacement (0, -delta, 0),
//!   and the force is 4x the sum of their reactions. For a bonded punch the exact
//!   half-space force is Mossakovskii's `4 mu a delta ln(3 - 4 nu) / (1 - 2 nu)`
//!   (reported as `force_bonded_n`); at nu = 0.495 it is 3e-5 above Sneddon's.
//! - **Material**: neo-Hookean, `*HYPERELASTIC, NEO HOOKE` with C10 = mu/2 and
//!   D1 = 2/K0, mu = 1 N/mm^2 and the tissue's K0/mu0 (100: nu = 0.495). Sneddon's
//!   force is linear in mu; mu = 1 keeps the forces (0.02 N) well above ccx's
//!   absolute convergence floors. The same energy written as `*HYPERELASTIC, OGDEN,
//!   N=1` (alpha = 2) does **not** converge in ccx 2.20: the first increment's
//!   residual wanders between 2e-4 and 7e-4 (average force 1.2e-5) instead of falling,
//!   and the increment is cut back below its minimum. That was the failure of the
//!   first version of this check, not the mesh (no inverted elements), the small
//!   forces or the geometry: the identical deck with NEO HOOKE converges in one
//!   increment of two iterations. The Ogden law works on principal stretches, which
//!   here are all nearly equal (strains below 1% almost everywhere); the invariant
//!   form has no such degeneracy.
//! - **Element: C3D20R** (20-node brick, reduced integration). ccx has no hybrid or
//!   B-bar (mean dilatation) brick: its C3D8 is fully integrated, and the ccx manual
//!   warns that it "behaves badly for isochoric material behaviour". At nu = 0.495 it
//!   locks: with C3D8 the check gives +23.7% (12 elements across the punch) and
//!   +19.4% (16 across), converging slowly; at K0/mu0 = 10 (nu = 0.45) on the
//!   12-across mesh the same C3D8 gives +7.2% against the bonded-punch force, so most
//!   of the C3D8 excess at K0/mu0 = 100 is volumetric locking. On that 12-across
//!   mesh: C3D8I +4.0%, C3D8R +5.3%, C3D20 (full integration) +2.6%, C3D20R +1.5%
//!   (the last two estimated with the same finite-block correction). The campaign
//!   meshes its tissue with C3D8 at K0/mu0 = 100, so `needle fe verify` also solves
//!   the punch with C3D8 on a mesh with as many nodes across the punch (16 elements)
//!   and reports that error as `campaign_element` (no goal): it measures how much
//!   stiffer than the continuum the campaign's tissue element is in confined,
//!   near-incompressible compression.
//! - **Mesh**: the campaign's O-grid with a round core of radius `a`
//!   ([`mesh::tissue_shaped`]), 8 elements across the punch (h = a/4) up to a depth
//!   a, then rings and layers growing by 1.3; the mid-side nodes of the rim lie on the
//!   circle. The remaining error comes from the stress singularity at the punch rim
//!   and is first order in h: +5.0% at h = a/2, +3.35% at a/3, +2.5% at a/4, which
//!   extrapolates to -0.1% at h -> 0 (the setup itself is exact to about 0.1%).
//! - **Indentation**: delta = a/100 keeps the problem linear: a linear elastic solve
//!   without NLGEOM gives a force 0.07% below the neo-Hookean NLGEOM one.
//! - **Finite block**: 30 mm deep on a rigid base and 50 mm wide, the block is stiffer
//!   than the half-space by a factor `1 + k a / h + O((a/h)^2)` (a/h = 1/60). The check
//!   solves the punch on the block and on the block scaled 2x in every direction (same
//!   mesh near the punch, more rings outside) and extrapolates linearly in a/h:
//!   `F_inf = 2 F_2x - F_1x`. The block as specified is 3.2% stiffer than F_inf. The
//!   linearity was checked with a 4x block (coarse mesh): its force is within 0.03% of
//!   the linear prediction, and `2 F_4x - F_2x` within 0.06% of `2 F_2x - F_1x`.
//!
//! Cost on the verification mesh (ccx, one thread, 2-core machine shared with the
//! FE campaign): C3D20R 13 481 / 22 061 nodes (block / 2x block), 40 s + 60-75 s;
//! C3D8 11 312 / 16 626 nodes, 15-25 s + 35 s (up to 4x longer under heavier load).
//! `punch_mesh_scale = 2` (4 C3D20R elements across the punch, 4 657 / 8 498 nodes)
//! takes about a minute and is the CI test (tests/fe_verify_punch.rs).

use super::VerifyOptions;
use crate::ccx::{self, dat};
use crate::mesh::{self, P3};
use crate::spec::{self, Campaign, PoseSpec, Role, Symmetry};
use anyhow::{bail, Context, Result};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;

/// Flat-punch result.
#[derive(Debug, Clone, Serialize)]
pub struct PunchReport {
    /// Punch radius, mm.
    pub radius_mm: f64,
    /// Indentation, mm.
    pub delta_mm: f64,
    /// Shear modulus of the neo-Hookean block, N/mm^2.
    pub mu_n_per_mm2: f64,
    /// Bulk / shear modulus (the tissue's K0/mu0).
    pub bulk_to_shear: f64,
    /// Poisson's ratio from K0/mu0.
    pub nu: f64,
    /// The block's material as written in the deck.
    pub material: String,
    /// The block's mesh in words.
    pub mesh: String,
    /// Coarsening factor of the mesh (1 = the verification mesh).
    pub mesh_scale: f64,
    /// Sneddon: 4 mu a delta / (1 - nu), N (the reference of the goal).
    pub force_sneddon_n: f64,
    /// Bonded punch (Mossakovskii): 4 mu a delta ln(3 - 4 nu) / (1 - 2 nu), N.
    pub force_bonded_n: f64,
    /// Goal on |error_percent|.
    pub goal_percent: f64,
    /// The engine and its version, e.g. "ccx 2.20", "febio 4.11.0".
    pub solver: String,
    /// The check itself: the punch with C3D20R (its fields are written at the top level
    /// of the report).
    #[serde(flatten)]
    pub check: PunchRun,
    /// The same check with the campaign's tissue element (C3D8, fully integrated) on a
    /// mesh with as many nodes across the punch: no goal; its error is the stiffening
    /// (volumetric locking) of that element at the tissue's K0/mu0.
    pub campaign_element: Option<PunchRun>,
}

/// Shear modulus of the flat-punch block, N/mm^2.
pub const PUNCH_MU_N_PER_MM2: f64 = 1.0;

/// The punch block's mesh: the O-grid of the campaign with a round core of the punch
/// radius `a` and `core_elements` elements across it (`core_elements / 2` under the
/// punch's radius in the quarter model), first ring and first layers of size
/// `2 a / core_elements` over a depth `a`, then growth 1.3. `mesh_scale` > 1 coarsens it
/// (fewer core elements, larger fine size) for quick tests.
pub fn punch_mesh(radius_mm: f64, core_elements: u32, mesh_scale: f64) -> spec::MeshLevel {
    let n = ((f64::from(core_elements) / mesh_scale / 2.0).round() as u32).max(1) * 2;
    spec::MeshLevel {
        core_half_mm: radius_mm,
        core_elements: n,
        fine_size_mm: 2.0 * radius_mm / f64::from(n),
        fine_depth_mm: radius_mm,
        growth: PUNCH_GROWTH,
        needle_facets_per_quarter: 4,
        needle_axial_mm: 0.3,
        etol: None,
        rtol: None,
        retry_rtol: None,
        retry_min_residual_n: None,
        first_attempt_retry_tolerances: None,
    }
}

/// Geometric growth of the punch mesh's rings and layers away from the punch.
pub const PUNCH_GROWTH: f64 = 1.3;

/// Poisson's ratio of an isotropic material with bulk / shear modulus ratio `k_over_mu`.
pub fn poisson(k_over_mu: f64) -> f64 {
    (3.0 * k_over_mu - 2.0) / (2.0 * (3.0 * k_over_mu + 1.0))
}

/// Sneddon (1965): rigid flat-ended cylinder of radius `a` pressed `delta` into a
/// frictionless elastic half-space, `F = 4 mu a delta / (1 - nu)`.
pub fn sneddon_force(mu: f64, a: f64, delta: f64, nu: f64) -> f64 {
    4.0 * mu * a * delta / (1.0 - nu)
}

/// Mossakovskii / Spence: the same punch bonded to the half-space (no slip),
/// `F = 4 mu a delta ln(3 - 4 nu) / (1 - 2 nu)`; equal to Sneddon's at nu = 1/2 and
/// 1.1 times it at nu = 0. For nu = 1/2 exactly the limit `8 mu a delta` is returned.
pub fn bonded_punch_force(mu: f64, a: f64, delta: f64, nu: f64) -> f64 {
    let e = 1.0 - 2.0 * nu;
    if e.abs() < 1e-9 {
        return 8.0 * mu * a * delta;
    }
    4.0 * mu * a * delta * (3.0 - 4.0 * nu).ln() / e
}

/// One flat-punch solve pair (block and 2x block) with one element type.
#[derive(Debug, Clone, Serialize)]
pub struct PunchRun {
    /// CalculiX element type of the block.
    pub element: String,
    /// Nodes of the block's mesh (as specified / scaled 2x).
    pub nodes: [usize; 2],
    /// Elements of the block's mesh (as specified / scaled 2x).
    pub elements: [usize; 2],
    /// Force on the block as specified, N.
    pub force_block_n: f64,
    /// Force on the block scaled 2x, N.
    pub force_block_2x_n: f64,
    /// Linear extrapolation in a/h to the half-space, `2 F_2x - F_1x`, N.
    pub force_half_space_n: f64,
    /// (F_inf - F_Sneddon) / F_Sneddon, %.
    pub error_percent: f64,
    /// Finite-block stiffening of the block as specified, (F_1x - F_inf) / F_inf, %.
    pub finite_block_percent: f64,
    /// ccx wall time of the two solves, s (one thread, on a shared machine).
    pub wall_s: [f64; 2],
}

impl PunchRun {
    /// The run from the forces on the block as specified and scaled 2x (`f`, N): the
    /// half-space force by linear extrapolation in a/h, `2 F_2x - F_1x`, and its error
    /// against Sneddon's `f_sneddon`.
    pub fn from_forces(element: &str, nodes: [usize; 2], elements: [usize; 2], f: [f64; 2], wall_s: [f64; 2], f_sneddon: f64) -> Self {
        let f_inf = 2.0 * f[1] - f[0];
        PunchRun {
            element: element.to_string(),
            nodes,
            elements,
            force_block_n: f[0],
            force_block_2x_n: f[1],
            force_half_space_n: f_inf,
            error_percent: 100.0 * (f_inf - f_sneddon) / f_sneddon,
            finite_block_percent: 100.0 * (f[0] - f_inf) / f_inf,
            wall_s,
        }
    }
}

/// A finite element for the punch block.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PunchElement {
    /// 20-node brick with reduced integration (2x2x2 points): the element of the check.
    C3D20R,
    /// 8-node brick, fully integrated: the campaign's tissue element.
    C3D8,
}

impl PunchElement {
    /// CalculiX name.
    pub fn name(self) -> &'static str {
        match self {
            PunchElement::C3D20R => "C3D20R",
            PunchElement::C3D8 => "C3D8",
        }
    }
}

pub(super) fn punch(c: &Campaign, work: &Path, opts: &VerifyOptions) -> Result<PunchReport> {
    let a = c.needle.diameter_mm / 2.0;
    let delta = a / 100.0;
    // Sneddon's force is linear in mu; the punch uses mu = 1 N/mm^2 (and the tissue's
    // K0/mu0) because ccx's convergence tests have absolute floors that forces of 1e-6 N
    // (the tissue's own mu at 1% indentation) sit below.
    let mu = PUNCH_MU_N_PER_MM2;
    let nu = poisson(c.tissue.bulk_to_shear);
    let f_sneddon = sneddon_force(mu, a, delta, nu);
    let mut runs = Vec::new();
    let mut elements = vec![PunchElement::C3D20R];
    if opts.punch_campaign_element {
        elements.push(PunchElement::C3D8);
    }
    for el in elements {
        let core = if el == PunchElement::C3D20R { PUNCH_CORE_ELEMENTS_C3D20R } else { PUNCH_CORE_ELEMENTS_C3D8 };
        let mesh = punch_mesh(a, core, opts.punch_mesh_scale);
        let mut f = [0.0; 2];
        let mut wall = [0.0; 2];
        let mut nodes = [0; 2];
        let mut nel = [0; 2];
        for (k, scale) in [1.0, 2.0].into_iter().enumerate() {
            let name = format!("punch-{}-{scale}x", el.name().to_ascii_lowercase());
            let d = punch_deck(c, &mesh, el, a, delta, scale)?;
            let dir = work.join(&name);
            std::fs::create_dir_all(&dir).with_context(|| format!("{}: cannot create", dir.display()))?;
            std::fs::write(dir.join(format!("{name}.inp")), &d.text)?;
            needle_stdx::outln!(
                "solving the flat punch with {} on the block scaled {scale}x ({} nodes, {} elements) ...",
                el.name(),
                d.nodes,
                d.elements
            );
            let exe = ccx::find_ccx()?;
            let job = ccx::run_job(&exe, &dir, &name, None, None)?;
            if !job.success() {
                bail!("{name}: ccx failed ({}); last lines of {}:\n{}", job.exit, job.log_path.display(), job.log_tail);
            }
            let dat_path = dir.join(format!("{name}.dat"));
            let dat_text = std::fs::read_to_string(&dat_path).with_context(|| format!("{}: cannot read", dat_path.display()))?;
            let steps = dat::parse_rf(&dat_text, "PUNCH").with_context(|| format!("{}", dat_path.display()))?;
            let last = steps.last().context("punch: no result block")?;
            if (last.total_time - 1.0).abs() > 1e-6 {
                bail!("{name}: the last result is at time {}, not 1 (the solve stopped early)", last.total_time);
            }
            // quarter model: the whole punch carries 4x; the tissue pushes the punch up (+y)
            f[k] = -4.0 * last.nodes.iter().map(|(_, r)| r[1]).sum::<f64>();
            if !f[k].is_finite() || f[k] <= 0.0 {
                bail!("{name}: punch force {} N is not a positive number", f[k]);
            }
            wall[k] = job.wall.as_secs_f64();
            nodes[k] = d.nodes;
            nel[k] = d.elements;
        }
        runs.push(PunchRun::from_forces(el.name(), nodes, nel, f, wall, f_sneddon));
    }
    let check = runs.remove(0);
    let mesh = punch_mesh(a, PUNCH_CORE_ELEMENTS_C3D20R, opts.punch_mesh_scale);
    Ok(PunchReport {
        radius_mm: a,
        delta_mm: delta,
        mu_n_per_mm2: mu,
        bulk_to_shear: c.tissue.bulk_to_shear,
        nu,
        material: "neo-Hookean (*HYPERELASTIC, NEO HOOKE: C10 = mu/2, D1 = 2/K0)".to_string(),
        mesh: format!(
            "quarter model, round-core O-grid: {} elements across the punch diameter, fine size {:.4} mm over {} mm depth, growth {}",
            mesh.core_elements, mesh.fine_size_mm, mesh.fine_depth_mm, mesh.growth
        ),
        mesh_scale: opts.punch_mesh_scale,
        force_sneddon_n: f_sneddon,
        force_bonded_n: bonded_punch_force(mu, a, delta, nu),
        goal_percent: PUNCH_GOAL_PERCENT,
        solver: format!("ccx {}", ccx::ccx_version(&ccx::find_ccx()?)?),
        check,
        campaign_element: runs.pop(),
    })
}

/// Elements across the punch diameter with C3D20R (the check).
pub const PUNCH_CORE_ELEMENTS_C3D20R: u32 = 8;
/// Elements across the punch diameter with C3D8 (the campaign-element comparison: the
/// same number of nodes across the punch as the C3D20R mesh).
pub const PUNCH_CORE_ELEMENTS_C3D8: u32 = 16;
/// Goal of the check, % of Sneddon's force.
pub const PUNCH_GOAL_PERCENT: f64 = 5.0;

/// A flat-punch deck and the size of its mesh.
#[derive(Debug, Clone)]
pub struct PunchDeck {
    /// The `.inp` text.
    pub text: String,
    /// Nodes of the block.
    pub nodes: usize,
    /// Elements of the block.
    pub elements: usize,
    /// Nodes under the punch (prescribed displacement), quarter model.
    pub punch_nodes: usize,
}

/// Deck of the bonded flat punch (radius `a`, indentation `delta`) on a quarter model of
/// the block scaled by `scale`, meshed with `mesh` and element `el`.
///
/// # Errors
/// Fewer than 4 nodes under the punch (a mesh too coarse for the punch).
pub fn punch_deck(c: &Campaign, mesh: &spec::MeshLevel, el: PunchElement, a: f64, delta: f64, scale: f64) -> Result<PunchDeck> {
    let (block, t) = punch_block(c, mesh, scale);
    let (nodes, elements) = match el {
        PunchElement::C3D8 => (t.nodes.clone(), t.elements.iter().map(|e| e.to_vec()).collect::<Vec<_>>()),
        PunchElement::C3D20R => quadratic(&t.nodes, &t.elements, a),
    };
    let PunchSets { under, bottom, sides, sym_x, sym_z } = punch_sets(&nodes, &block, a)?;
    let mu = PUNCH_MU_N_PER_MM2;
    let k0 = c.tissue.bulk_to_shear * mu;
    let d1 = 2.0 / k0;
    let mut s = String::with_capacity(120 * (nodes.len() + elements.len()));
    let _ = writeln!(s, "** needle-haptics flat-punch verification: radius {a} mm, indentation {delta} mm, block scaled {scale}x");
    let _ =
        writeln!(s, "** quarter model (mirror planes x = 0, z = 0), bonded rigid punch: the nodes under it have a prescribed displacement");
    let _ = writeln!(s, "** tissue mesh: {}; {} {} elements; units mm, N, N/mm^2", t.info, elements.len(), el.name());
    let _ = writeln!(s, "*NODE, NSET=NBLOCK");
    for (i, p) in nodes.iter().enumerate() {
        let _ = writeln!(s, "{},{:.9},{:.9},{:.9}", i + 1, p[0], p[1], p[2]);
    }
    let _ = writeln!(s, "*ELEMENT, TYPE={}, ELSET=BLOCK", el.name());
    for (e, n) in elements.iter().enumerate() {
        let ids: Vec<String> = n.iter().map(|i| (i + 1).to_string()).collect();
        // 20-node elements continue on a second line (at most 16 entries a line)
        let (first, rest) = ids.split_at(ids.len().min(15));
        let _ = write!(s, "{},{}", e + 1, first.join(","));
        if rest.is_empty() {
            let _ = writeln!(s);
        } else {
            let _ = writeln!(s, ",\n{}", rest.join(","));
        }
    }
    for (name, set) in [("PUNCH", &under), ("BBOTTOM", &bottom), ("BSIDES", &sides), ("SYMX", &sym_x), ("SYMZ", &sym_z)] {
        let _ = writeln!(s, "*NSET, NSET={name}");
        for chunk in set.chunks(12) {
            let ids: Vec<String> = chunk.iter().map(|i| (i + 1).to_string()).collect();
            let _ = writeln!(s, "{},", ids.join(","));
        }
    }
    let _ = writeln!(s, "** neo-Hookean, mu = {mu:e} N/mm^2, K0 = {k0:e} N/mm^2: C10 = mu/2, D1 = 2/K0");
    let _ = writeln!(
        s,
        "** (the same energy as Ogden N=1, alpha=2; ccx's Ogden law does not converge here, see crates/fe/src/verify/punch.rs)"
    );
    let _ = writeln!(s, "*MATERIAL, NAME=BLOCK\n*HYPERELASTIC, NEO HOOKE\n{:e}, {d1:e}", mu / 2.0);
    let _ = writeln!(s, "*SOLID SECTION, ELSET=BLOCK, MATERIAL=BLOCK");
    let _ = writeln!(s, "** bottom encastred, sides pinned, mirror planes");
    let _ = writeln!(s, "*BOUNDARY\nBBOTTOM, 1, 3\nBSIDES, 1, 3\nSYMX, 1, 1\nSYMZ, 3, 3");
    let _ = writeln!(s, "*STEP, NLGEOM, INC=100\n*STATIC\n1., 1., 1e-4, 1.");
    let _ = writeln!(s, "*BOUNDARY\nPUNCH, 1, 1, 0.\nPUNCH, 2, 2, {:.9}\nPUNCH, 3, 3, 0.", -delta);
    let _ = writeln!(s, "*NODE PRINT, NSET=PUNCH\nRF\n*END STEP");
    Ok(PunchDeck { text: s, nodes: nodes.len(), elements: elements.len(), punch_nodes: under.len() })
}

/// The punch block: the spec's block scaled by `scale` in every direction, and its
/// quarter model (mirror planes x = 0, z = 0) meshed with `mesh` and a round core (the
/// punch's footprint).
pub fn punch_block(c: &Campaign, mesh: &spec::MeshLevel, scale: f64) -> (crate::spec::Block, mesh::TissueMesh) {
    let mut block = c.block.clone();
    block.size_x_mm *= scale;
    block.size_z_mm *= scale;
    block.depth_mm *= scale;
    let pose = PoseSpec { name: "punch".into(), role: Role::Centre, x_mm: 0.0, z_mm: 0.0, theta_x_deg: 0.0, theta_z_deg: 0.0 };
    let sym = Symmetry { plane_x: true, plane_z: true };
    let t = mesh::tissue_shaped(&block, mesh, &pose, sym, 0.0, true);
    (block, t)
}

/// Node sets of a punch block's quarter model (0-based node indices).
#[derive(Debug, Clone)]
pub struct PunchSets {
    /// On the top surface, on and inside the punch's rim (prescribed displacement).
    pub under: Vec<usize>,
    /// On the bottom face (encastred).
    pub bottom: Vec<usize>,
    /// On the side faces (pinned).
    pub sides: Vec<usize>,
    /// On the mirror plane x = 0.
    pub sym_x: Vec<usize>,
    /// On the mirror plane z = 0.
    pub sym_z: Vec<usize>,
}

/// The node sets of the punch block `block` (already scaled), from the coordinates (the
/// block's faces are planes), punch radius `a`.
///
/// # Errors
/// Fewer than 4 nodes under the punch (a mesh too coarse for the punch).
pub fn punch_sets(nodes: &[P3], block: &crate::spec::Block, a: f64) -> Result<PunchSets> {
    let hb = [block.size_x_mm / 2.0, block.depth_mm, block.size_z_mm / 2.0];
    let eps = 1e-6;
    let pick = |f: &dyn Fn(&P3) -> bool| -> Vec<usize> { (0..nodes.len()).filter(|&i| f(&nodes[i])).collect() };
    let sets = PunchSets {
        under: pick(&|p| p[1].abs() < 1e-9 && (p[0] * p[0] + p[2] * p[2]).sqrt() <= a * (1.0 + 1e-6)),
        bottom: pick(&|p| (p[1] + hb[1]).abs() < eps),
        sides: pick(&|p| (p[0].abs() - hb[0]).abs() < eps || (p[2].abs() - hb[2]).abs() < eps),
        sym_x: pick(&|p| p[0].abs() < eps),
        sym_z: pick(&|p| p[2].abs() < eps),
    };
    if sets.under.len() < 4 {
        bail!("punch: only {} nodes under the punch", sets.under.len());
    }
    Ok(sets)
}

/// C3D20 edges (local corner pairs) in CalculiX's order of the mid-side nodes 9..20.
const EDGES20: [(usize, usize); 12] = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7)];

/// 20-node elements from 8-node ones: a mid-side node on every edge, at the edge's
/// midpoint, except on the punch's rim: an edge whose both ends lie on the cylinder of
/// radius `a` about the y axis gets its mid-side node on that cylinder, so that the
/// punch footprint is the circle itself and not an inscribed polygon.
fn quadratic(nodes: &[P3], elements: &[[usize; 8]], a: f64) -> (Vec<P3>, Vec<Vec<usize>>) {
    let mut out = nodes.to_vec();
    let mut mid: std::collections::HashMap<(usize, usize), usize> = std::collections::HashMap::new();
    let radius = |p: &P3| (p[0] * p[0] + p[2] * p[2]).sqrt();
    let mut els = Vec::with_capacity(elements.len());
    for e in elements {
        let mut n: Vec<usize> = e.to_vec();
        for (i, j) in EDGES20 {
            let key = (e[i].min(e[j]), e[i].max(e[j]));
            let id = *mid.entry(key).or_insert_with(|| {
                let (p, q) = (nodes[key.0], nodes[key.1]);
                let mut m = [0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1]), 0.5 * (p[2] + q[2])];
                let on_rim = |x: &P3| (radius(x) - a).abs() < 1e-7 * a;
                if on_rim(&p) && on_rim(&q) && (p[1] - q[1]).abs() < 1e-12 {
                    let r = radius(&m);
                    m[0] *= a / r;
                    m[2] *= a / r;
                }
                out.push(m);
                out.len() - 1
            });
            n.push(id);
        }
        els.push(n);
    }
    (out, els)
}
