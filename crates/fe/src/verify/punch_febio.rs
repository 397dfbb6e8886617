//! The flat-punch check with FEBio's campaign element: the same bonded rigid punch,
//! quarter block, finite-block extrapolation and Sneddon reference as [`super::punch`]
//! (its docs give the reasoning), solved with the element and material family the FEBio
//! campaign uses for the tissue: `hex8` with FEBio's uncoupled `Ogden` law, which FEBio
//! integrates with its three-field (u-p-J) formulation. One Ogden term with alpha = 2 and
//! c1 = 2 mu is the neo-Hookean energy of shear modulus mu (Sneddon's force is linear in
//! mu); k = K0 = the tissue's K0/mu0 times mu, so the check sees the tissue's near
//! incompressibility. The force is the sum of FEBio's nodal reactions `Ry` of the punch
//! nodes (logfile `node_data`), times 4 (quarter model).

use super::punch::{
    bonded_punch_force, poisson, punch_block, punch_mesh, punch_sets, sneddon_force, PunchReport, PunchRun, PunchSets, PUNCH_GOAL_PERCENT,
    PUNCH_MU_N_PER_MM2,
};
use super::VerifyOptions;
use crate::febio;
use crate::febio::logs;
use crate::process;
use crate::spec::{self, Campaign};
use anyhow::{bail, Context, Result};
use std::fmt::Write as _;
use std::path::Path;

/// Elements across the punch diameter on the FEBio check's mesh (hex8: the same number
/// of nodes across as the C3D20R check's 8 elements).
pub const PUNCH_CORE_ELEMENTS_HEX8: u32 = 16;

/// The logfile of the punch nodes' reactions.
const REACTION_LOG: &str = "punch-ry.txt";

/// A FEBio punch input and the size of its mesh.
#[derive(Debug, Clone)]
pub struct PunchFeb {
    /// The `.feb` text.
    pub text: String,
    /// Nodes of the block.
    pub nodes: usize,
    /// Elements of the block.
    pub elements: usize,
    /// Nodes under the punch, quarter model.
    pub punch_nodes: usize,
}

/// FEBio input of the bonded flat punch (radius `a`, indentation `delta`) on a quarter
/// model of the block scaled by `scale`, hex8 mesh `mesh`.
///
/// # Errors
/// Fewer than 4 nodes under the punch (a mesh too coarse for the punch).
pub fn punch_feb(c: &Campaign, mesh_level: &spec::MeshLevel, a: f64, delta: f64, scale: f64) -> Result<PunchFeb> {
    let (block, t) = punch_block(c, mesh_level, scale);
    let PunchSets { under, bottom, sides, sym_x, sym_z } = punch_sets(&t.nodes, &block, a)?;
    let mu = PUNCH_MU_N_PER_MM2;
    let k0 = c.tissue.bulk_to_shear * mu;
    let mut s = String::with_capacity(120 * (t.nodes.len() + t.elements.len()));
    let _ = writeln!(s, r#"<?xml version="1.0" encoding="ISO-8859-1"?>"#);
    let _ = writeln!(
        s,
        "<!-- needle-haptics flat-punch verification (FEBio): radius {a} mm, indentation {delta} mm, block scaled {scale}x; quarter model, bonded rigid punch (prescribed displacement of the nodes under it); mesh: {}; hex8 three-field, uncoupled Ogden N=1 alpha=2 (neo-Hookean mu = {mu} N/mm^2), k = {k0} N/mm^2 -->",
        t.info
    );
    let _ = writeln!(s, r#"<febio_spec version="4.0">"#);
    let _ = writeln!(s, r#"  <Module type="solid"/>"#);
    let _ = writeln!(
        s,
        "  <Control>\n    <analysis>STATIC</analysis>\n    <time_steps>2</time_steps>\n    <step_size>0.5</step_size>\n    <plot_level>PLOT_NEVER</plot_level>\n    <output_level>OUTPUT_FINAL</output_level>\n    <solver type=\"solid\">\n      <dtol>1e-6</dtol>\n      <etol>1e-8</etol>\n      <rtol>0</rtol>\n      <qn_method type=\"BFGS\"><max_ups>0</max_ups></qn_method>\n      <linear_solver type=\"pardiso\"/>\n    </solver>\n  </Control>"
    );
    let _ = writeln!(s, "  <Material>\n    <material id=\"1\" name=\"block\" type=\"Ogden\">\n      <density>1e-9</density>\n      <k>{k0:?}</k>\n      <c1>{:?}</c1>\n      <m1>2</m1>\n    </material>\n  </Material>", 2.0 * mu);
    let _ = writeln!(s, "  <Mesh>\n    <Nodes name=\"block\">");
    for (i, p) in t.nodes.iter().enumerate() {
        let _ = writeln!(s, r#"      <node id="{}">{:.9},{:.9},{:.9}</node>"#, i + 1, p[0], p[1], p[2]);
    }
    let _ = writeln!(s, "    </Nodes>\n    <Elements type=\"hex8\" name=\"block\">");
    for (e, n) in t.elements.iter().enumerate() {
        let v: Vec<String> = n.iter().map(|i| (i + 1).to_string()).collect();
        let _ = writeln!(s, r#"      <elem id="{}">{}</elem>"#, e + 1, v.join(","));
    }
    let _ = writeln!(s, "    </Elements>");
    for (name, set) in [("punch", &under), ("bottom", &bottom), ("sides", &sides), ("sym_x", &sym_x), ("sym_z", &sym_z)] {
        let _ = writeln!(s, r#"    <NodeSet name="{name}">"#);
        let ids: Vec<String> = set.iter().map(|i| (i + 1).to_string()).collect();
        for chunk in ids.chunks(16) {
            let _ = writeln!(s, "      {},", chunk.join(","));
        }
        let _ = writeln!(s, "    </NodeSet>");
    }
    let _ = writeln!(s, "  </Mesh>\n  <MeshDomains>\n    <SolidDomain name=\"block\" mat=\"block\"/>\n  </MeshDomains>\n  <Boundary>");
    for (name, set, xyz) in [
        ("bottom", "bottom", [1, 1, 1]),
        ("sides", "sides", [1, 1, 1]),
        ("sym_x", "sym_x", [1, 0, 0]),
        ("sym_z", "sym_z", [0, 0, 1]),
        ("punch_xz", "punch", [1, 0, 1]),
    ] {
        let _ = writeln!(
            s,
            "    <bc name=\"{name}\" node_set=\"{set}\" type=\"zero displacement\">\n      <x_dof>{}</x_dof>\n      <y_dof>{}</y_dof>\n      <z_dof>{}</z_dof>\n    </bc>",
            xyz[0], xyz[1], xyz[2]
        );
    }
    let _ = writeln!(
        s,
        "    <bc name=\"punch_y\" node_set=\"punch\" type=\"prescribed displacement\">\n      <dof>y</dof>\n      <value lc=\"1\">{:?}</value>\n      <relative>0</relative>\n    </bc>\n  </Boundary>",
        -delta
    );
    let _ = writeln!(
        s,
        "  <LoadData>\n    <load_controller id=\"1\" name=\"ramp\" type=\"loadcurve\">\n      <interpolate>LINEAR</interpolate>\n      <points>\n        <pt>0,0</pt>\n        <pt>1,1</pt>\n      </points>\n    </load_controller>\n  </LoadData>"
    );
    let _ = writeln!(
        s,
        "  <Output>\n    <logfile>\n      <node_data data=\"Ry\" node_set=\"punch\" file=\"{REACTION_LOG}\" delim=\",\"/>\n    </logfile>\n  </Output>\n</febio_spec>"
    );
    Ok(PunchFeb { text: s, nodes: t.nodes.len(), elements: t.elements.len(), punch_nodes: under.len() })
}

/// Solve the punch on the block scaled by `scale` in `dir` with `febio4` at `exe`: the
/// force of the whole punch, N (positive: the block pushes the punch back), and the wall
/// time, s.
///
/// # Errors
/// FEBio fails, or its log has no reactions at t = 1.
pub fn solve_punch(exe: &Path, c: &Campaign, mesh_scale: f64, a: f64, delta: f64, scale: f64, dir: &Path) -> Result<(f64, f64, PunchFeb)> {
    let mesh_level = punch_mesh(a, PUNCH_CORE_ELEMENTS_HEX8, mesh_scale);
    let feb = punch_feb(c, &mesh_level, a, delta, scale)?;
    std::fs::create_dir_all(dir).with_context(|| format!("{}: cannot create", dir.display()))?;
    std::fs::write(dir.join("punch.feb"), &feb.text).with_context(|| format!("{}: cannot write", dir.display()))?;
    let log_path = dir.join(REACTION_LOG);
    let _ = std::fs::remove_file(&log_path);
    let mut cmd = std::process::Command::new(exe);
    cmd.args(["-nosplash", "-i", "punch.feb", "-o", "punch.log", "-p", "punch.xplt"]).env("OMP_NUM_THREADS", "1");
    let done = process::run(cmd, dir, &dir.join("febio.out"), &[dir.join("punch.log")], None, Some(crate::campaign::DEFAULT_STALL))?;
    let run = logs::parse_run_log(&std::fs::read_to_string(dir.join("punch.log")).unwrap_or_default());
    if done.exit != process::ExitKind::Code(0) || !run.normal_termination {
        bail!(
            "punch (block {scale}x): febio4 {} {}; last lines of {}:\n{}",
            done.exit,
            run.cause.unwrap_or_default(),
            dir.join("punch.log").display(),
            process::tail(&done.log_text, 20)
        );
    }
    let text = std::fs::read_to_string(&log_path).with_context(|| format!("{}: cannot read", log_path.display()))?;
    let ry = node_sum_at_end(&text).with_context(|| format!("{}", log_path.display()))?;
    // the reaction is the force the prescription applies to the block; the block pushes
    // the punch with the opposite force; quarter model: 4x
    let f = -4.0 * ry;
    if !(f.is_finite() && f > 0.0) {
        bail!("punch (block {scale}x): force {f} N is not a positive number ({})", log_path.display());
    }
    Ok((f, done.wall.as_secs_f64(), feb))
}

/// The sum of the single value of every node line in the last block of a `node_data` log.
fn node_sum_at_end(text: &str) -> Result<f64> {
    let mut sum = None;
    for line in text.lines().map(str::trim).filter(|l| !l.is_empty()) {
        if line.starts_with('*') {
            if line.to_ascii_lowercase().starts_with("*time") {
                sum = Some(0.0);
            }
            continue;
        }
        let v: f64 = line
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|f| !f.is_empty())
            .nth(1)
            .context("a node line without a value")?
            .parse()
            .with_context(|| format!("not a number in {line:?}"))?;
        *sum.as_mut().context("data before *Time")? += v;
    }
    sum.context("no *Time block")
}

/// The `febio4` and its version, for the report.
///
/// # Errors
/// As [`febio::find_febio`], [`febio::febio_version`].
pub fn febio() -> Result<(std::path::PathBuf, String)> {
    let exe = febio::find_febio()?;
    let v = febio::febio_version(&exe)?;
    Ok((exe, v))
}

/// The check with the FEBio campaign's element (module docs).
pub(super) fn punch(c: &Campaign, work: &Path, opts: &VerifyOptions) -> Result<PunchReport> {
    let a = c.needle.diameter_mm / 2.0;
    let delta = a / 100.0;
    let mu = PUNCH_MU_N_PER_MM2;
    let nu = poisson(c.tissue.bulk_to_shear);
    let f_sneddon = sneddon_force(mu, a, delta, nu);
    let (exe, version) = febio()?;
    let mut f = [0.0; 2];
    let mut wall = [0.0; 2];
    let mut nodes = [0; 2];
    let mut nel = [0; 2];
    for (k, scale) in [1.0, 2.0].into_iter().enumerate() {
        let dir = work.join(format!("punch-febio-hex8-{scale}x"));
        needle_stdx::outln!("solving the flat punch with FEBio hex8 (three-field) on the block scaled {scale}x ...");
        let (force, w, feb) = solve_punch(&exe, c, opts.punch_mesh_scale, a, delta, scale, &dir)?;
        (f[k], wall[k], nodes[k], nel[k]) = (force, w, feb.nodes, feb.elements);
    }
    let mesh = punch_mesh(a, PUNCH_CORE_ELEMENTS_HEX8, opts.punch_mesh_scale);
    Ok(PunchReport {
        radius_mm: a,
        delta_mm: delta,
        mu_n_per_mm2: mu,
        bulk_to_shear: c.tissue.bulk_to_shear,
        nu,
        material: "uncoupled Ogden N=1, alpha = 2, c1 = 2 mu (the neo-Hookean energy), k = K0".to_string(),
        mesh: format!(
            "quarter model, round-core O-grid: {} elements across the punch diameter, fine size {:.4} mm over {} mm depth, growth {}",
            mesh.core_elements, mesh.fine_size_mm, mesh.fine_depth_mm, mesh.growth
        ),
        mesh_scale: opts.punch_mesh_scale,
        force_sneddon_n: f_sneddon,
        force_bonded_n: bonded_punch_force(mu, a, delta, nu),
        goal_percent: PUNCH_GOAL_PERCENT,
        solver: format!("febio {version}"),
        check: PunchRun::from_forces("FEBio hex8, three-field (the campaign's tissue element)", nodes, nel, f, wall, f_sneddon),
        campaign_element: None,
    })
}

#[cfg(test)]
mod tests {
    #[test]
    fn sums_the_last_block() {
        let t = "*Step = 1\n*Time = 0.5\n*Data = Ry\n1,1.0\n2,2.0\n*Step = 2\n*Time = 1\n*Data = Ry\n1,-0.5\n2,-0.25\n";
        assert_eq!(super::node_sum_at_end(t).ok(), Some(-0.75));
        assert!(super::node_sum_at_end("1,2\n").is_err());
    }
}
