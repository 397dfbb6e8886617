//! CalculiX deck writer: one `.inp` per pose, in keyword syntax an ABAQUS user can read.
//!
//! The deck: tissue block of C3D8 hexahedra (Ogden hyperelastic), a needle meshed with
//! C3D8 whose every node is driven by a prescribed displacement (a rigid needle; steel is
//! about 1e5 times stiffer than the tissue), surface-to-surface penalty contact with
//! Coulomb friction, one `*STEP, NLGEOM` per depth increment, and a `*NODE PRINT` of the
//! needle surface nodes' reaction forces at the end of each step.
//!
//! Differences from ABAQUS syntax (all CalculiX-only spellings are noted in the deck):
//! - `*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR` takes the slope and, for CalculiX,
//!   a tension value at large clearance (ABAQUS: `*SURFACE BEHAVIOR, PENALTY=...`);
//! - `*CONTACT PAIR, TYPE=SURFACE TO SURFACE` (ABAQUS: `*CONTACT PAIR` with the default
//!   finite-sliding surface-to-surface discretisation);
//! - `*FRICTION` second value: stick slope (ABAQUS: `SLIP TOLERANCE` / `ELASTIC SLIP`);
//! - `*TIME POINTS` and `TIME POINTS=` on print requests (ABAQUS: `*OUTPUT, TIME POINTS=`).

use crate::mesh::summary::{model_name, MeshSummary};
use crate::mesh::{self, NeedleMesh, TissueMesh};
use crate::spec::{Campaign, MeshLevel, PoseSpec, Symmetry};
use anyhow::{bail, Result};
use std::fmt::Write;

/// Version of the mesh and deck generator ([`versions::CCX_DECK`](crate::versions::CCX_DECK)).
pub use crate::versions::CCX_DECK as GENERATOR_VERSION;

/// CalculiX ids of the needle's first node and first element: right after the tissue's
/// (tissue ids start at 1). The ids are contiguous on purpose: ccx sizes its per-node and
/// per-element arrays by the largest id and loops over them every iteration, so the
/// fixed offset of generator v2 (1 000 001) made the centred quarter run 3.3 times
/// slower (247 s against 74 s, same iterations, same forces to the printed digit).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NeedleIds {
    /// Id of needle node 0.
    pub node0: usize,
    /// Id of needle element 0.
    pub element0: usize,
}

impl NeedleIds {
    /// The first free ids after a tissue of `nodes` nodes and `elements` elements.
    pub fn after(nodes: usize, elements: usize) -> Self {
        Self { node0: nodes + 1, element0: elements + 1 }
    }
}

/// Name of the node set whose reaction forces are printed every step.
pub const PRINT_SET: &str = "NPRINT";

/// A written deck and what is needed to read its results back.
#[derive(Debug, Clone)]
pub struct Deck {
    /// The whole `.inp` text.
    pub text: String,
    /// Size of the model.
    pub summary: MeshSummary,
    /// Node set whose RF is printed at the end of every step.
    pub print_set: String,
    /// Number of load steps; step k ends at total time k, depth `loading.depth_mm * k / steps`.
    pub steps: u32,
    /// Initial coordinates (mm) of the printed nodes, by CalculiX node id.
    pub print_nodes: Vec<(u32, [f64; 3])>,
    /// Reference point (hub) at depth 0, mm.
    pub reference_mm: [f64; 3],
    /// Mirror planes used to cut the model.
    pub symmetry: Symmetry,
}

/// Write the deck of `pose` on mesh level `mesh`, with `steps` load steps over the full
/// insertion depth of the spec.
///
/// # Errors
/// The spec's values make an empty or degenerate mesh.
pub fn write_deck(c: &Campaign, pose: &PoseSpec, mesh_level: &MeshLevel, steps: u32) -> Result<Deck> {
    write_deck_with_symmetry(c, pose, mesh_level, steps, pose.symmetry())
}

/// As [`write_deck`], with every load step starting at `first_increment` of the step
/// (the retries: [`RETRY_FIRST_INCREMENT`](crate::backend::RETRY_FIRST_INCREMENT))
/// (`*STATIC` first value; 1 is [`write_deck`]'s). The model and the loads are the same:
/// only ccx's incrementation within a step differs.
///
/// # Errors
/// As [`write_deck`]; `first_increment` not in (0, 1].
pub fn write_deck_first_increment(c: &Campaign, pose: &PoseSpec, mesh_level: &MeshLevel, steps: u32, first_increment: f64) -> Result<Deck> {
    write_deck_full(c, pose, mesh_level, steps, pose.symmetry(), first_increment)
}

/// As [`write_deck`], with the mirror planes chosen by the caller (a full model of a
/// symmetric pose, for checking the symmetry reduction).
///
/// # Errors
/// As [`write_deck`]; a mirror plane the pose does not have.
pub fn write_deck_with_symmetry(c: &Campaign, pose: &PoseSpec, mesh_level: &MeshLevel, steps: u32, sym: Symmetry) -> Result<Deck> {
    write_deck_full(c, pose, mesh_level, steps, sym, 1.0)
}

fn write_deck_full(c: &Campaign, pose: &PoseSpec, mesh_level: &MeshLevel, steps: u32, sym: Symmetry, first_increment: f64) -> Result<Deck> {
    if !(first_increment > 1e-5 && first_increment <= 1.0) {
        bail!("pose {}: first increment {first_increment} of a step: must be in (1e-5, 1]", pose.name);
    }
    let depth = c.loading.depth_mm;
    let (t, n) = mesh::pose_meshes(c, pose, mesh_level, steps, sym)?;
    let mut s = String::with_capacity(200 * (t.nodes.len() + n.nodes.len()));
    let w = &mut s;
    let _ = writeln!(w, "** needle-haptics CalculiX deck (generator v{GENERATOR_VERSION}), set {:?}, pose {:?}", c.set.name, pose.name);
    let _ = writeln!(
        w,
        "** pose: x = {} mm, z = {} mm, theta_x = {} deg, theta_z = {} deg; insertion {} mm in {} steps",
        pose.x_mm, pose.z_mm, pose.theta_x_deg, pose.theta_z_deg, depth, steps
    );
    let _ = writeln!(w, "** model: {}; tissue mesh: {}", model_name(sym), t.info);
    let _ = writeln!(w, "** units: mm, N, N/mm^2 (MPa); frame: origin at the centre of the top surface, y up");
    write_tissue(w, &t);
    let ids = NeedleIds::after(t.nodes.len(), t.elements.len());
    write_needle(w, &n, ids);
    write_material(w, c);
    write_contact(w, c);
    write_boundary(w, &t);
    let axis = n.axis;
    let _ = writeln!(w, "*TIME POINTS, NAME=TEND\n1.");
    for k in 1..=steps {
        let d = depth * f64::from(k) / f64::from(steps);
        let _ = writeln!(w, "** ---- load step {k}: depth {d:.4} mm along the needle axis");
        let _ = writeln!(w, "*STEP, NLGEOM, INC=1000");
        let _ = writeln!(w, "*STATIC\n{}, 1., 1e-5, 1.", fortran_real(first_increment));
        let _ = writeln!(w, "*BOUNDARY");
        for (dof, a) in axis.iter().enumerate() {
            let _ = writeln!(w, "NEEDLE, {}, {}, {:.9}", dof + 1, dof + 1, -d * a);
        }
        let _ = writeln!(w, "*NODE PRINT, NSET={PRINT_SET}, TIME POINTS=TEND\nRF");
        let _ = writeln!(w, "*END STEP");
    }
    let reference_mm = [0, 1, 2].map(|k| n.tip[k] + c.needle.reference_from_tip_mm * axis[k]);
    let print_nodes = n.surface_nodes.iter().map(|&i| ((ids.node0 + i) as u32, n.nodes[i])).collect();
    Ok(Deck {
        text: s,
        summary: MeshSummary::of(&t, &n, sym),
        print_set: PRINT_SET.to_string(),
        steps,
        print_nodes,
        reference_mm,
        symmetry: sym,
    })
}

fn write_ids(w: &mut String, ids: impl Iterator<Item = usize>) {
    let ids: Vec<usize> = ids.collect();
    for chunk in ids.chunks(12) {
        let line: Vec<String> = chunk.iter().map(|i| i.to_string()).collect();
        let _ = writeln!(w, "{},", line.join(","));
    }
}

fn write_tissue(w: &mut String, t: &TissueMesh) {
    let _ = writeln!(w, "*NODE, NSET=NTISSUE");
    for (i, p) in t.nodes.iter().enumerate() {
        let _ = writeln!(w, "{},{:.7},{:.7},{:.7}", i + 1, p[0], p[1], p[2]);
    }
    let _ = writeln!(w, "*ELEMENT, TYPE=C3D8, ELSET=TISSUE");
    for (e, n) in t.elements.iter().enumerate() {
        let ids: Vec<String> = n.iter().map(|i| (i + 1).to_string()).collect();
        let _ = writeln!(w, "{},{}", e + 1, ids.join(","));
    }
    let _ = writeln!(w, "*NSET, NSET=TBOTTOM");
    write_ids(w, t.bottom.iter().map(|i| i + 1));
    let _ = writeln!(w, "*NSET, NSET=TSIDES");
    write_ids(w, t.sides.iter().map(|i| i + 1));
    if !t.plane_x.is_empty() {
        let _ = writeln!(w, "*NSET, NSET=SYMX");
        write_ids(w, t.plane_x.iter().map(|i| i + 1));
    }
    if !t.plane_z.is_empty() {
        let _ = writeln!(w, "*NSET, NSET=SYMZ");
        write_ids(w, t.plane_z.iter().map(|i| i + 1));
    }
    let _ = writeln!(w, "*SURFACE, NAME=TISSUE_TOP, TYPE=ELEMENT");
    for (e, f) in &t.top_faces {
        let _ = writeln!(w, "{},S{}", e + 1, f);
    }
}

fn write_needle(w: &mut String, n: &NeedleMesh, ids: NeedleIds) {
    let _ = writeln!(w, "*NODE, NSET=NEEDLE");
    for (i, p) in n.nodes.iter().enumerate() {
        let _ = writeln!(w, "{},{:.7},{:.7},{:.7}", ids.node0 + i, p[0], p[1], p[2]);
    }
    let _ = writeln!(w, "*ELEMENT, TYPE=C3D8, ELSET=NEEDLE");
    for (e, nn) in n.elements.iter().enumerate() {
        let nodes: Vec<String> = nn.iter().map(|i| (ids.node0 + i).to_string()).collect();
        let _ = writeln!(w, "{},{}", ids.element0 + e, nodes.join(","));
    }
    let _ = writeln!(w, "*NSET, NSET={PRINT_SET}");
    write_ids(w, n.surface_nodes.iter().map(|i| ids.node0 + i));
    let _ = writeln!(w, "*SURFACE, NAME=NEEDLE_SURF, TYPE=ELEMENT");
    for (e, f) in &n.faces {
        let _ = writeln!(w, "{},S{}", ids.element0 + e, f);
    }
}

fn write_material(w: &mut String, c: &Campaign) {
    let t = &c.tissue;
    let k0 = t.k0_n_per_mm2();
    let d1 = 2.0 / k0;
    let n = t.mu_n_per_mm2.len();
    let _ = writeln!(w, "*MATERIAL, NAME=TISSUE");
    let _ =
        writeln!(w, "** Ogden N={n}: mu_i [N/mm^2], alpha_i, then D_i = 2/K0; mu0 = {:e} N/mm^2, K0 = {:e} N/mm^2", t.mu0_n_per_mm2(), k0);
    let _ = writeln!(w, "*HYPERELASTIC, OGDEN, N={n}");
    let mut vals: Vec<String> = Vec::new();
    for (m, a) in t.mu_n_per_mm2.iter().zip(&t.alpha) {
        vals.push(format!("{m:e}"));
        vals.push(format!("{a}"));
    }
    vals.push(format!("{d1:e}"));
    // D2, D3 (CalculiX replaces 0 by its own default, harmless: only D1 is used for N terms)
    for _ in 1..n {
        vals.push("0".to_string());
    }
    for chunk in vals.chunks(8) {
        let _ = writeln!(w, "{}", chunk.join(","));
    }
    let _ = writeln!(w, "*MATERIAL, NAME=STEEL\n*ELASTIC\n210000., 0.3");
    let _ = writeln!(w, "*SOLID SECTION, ELSET=TISSUE, MATERIAL=TISSUE");
    let _ = writeln!(w, "*SOLID SECTION, ELSET=NEEDLE, MATERIAL=STEEL");
}

fn write_contact(w: &mut String, c: &Campaign) {
    let k = c.contact.penalty_slope_n_per_mm3;
    let _ = writeln!(w, "*SURFACE INTERACTION, NAME=SI");
    let _ = writeln!(w, "** hard contact by a linear penalty: slope {k} N/mm^3 (CalculiX: slope, tension at large clearance, c0)");
    let _ = writeln!(w, "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n{k}, {}, 0.", 0.0005 * k);
    if c.contact.friction > 0.0 {
        let _ = writeln!(w, "** Coulomb friction {}, stick slope {} N/mm^3", c.contact.friction, c.contact.stick_slope_n_per_mm3);
        let _ = writeln!(w, "*FRICTION\n{}, {}", c.contact.friction, c.contact.stick_slope_n_per_mm3);
    }
    // Slave first, then master: the needle's fine, sharp surface is sampled at its own
    // integration points (why: GENERATOR_VERSION's history).
    let _ = writeln!(w, "** slave (needle), master (tissue)");
    let _ = writeln!(w, "*CONTACT PAIR, INTERACTION=SI, TYPE=SURFACE TO SURFACE\nNEEDLE_SURF, TISSUE_TOP");
}

fn write_boundary(w: &mut String, t: &TissueMesh) {
    let _ = writeln!(w, "** bottom encastred, sides pinned (displacements; C3D8 has no rotations)");
    let _ = writeln!(w, "*BOUNDARY\nTBOTTOM, 1, 3\nTSIDES, 1, 3");
    if !t.plane_x.is_empty() {
        let _ = writeln!(w, "SYMX, 1, 1");
    }
    if !t.plane_z.is_empty() {
        let _ = writeln!(w, "SYMZ, 3, 3");
    }
}

/// `v` as a deck real: `1.` for one (the generator's historical text), else Rust's
/// shortest round-trip form (`0.25`).
fn fortran_real(v: f64) -> String {
    if v == 1.0 {
        "1.".to_string()
    } else {
        format!("{v:?}")
    }
}
