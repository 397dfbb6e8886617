//! FEBio 4 input writer: one `.feb` (FEBio XML, spec version 4.0) per pose.
//!
//! The model, the same physics as the CalculiX deck (`fe::deck`) with FEBio's elements:
//! - tissue: the campaign's hexahedral mesh (`fe::mesh::tissue`) as `hex8` with FEBio's
//!   uncoupled `Ogden` material, which FEBio solves with its three-field (displacement,
//!   pressure, dilatation) hexahedron: no volumetric locking at K0/mu0 = 100. FEBio's
//!   Ogden energy is `sum c_i / m_i^2 (l1^m_i + l2^m_i + l3^m_i - 3) + U(J)`; the spec's is
//!   Abaqus's `sum 2 mu_i / alpha_i^2 (...)`, so `c_i = 2 mu_i`, `m_i = alpha_i`, and the
//!   bulk modulus `k = K0 = bulk_to_shear * mu0`;
//! - needle: the needle mesh (`fe::mesh::needle`) as a `rigid body` (steel is about 1e5
//!   times stiffer than the tissue), its rotations fixed, its translation prescribed
//!   along its own axis; its centre of mass is placed at the wrench's reference point
//!   (the hub), so that FEBio's rigid-body reaction moment is the moment about the hub;
//! - contact: `[solver.febio]` (type, primary surface, enforcement), Coulomb friction
//!   `contact.friction`; the tissue's top surface near the path against the needle's
//!   outer faces;
//! - boundary: bottom fixed, sides fixed (pinned: hex8 has no rotations), mirror planes
//!   of quarter and half models fixed in their normal direction;
//! - time: t runs from 0 to the insertion depth in mm (t = depth), one must point per
//!   load step with automatic time stepping between; the log file records the rigid
//!   body's reaction force and moment at the must points only;
//! - a viscoelastic ramp-and-hold run (`loading.ramp_hold`, `tissue.prony`: `crate::visco`)
//!   wraps the Ogden in `uncoupled viscoelastic` (the Prony terms act on the deviatoric
//!   stress; the bulk modulus stays the Ogden's) and its time is seconds: the feed curve
//!   ramps to the depth at the set speed and holds, the must points are the run's.

use crate::mesh::summary::{model_name, MeshSummary};
use crate::mesh::{self, NeedleMesh, TissueMesh, FACES};
use crate::spec::{Campaign, FebioSettings, Loading, MeshLevel, PoseSpec, Symmetry};
use anyhow::{bail, Result};
use std::fmt::Write;

/// File name (in the work folder) of the rigid body's reaction log.
pub const RIGID_LOG: &str = "needle-rb.txt";

/// Material id of the needle's rigid body (the item of the `rigid_body_data` record).
const NEEDLE_MAT_ID: u32 = 2;

/// A written FEBio input and what is needed to read its results back.
#[derive(Debug, Clone)]
pub struct Feb {
    /// The whole `.feb` text.
    pub text: String,
    /// Size of the model.
    pub summary: MeshSummary,
    /// Load steps: must points at t = depth * k / steps, k = 1..=steps.
    pub steps: u32,
    /// Mirror planes of the modelled part.
    pub symmetry: Symmetry,
}

/// How a run's time stepper starts and converges.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stepping {
    /// The first time step as a fraction of a load step, in (0, 1].
    pub first_step_fraction: f64,
    /// Converge with `retry_dtol` / `retry_rtol` instead of `dtol` / `rtol`.
    pub retry_tolerances: bool,
    /// Time steps of at most `step_fraction` of a load step over the first `depth_mm`
    /// (the retry ladder's first-contact steps, `ladder.rs`); the first time step too.
    pub first_contact: Option<FirstContact>,
}

/// The first-contact steps of [`Stepping`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FirstContact {
    /// Depth over which the steps are capped, mm.
    pub depth_mm: f64,
    /// The cap, as a fraction of a load step, in (0, 1].
    pub step_fraction: f64,
}

impl Stepping {
    /// The old ladder's stepping: a first step of `dt_fraction` of a load step, the retry
    /// tolerances when it is below 1, no first-contact steps.
    pub fn first_increment(dt_fraction: f64) -> Self {
        Stepping { first_step_fraction: dt_fraction, retry_tolerances: dt_fraction < 1.0, first_contact: None }
    }

    /// The first time step as a fraction of a load step, the first-contact cap included.
    pub fn first_step(&self) -> f64 {
        match self.first_contact {
            Some(fc) if fc.depth_mm > 0.0 => self.first_step_fraction.min(fc.step_fraction),
            _ => self.first_step_fraction,
        }
    }
}

/// Write the FEBio input of `pose` on mesh level `mesh_level` with `steps` load steps
/// over the spec's insertion depth. `dt_fraction`: the first automatic time step as a
/// fraction of a load step (1 on a first attempt; the campaign's retry asks for less,
/// and then also gets the retry's convergence tolerances, `retry_dtol`/`retry_rtol`).
///
/// # Errors
/// The spec's values make an empty mesh, `steps` is 0, or `dt_fraction` is not in (0, 1].
pub fn write(c: &Campaign, pose: &PoseSpec, mesh_level: &MeshLevel, steps: u32, dt_fraction: f64) -> Result<Feb> {
    write_stepped(c, pose, mesh_level, steps, &Stepping::first_increment(dt_fraction))
}

/// As [`write()`], with the time stepper's start given in full ([`Stepping`]).
///
/// # Errors
/// As [`write()`]; a first-contact cap outside (0, 1] or a negative depth.
pub fn write_stepped(c: &Campaign, pose: &PoseSpec, mesh_level: &MeshLevel, steps: u32, stepping: &Stepping) -> Result<Feb> {
    write_with_symmetry(c, pose, mesh_level, steps, stepping, pose.symmetry())
}

/// As [`write_stepped`], with the mirror planes chosen by the caller (a full model of a
/// symmetric pose, for checking the symmetry reduction).
///
/// # Errors
/// As [`write_stepped`]; a mirror plane the pose does not have.
pub fn write_with_symmetry(
    c: &Campaign,
    pose: &PoseSpec,
    mesh_level: &MeshLevel,
    steps: u32,
    stepping: &Stepping,
    sym: Symmetry,
) -> Result<Feb> {
    let dt_fraction = stepping.first_step_fraction;
    if !(dt_fraction > 0.0 && dt_fraction <= 1.0) {
        bail!("pose {}: first time step {dt_fraction} of a load step: must be in (0, 1]", pose.name);
    }
    if let Some(fc) = stepping.first_contact {
        if !(fc.step_fraction > 0.0 && fc.step_fraction <= 1.0 && fc.depth_mm.is_finite() && fc.depth_mm >= 0.0) {
            bail!(
                "pose {}: first-contact steps of {} of a load step over {} mm: the fraction must be in (0, 1], the depth >= 0",
                pose.name,
                fc.step_fraction,
                fc.depth_mm
            );
        }
    }
    let depth = c.loading.depth_mm;
    let (t, n) = mesh::pose_meshes(c, pose, mesh_level, steps, sym)?;
    let hub = [0, 1, 2].map(|k| n.tip[k] + c.needle.reference_from_tip_mm * n.axis[k]);
    let s = &c.solver.febio;
    let mut w = String::with_capacity(160 * (t.nodes.len() + n.nodes.len()));
    let _ = writeln!(w, r#"<?xml version="1.0" encoding="ISO-8859-1"?>"#);
    let _ = writeln!(
        w,
        "<!-- needle-haptics FEBio input (generator v{}), set {:?}, pose {:?}: x = {} mm, z = {} mm, theta_x = {} deg, theta_z = {} deg; insertion {} mm in {} load steps; model: {}; tissue mesh: {}. Units: mm, N, N/mm^2, s ({}). -->",
        super::GENERATOR_VERSION,
        c.set.name,
        pose.name,
        pose.x_mm,
        pose.z_mm,
        pose.theta_x_deg,
        pose.theta_z_deg,
        depth,
        steps,
        model_name(sym),
        t.info,
        match &c.loading.ramp_hold {
            Some(r) => format!("time in s: ramp at {} mm/s, then a {} s hold", r.speed_mm_per_s, r.hold_s),
            None => "time t = depth in mm".to_string(),
        }
    );
    let _ = writeln!(w, r#"<febio_spec version="4.0">"#);
    let _ = writeln!(w, r#"  <Module type="solid"/>"#);
    write_control(&mut w, s, &c.loading, steps, stepping);
    write_material(&mut w, c, hub);
    let needle0 = t.nodes.len();
    let needle_el0 = t.elements.len();
    write_mesh(&mut w, &t, &n, needle0, needle_el0, s);
    let _ = writeln!(w, "  <MeshDomains>");
    let _ = writeln!(w, r#"    <SolidDomain name="tissue" mat="tissue"/>"#);
    let _ = writeln!(w, r#"    <SolidDomain name="needle" mat="needle"/>"#);
    let _ = writeln!(w, "  </MeshDomains>");
    write_boundary(&mut w, &t);
    write_rigid(&mut w, n.axis);
    write_contact(&mut w, c);
    write_load_data(&mut w, &c.loading, steps, stepping.first_contact);
    let _ = writeln!(w, "  <Output>");
    let _ = writeln!(w, "    <logfile>");
    let _ =
        writeln!(w, r#"      <rigid_body_data data="Fx;Fy;Fz;Mx;My;Mz" file="{RIGID_LOG}" delim=",">{NEEDLE_MAT_ID}</rigid_body_data>"#);
    let _ = writeln!(w, "    </logfile>");
    let _ = writeln!(w, "  </Output>");
    let _ = writeln!(w, "</febio_spec>");
    Ok(Feb { text: w, summary: MeshSummary::of(&t, &n, sym), steps, symmetry: sym })
}

fn write_control(w: &mut String, s: &FebioSettings, loading: &Loading, steps: u32, stepping: &Stepping) {
    let dt_fraction = stepping.first_step();
    // FEBio ends at time_steps * step_size: keep that the insertion depth when the first
    // step is a fraction of a load step (the automatic stepper then grows it to dt)
    let (time_steps, step_size, dt) = if loading.ramp_hold.is_some() {
        // uneven must points: the first step a fraction of the first one, the end exact
        let end = loading.time_at(steps);
        let n = (end / (loading.step_time(1) * dt_fraction)).ceil().max(1.0);
        let shortest = (1..=steps).map(|k| loading.step_time(k)).fold(f64::INFINITY, f64::min);
        (n as u64, end / n, shortest)
    } else {
        let dt = loading.depth_mm / f64::from(steps);
        ((f64::from(steps) / dt_fraction).round().max(1.0) as u64, dt * dt_fraction, dt)
    };
    let _ = writeln!(w, "  <Control>");
    let _ = writeln!(w, "    <analysis>STATIC</analysis>");
    let _ = writeln!(w, "    <time_steps>{time_steps}</time_steps>");
    let _ = writeln!(w, "    <step_size>{}</step_size>", num(step_size));
    let _ = writeln!(w, "    <plot_zero_state>0</plot_zero_state>");
    let _ = writeln!(w, "    <plot_level>PLOT_NEVER</plot_level>");
    let _ = writeln!(w, "    <output_level>OUTPUT_MUST_POINTS</output_level>");
    let _ = writeln!(w, "    <time_stepper type=\"default\">");
    let _ = writeln!(w, "      <max_retries>{}</max_retries>", s.max_retries);
    let _ = writeln!(w, "      <opt_iter>{}</opt_iter>", s.opt_iter);
    let _ = writeln!(w, "      <dtmin>{}</dtmin>", num(dt * s.dtmin_fraction));
    let _ = writeln!(w, "      <dtmax lc=\"2\">0</dtmax>");
    let _ = writeln!(w, "      <aggressiveness>1</aggressiveness>");
    let _ = writeln!(w, "      <cutback>0.5</cutback>");
    let _ = writeln!(w, "      <dtforce>0</dtforce>");
    let _ = writeln!(w, "    </time_stepper>");
    let _ = writeln!(w, "    <solver type=\"solid\">");
    // friction makes the contact stiffness non-symmetric
    let _ = writeln!(w, "      <symmetric_stiffness>non-symmetric</symmetric_stiffness>");
    let _ = writeln!(w, "      <equation_scheme>staggered</equation_scheme>");
    let _ = writeln!(w, "      <lstol>{}</lstol>", num(s.lstol));
    let _ = writeln!(w, "      <lsmin>0.01</lsmin>");
    let _ = writeln!(w, "      <lsiter>5</lsiter>");
    let _ = writeln!(w, "      <max_refs>{}</max_refs>", s.max_refs);
    let _ = writeln!(w, "      <reform_each_time_step>1</reform_each_time_step>");
    let _ = writeln!(w, "      <diverge_reform>1</diverge_reform>");
    // FEBio compares the squared norm
    let floor_n = residual_floor_n(s, loading, stepping.retry_tolerances);
    let min_residual = if floor_n > 0.0 { floor_n * floor_n } else { 1e-20 };
    let _ = writeln!(w, "      <min_residual>{}</min_residual>", num(min_residual));
    // the campaign's retry converges on energy and residual with `retry_dtol` /
    // `retry_rtol` (FebioSettings docs)
    let (dtol, rtol) = if stepping.retry_tolerances { (s.retry_dtol, s.retry_rtol) } else { (s.dtol, s.rtol) };
    let _ = writeln!(w, "      <dtol>{}</dtol>", num(dtol));
    let _ = writeln!(w, "      <etol>{}</etol>", num(s.etol));
    let _ = writeln!(w, "      <rtol>{}</rtol>", num(rtol));
    let _ = writeln!(w, "      <qn_method type=\"BFGS\">");
    let _ = writeln!(w, "        <max_ups>{}</max_ups>", s.max_ups);
    let _ = writeln!(w, "      </qn_method>");
    let _ = writeln!(w, "      <linear_solver type=\"pardiso\"/>");
    let _ = writeln!(w, "    </solver>");
    let _ = writeln!(w, "  </Control>");
}

/// Newton's absolute residual floor, N (0: none, FEBio's own 1e-20 N^2): a ramp-and-hold
/// loading's (`crate::visco`) or, in an attempt with the retry tolerances (`retry`), the
/// retry's (`retry_min_residual_n`), the larger. The input file and a continuation's
/// restart input both set it.
pub(super) fn residual_floor_n(s: &FebioSettings, loading: &Loading, retry: bool) -> f64 {
    let retry_floor_n = if retry { s.retry_min_residual_n } else { 0.0 };
    loading.ramp_hold.as_ref().map_or(0.0, |r| r.min_residual_n).max(retry_floor_n)
}

fn write_material(w: &mut String, c: &Campaign, hub: [f64; 3]) {
    let t = &c.tissue;
    let _ = writeln!(w, "  <Material>");
    let _ = writeln!(
        w,
        "    <!-- Ogden N={}: c_i = 2 mu_i (N/mm^2), m_i = alpha_i; k = K0 = {} * mu0 = {} N/mm^2 -->",
        t.mu_n_per_mm2.len(),
        t.bulk_to_shear,
        num(t.k0_n_per_mm2())
    );
    // the Ogden, alone or as the elastic part of the viscoelastic wrapper (FEBio adds the
    // child's k to the wrapper's, which is left at 0: the volumetric part stays elastic)
    let ind = if let Some(p) = &t.prony {
        let _ = writeln!(
            w,
            "    <!-- uncoupled viscoelastic, FEBio's normalisation: g0 = 1 (the Ogden is the long-term response); tau_i in s -->"
        );
        let _ = writeln!(w, r#"    <material id="1" name="tissue" type="uncoupled viscoelastic">"#);
        let _ = writeln!(w, "      <g0>1</g0>");
        for (i, (g, tau)) in p.g.iter().zip(&p.tau_s).enumerate() {
            let _ = writeln!(w, "      <g{}>{}</g{}>\n      <t{}>{}</t{}>", i + 1, num(*g), i + 1, i + 1, num(*tau), i + 1);
        }
        let _ = writeln!(w, r#"      <elastic type="Ogden">"#);
        "  "
    } else {
        let _ = writeln!(w, r#"    <material id="1" name="tissue" type="Ogden">"#);
        ""
    };
    let _ = writeln!(w, "{ind}      <density>1e-9</density>");
    let _ = writeln!(w, "{ind}      <k>{}</k>", num(t.k0_n_per_mm2()));
    for (i, (mu, a)) in t.mu_n_per_mm2.iter().zip(&t.alpha).enumerate() {
        let _ = writeln!(w, "{ind}      <c{}>{}</c{}>", i + 1, num(2.0 * mu), i + 1);
        let _ = writeln!(w, "{ind}      <m{}>{}</m{}>", i + 1, num(*a), i + 1);
    }
    if t.prony.is_some() {
        let _ = writeln!(w, "      </elastic>");
    }
    let _ = writeln!(w, "    </material>");
    let _ = writeln!(w, "    <!-- rigid needle; centre of mass at the hub: the reaction moment is about the hub -->");
    let _ = writeln!(w, r#"    <material id="{NEEDLE_MAT_ID}" name="needle" type="rigid body">"#);
    let _ = writeln!(w, "      <density>7.85e-9</density>");
    let _ = writeln!(w, "      <E>210000</E>");
    let _ = writeln!(w, "      <v>0.3</v>");
    let _ = writeln!(w, "      <center_of_mass>{},{},{}</center_of_mass>", num(hub[0]), num(hub[1]), num(hub[2]));
    let _ = writeln!(w, "    </material>");
    let _ = writeln!(w, "  </Material>");
}

fn ids(w: &mut String, ids: impl Iterator<Item = usize>) {
    let v: Vec<String> = ids.map(|i| i.to_string()).collect();
    for chunk in v.chunks(16) {
        let _ = writeln!(w, "      {},", chunk.join(","));
    }
    // FEBio's list reader accepts a trailing comma at the end of a line
}

fn write_mesh(w: &mut String, t: &TissueMesh, n: &NeedleMesh, needle0: usize, needle_el0: usize, s: &FebioSettings) {
    let _ = writeln!(w, "  <Mesh>");
    let _ = writeln!(w, r#"    <Nodes name="all">"#);
    for (i, p) in t.nodes.iter().chain(&n.nodes).enumerate() {
        let _ = writeln!(w, r#"      <node id="{}">{:.7},{:.7},{:.7}</node>"#, i + 1, p[0], p[1], p[2]);
    }
    let _ = writeln!(w, "    </Nodes>");
    let _ = writeln!(w, r#"    <Elements type="hex8" name="tissue">"#);
    for (e, nn) in t.elements.iter().enumerate() {
        let v: Vec<String> = nn.iter().map(|i| (i + 1).to_string()).collect();
        let _ = writeln!(w, r#"      <elem id="{}">{}</elem>"#, e + 1, v.join(","));
    }
    let _ = writeln!(w, "    </Elements>");
    let _ = writeln!(w, r#"    <Elements type="hex8" name="needle">"#);
    for (e, nn) in n.elements.iter().enumerate() {
        let v: Vec<String> = nn.iter().map(|i| (needle0 + i + 1).to_string()).collect();
        let _ = writeln!(w, r#"      <elem id="{}">{}</elem>"#, needle_el0 + e + 1, v.join(","));
    }
    let _ = writeln!(w, "    </Elements>");
    for (name, set) in [("bottom", &t.bottom), ("sides", &t.sides), ("sym_x", &t.plane_x), ("sym_z", &t.plane_z)] {
        if set.is_empty() {
            continue;
        }
        let _ = writeln!(w, r#"    <NodeSet name="{name}">"#);
        ids(w, set.iter().map(|i| i + 1));
        let _ = writeln!(w, "    </NodeSet>");
    }
    // FACES lists each face's nodes the Abaqus way, whose right-hand normal points into
    // the element; FEBio takes a facet's right-hand normal as its outward normal, so the
    // order is reversed.
    let face = |e: usize, f: u8, nodes: &[[usize; 8]], off: usize| -> String {
        let el = nodes[e];
        let v: Vec<String> = FACES[usize::from(f - 1)].iter().rev().map(|&k| (off + el[k] + 1).to_string()).collect();
        v.join(",")
    };
    let _ = writeln!(w, r#"    <Surface name="tissue_top">"#);
    for (k, &(e, f)) in t.top_faces.iter().enumerate() {
        let _ = writeln!(w, r#"      <quad4 id="{}">{}</quad4>"#, k + 1, face(e, f, &t.elements, 0));
    }
    let _ = writeln!(w, "    </Surface>");
    let _ = writeln!(w, r#"    <Surface name="needle_surface">"#);
    for (k, &(e, f)) in n.faces.iter().enumerate() {
        let _ = writeln!(w, r#"      <quad4 id="{}">{}</quad4>"#, k + 1, face(e, f, &n.elements, needle0));
    }
    let _ = writeln!(w, "    </Surface>");
    let (primary, secondary) = if s.primary == "needle" { ("needle_surface", "tissue_top") } else { ("tissue_top", "needle_surface") };
    let _ = writeln!(w, r#"    <SurfacePair name="needle_tissue">"#);
    let _ = writeln!(w, "      <primary>{primary}</primary>");
    let _ = writeln!(w, "      <secondary>{secondary}</secondary>");
    let _ = writeln!(w, "    </SurfacePair>");
    let _ = writeln!(w, "  </Mesh>");
}

fn write_boundary(w: &mut String, t: &TissueMesh) {
    let _ = writeln!(w, "  <Boundary>");
    let bc = |w: &mut String, set: &str, xyz: [u8; 3]| {
        let _ = writeln!(w, r#"    <bc name="fix_{set}" node_set="{set}" type="zero displacement">"#);
        let _ = writeln!(w, "      <x_dof>{}</x_dof>\n      <y_dof>{}</y_dof>\n      <z_dof>{}</z_dof>", xyz[0], xyz[1], xyz[2]);
        let _ = writeln!(w, "    </bc>");
    };
    bc(w, "bottom", [1, 1, 1]);
    bc(w, "sides", [1, 1, 1]);
    if !t.plane_x.is_empty() {
        bc(w, "sym_x", [1, 0, 0]);
    }
    if !t.plane_z.is_empty() {
        bc(w, "sym_z", [0, 0, 1]);
    }
    let _ = writeln!(w, "  </Boundary>");
}

fn write_rigid(w: &mut String, axis: [f64; 3]) {
    let _ = writeln!(w, "  <Rigid>");
    let _ = writeln!(w, r#"    <rigid_bc name="needle_no_rotation" type="rigid_fixed">"#);
    let _ = writeln!(w, "      <rb>needle</rb>");
    let _ = writeln!(w, "      <Rx_dof>0</Rx_dof>\n      <Ry_dof>0</Ry_dof>\n      <Rz_dof>0</Rz_dof>");
    let _ = writeln!(w, "      <Ru_dof>1</Ru_dof>\n      <Rv_dof>1</Rv_dof>\n      <Rw_dof>1</Rw_dof>");
    let _ = writeln!(w, "    </rigid_bc>");
    // fed along its own axis, towards the tip: displacement = -t * axis (t = depth, mm)
    for (k, dof) in ["x", "y", "z"].iter().enumerate() {
        let _ = writeln!(w, r#"    <rigid_bc name="needle_feed_{dof}" type="rigid_displacement">"#);
        let _ = writeln!(w, "      <rb>needle</rb>\n      <dof>{dof}</dof>");
        let _ = writeln!(w, r#"      <value lc="1">{}</value>"#, num(-axis[k]));
        let _ = writeln!(w, "      <relative>0</relative>");
        let _ = writeln!(w, "    </rigid_bc>");
    }
    let _ = writeln!(w, "  </Rigid>");
}

fn write_contact(w: &mut String, c: &Campaign) {
    let s = &c.solver.febio;
    let _ = writeln!(w, "  <Contact>");
    let _ = writeln!(w, r#"    <contact name="needle_tissue" surface_pair="needle_tissue" type="{}">"#, s.contact);
    let _ = writeln!(w, "      <laugon>{}</laugon>", if s.augmented { "AUGLAG" } else { "PENALTY" });
    let _ = writeln!(w, "      <tolerance>{}</tolerance>", num(s.aug_tolerance));
    let _ = writeln!(w, "      <gaptol>{}</gaptol>", num(s.gap_tolerance_mm));
    let _ = writeln!(w, "      <penalty>{}</penalty>", num(s.penalty));
    let _ = writeln!(w, "      <auto_penalty>{}</auto_penalty>", u8::from(s.auto_penalty));
    let _ = writeln!(w, "      <two_pass>{}</two_pass>", u8::from(s.two_pass));
    let _ = writeln!(w, "      <search_tol>{}</search_tol>", num(s.search_tol));
    let _ = writeln!(w, "      <minaug>0</minaug>\n      <maxaug>{}</maxaug>", s.max_aug);
    let _ = writeln!(w, "      <fric_coeff>{}</fric_coeff>", num(c.contact.friction));
    if s.contact == "sliding-elastic" {
        let _ = writeln!(w, "      <search_radius>{}</search_radius>", num(s.search_radius_mm));
        let _ = writeln!(w, "      <seg_up>{}</seg_up>", s.seg_up);
        let _ = writeln!(w, "      <symmetric_stiffness>0</symmetric_stiffness>");
    }
    let _ = writeln!(w, "    </contact>");
    let _ = writeln!(w, "  </Contact>");
}

/// The load controller (1-based id) of the must points, which is also the time stepper's
/// `dtmax` curve (`<dtmax lc="2">`); a restart redefines it (`restart.rs`).
pub const MUST_POINT_LC: u32 = 2;

/// One point of the must-point curve: a must point and the largest time step up to it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MustPoint {
    /// The solver's time of the must point (the end of a load step): mm of depth, or s of
    /// a ramp-and-hold run.
    pub time: f64,
    /// The largest time step of the load step that ends here, in the same unit.
    pub dtmax: f64,
}

/// The must points 1..=`steps` of `loading` and, as the load curve's values, the largest
/// time step up to each: the load step itself, or within the first-contact depth
/// ([`FirstContact`]) that fraction of it. FEBio reads the curve with STEP interpolation
/// (`PointCurve::value`): at a time in (t(k-1), t(k)) it is point k's value; at a must
/// point t(k) itself it is point k+1's (the first point after the time), except at the
/// first and the last must point, whose own values FEBio returns at their times.
pub fn must_points(loading: &Loading, steps: u32, first_contact: Option<FirstContact>) -> Vec<MustPoint> {
    let depth = loading.depth_mm;
    (1..=steps)
        .map(|k| {
            let dt = loading.step_time(k);
            // the step ending at t starts within the first-contact depth
            let capped = first_contact.filter(|fc| loading.depth_at(k - 1) < fc.depth_mm - 1e-9 * depth);
            MustPoint { time: loading.time_at(k), dtmax: capped.map_or(dt, |fc| dt * fc.step_fraction) }
        })
        .collect()
}

/// The `<load_controller>` element of the must-point curve ([`MUST_POINT_LC`]), indented
/// for `<LoadData>`: the `.feb` writes it, a restart redefines it with the same text but
/// for the values (`restart.rs`).
pub fn must_point_controller(points: &[MustPoint]) -> String {
    let mut w = String::new();
    let _ = writeln!(w, r#"    <load_controller id="{MUST_POINT_LC}" name="must_points" type="loadcurve">"#);
    let _ = writeln!(w, "      <interpolate>STEP</interpolate>\n      <extend>CONSTANT</extend>\n      <points>");
    for p in points {
        let _ = writeln!(w, "        <pt>{},{}</pt>", num(p.time), num(p.dtmax));
    }
    let _ = writeln!(w, "      </points>\n    </load_controller>");
    w
}

/// The feed curve (load controller 1) and the must points ([`must_points`], load
/// controller [`MUST_POINT_LC`]).
fn write_load_data(w: &mut String, loading: &Loading, steps: u32, first_contact: Option<FirstContact>) {
    let depth = loading.depth_mm;
    let _ = writeln!(w, "  <LoadData>");
    let _ = writeln!(w, r#"    <load_controller id="1" name="feed_mm" type="loadcurve">"#);
    match &loading.ramp_hold {
        Some(r) => {
            // time in s: the ramp at the speed, then the hold
            let ramp = r.ramp_s(depth);
            let _ = writeln!(w, "      <interpolate>LINEAR</interpolate>\n      <extend>CONSTANT</extend>");
            let _ = writeln!(
                w,
                "      <points>\n        <pt>0,0</pt>\n        <pt>{},{}</pt>\n        <pt>{},{}</pt>\n      </points>",
                num(ramp),
                num(depth),
                num(ramp + r.hold_s),
                num(depth)
            );
        }
        None => {
            let _ = writeln!(w, "      <interpolate>LINEAR</interpolate>\n      <extend>EXTRAPOLATE</extend>");
            let _ = writeln!(w, "      <points>\n        <pt>0,0</pt>\n        <pt>{},{}</pt>\n      </points>", num(depth), num(depth));
        }
    }
    let _ = writeln!(w, "    </load_controller>");
    let _ = writeln!(w, "    <!-- must points: the end of every load step; value: the largest time step -->");
    w.push_str(&must_point_controller(&must_points(loading, steps, first_contact)));
    let _ = writeln!(w, "  </LoadData>");
}

/// A number as FEBio reads it: Rust's shortest round-trip form.
pub(super) fn num(v: f64) -> String {
    let v = if v == 0.0 { 0.0 } else { v };
    format!("{v:?}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn shipped() -> String {
        std::fs::read_to_string(needle_stdx::workspace_root().join("coeffs/default/campaign.toml")).expect("campaign.toml")
    }

    #[test]
    fn the_feb_wraps_the_ogden_and_runs_in_seconds() {
        let c = crate::spec::parse(&shipped(), Path::new("campaign.toml")).expect("the shipped spec");
        let v = c.viscoelastic.clone().expect("[viscoelastic]");
        let (run, poses) = crate::spec::visco::apply(&c, &v, 1.0, 4, crate::spec::visco::Friction::Campaign);
        let pose = poses.first().expect("a pose");
        let mesh = run.mesh_level("smoke").expect("smoke").clone();
        let feb = write(&run, pose, &mesh, run.loading.steps, 1.0).expect("feb");
        let t = &feb.text;
        assert!(t.contains(r#"type="uncoupled viscoelastic""#) && t.contains(r#"<elastic type="Ogden">"#), "wrapped");
        assert!(t.contains("<g1>0.6</g1>") && t.contains("<t2>5.0</t2>"), "the Prony terms");
        // the feed: 6 mm at 1 mm/s, then held to 36 s; the last must point at 36 s
        assert!(t.contains("<pt>6.0,6.0</pt>") && t.contains("<pt>36.0,6.0</pt>"), "feed curve");
        assert!(t.contains("<pt>1.5,1.5</pt>") && t.contains("<pt>36.0,"), "must points");
        let elastic = write(&c, pose, &mesh, 4, 1.0).expect("feb");
        assert!(!elastic.text.contains("viscoelastic"), "an elastic run stays elastic");
    }

    /// The retry's residual floor is written squared, only with the retry tolerances; a
    /// ramp-and-hold run keeps the larger of its own floor and the retry's.
    #[test]
    fn the_retrys_residual_floor_is_written_squared_only_with_the_retry_tolerances() {
        let mut c = crate::spec::parse(&shipped(), Path::new("campaign.toml")).expect("the shipped spec");
        c.solver.febio.retry_min_residual_n = 1e-4;
        let pose = c.poses().into_iter().find(|p| p.name == "centre").expect("centre");
        let mesh = c.mesh_level("smoke").expect("smoke").clone();
        let floor = |c: &Campaign, dt: f64| {
            let t = write(c, &pose, &mesh, 4, dt).expect("feb").text;
            let v = t.split("<min_residual>").nth(1).and_then(|r| r.split('<').next()).and_then(|v| v.parse::<f64>().ok());
            v.unwrap_or(f64::NAN)
        };
        let close = |got: f64, want: f64| (got - want).abs() <= 1e-12 * want;
        assert!(close(floor(&c, 1.0), 1e-20), "a first attempt: FEBio's own");
        assert!(close(floor(&c, 0.25), 1e-8), "the retry: (1e-4 N)^2");
        let v = c.viscoelastic.clone().expect("[viscoelastic]");
        let (run, _) = crate::spec::visco::apply(&c, &v, 1.0, 4, crate::spec::visco::Friction::Campaign);
        assert!(close(floor(&run, 0.25), 1e-8), "the larger floor: the retry's 1e-4 N over the hold's 1e-5 N");
        assert!(close(floor(&run, 1.0), 1e-10), "the hold's (1e-5 N)^2");
    }
}
