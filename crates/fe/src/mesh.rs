//! Hexahedral meshes of the tissue block (an O-grid refined around the needle's path)
//! and of the needle (an O-grid cross-section swept along the axis, wedge tip).
//!
//! Frame (docs/architecture.md section 3): origin at the centre of the top surface, y up, the
//! block occupies |x| <= size_x/2, |z| <= size_z/2, -depth <= y <= 0.

use super::spec::{Block, Campaign, MeshLevel, Needle, PoseSpec, Symmetry};
use anyhow::{bail, Result};
use std::collections::HashMap;

/// A point in the block frame, mm.
pub type P3 = [f64; 3];

/// Face numbering of a C3D8 element (CalculiX/Abaqus): local node indices of faces S1..S6.
pub const FACES: [[usize; 4]; 6] = [[0, 1, 2, 3], [4, 7, 6, 5], [0, 4, 5, 1], [1, 5, 6, 2], [2, 6, 7, 3], [3, 7, 4, 0]];

/// The tissue mesh. Node `i` of `nodes` has CalculiX id `i + 1`, element `e` id `e + 1`.
#[derive(Debug, Clone, Default)]
pub struct TissueMesh {
    /// Node coordinates, mm.
    pub nodes: Vec<P3>,
    /// C3D8 connectivity (0-based node indices), positive volume.
    pub elements: Vec<[usize; 8]>,
    /// Top-surface faces near the needle (element index, face number 1..=6): the contact slave.
    pub top_faces: Vec<(usize, u8)>,
    /// Nodes on the bottom face (encastred).
    pub bottom: Vec<usize>,
    /// Nodes on the four side faces (pinned).
    pub sides: Vec<usize>,
    /// Nodes on the mirror plane x = 0 (half or quarter models).
    pub plane_x: Vec<usize>,
    /// Nodes on the mirror plane z = 0.
    pub plane_z: Vec<usize>,
    /// Human summary, e.g. "O-grid core 1.2 x 1.2 mm / 4 x 4, 11 rings, 13 layers".
    pub info: String,
}

/// The needle mesh (rigid: every node follows the prescribed needle motion).
#[derive(Debug, Clone, Default)]
pub struct NeedleMesh {
    /// Node coordinates in the block frame at depth 0 (lowest point touching y = 0), mm.
    pub nodes: Vec<P3>,
    /// C3D8 connectivity (0-based), positive volume.
    pub elements: Vec<[usize; 8]>,
    /// Outer faces that can touch the tissue: the contact master.
    pub faces: Vec<(usize, u8)>,
    /// Nodes that carry the contact reactions (nodes of `faces`).
    pub surface_nodes: Vec<usize>,
    /// Centre of the tip (local origin) at depth 0, mm.
    pub tip: P3,
    /// Unit axis from tip to hub.
    pub axis: P3,
}

/// Points `lo..=hi` with uniform spacing `h` over `[flo, fhi]` and geometric growth `g`
/// (capped at `hmax`) outside it.
pub fn graded(lo: f64, hi: f64, flo: f64, fhi: f64, h: f64, g: f64, hmax: f64) -> Vec<f64> {
    let flo = flo.max(lo);
    let fhi = fhi.min(hi);
    let n = (((fhi - flo) / h).round() as usize).max(1);
    let core: Vec<f64> = (0..=n).map(|i| flo + (fhi - flo) * i as f64 / n as f64).collect();
    let side = |length: f64| -> Vec<f64> {
        if length <= 1e-9 {
            return Vec::new();
        }
        let (mut s, mut d, mut out) = (0.0, h, Vec::new());
        loop {
            d = (d * g).min(hmax);
            if s + d >= length - 0.3 * d {
                break;
            }
            s += d;
            out.push(s);
        }
        out.push(length);
        out
    };
    let mut left: Vec<f64> = side(flo - lo).into_iter().map(|s| flo - s).collect();
    left.reverse();
    let right: Vec<f64> = side(hi - fhi).into_iter().map(|s| fhi + s).collect();
    let mut all = left;
    all.extend(core);
    all.extend(right);
    all
}

fn sub(a: P3, b: P3) -> P3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn cross(a: P3, b: P3) -> P3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
fn dot(a: P3, b: P3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Order the 8 nodes of a hexahedron so that its volume is positive (CalculiX convention).
fn orient(n: [usize; 8], xyz: impl Fn(usize) -> P3) -> [usize; 8] {
    let p: Vec<P3> = n.iter().map(|&i| xyz(i)).collect();
    if dot(cross(sub(p[1], p[0]), sub(p[3], p[0])), sub(p[4], p[0])) < 0.0 {
        [n[4], n[5], n[6], n[7], n[0], n[1], n[2], n[3]]
    } else {
        n
    }
}

struct Pattern {
    pts: Vec<[f64; 2]>,
    key: HashMap<(i64, i64), usize>,
}
impl Pattern {
    fn node(&mut self, x: f64, z: f64) -> usize {
        let k = ((x * 1e7).round() as i64, (z * 1e7).round() as i64);
        if let Some(&i) = self.key.get(&k) {
            return i;
        }
        self.pts.push([x, z]);
        self.key.insert(k, self.pts.len() - 1);
        self.pts.len() - 1
    }
}

/// The tissue and needle meshes of `pose` on `mesh_level` with mirror planes `sym`, for
/// a solver input of `steps` load steps (every engine's writer starts here).
///
/// # Errors
/// A mirror plane the pose does not have, 0 steps, or a mesh without contact faces.
pub fn pose_meshes(c: &Campaign, pose: &PoseSpec, mesh_level: &MeshLevel, steps: u32, sym: Symmetry) -> Result<(TissueMesh, NeedleMesh)> {
    let own = pose.symmetry();
    if (sym.plane_x && !own.plane_x) || (sym.plane_z && !own.plane_z) {
        bail!("pose {}: asked for a mirror plane the pose does not have", pose.name);
    }
    if steps == 0 {
        bail!("pose {}: 0 load steps", pose.name);
    }
    let depth = c.loading.depth_mm;
    let t = tissue(&c.block, mesh_level, pose, sym, depth);
    let n = needle(&c.needle, mesh_level, pose, depth, sym);
    if t.top_faces.is_empty() || n.faces.is_empty() {
        bail!("pose {}: the mesh has no contact faces (tissue {}, needle {})", pose.name, t.top_faces.len(), n.faces.len());
    }
    Ok((t, n))
}

/// Contact slave region around the needle path: radius in mm beyond the path's centre.
const CONTACT_RADIUS_MM: f64 = 4.0;

/// Mesh the tissue block for `pose`: an O-grid centred on the middle of the tip's path.
pub fn tissue(block: &Block, m: &MeshLevel, pose: &PoseSpec, sym: Symmetry, depth_mm: f64) -> TissueMesh {
    tissue_shaped(block, m, pose, sym, depth_mm, false)
}

/// As [`tissue`]; with `round_core` the square core is mapped onto a disc of radius
/// `core_half_mm` (elliptical grid mapping) and the first rings blend from that circle
/// back to squares, so that a circular footprint of radius `core_half_mm` is meshed
/// exactly (used by the flat-punch verification; needs a pose without tilt).
pub fn tissue_shaped(block: &Block, m: &MeshLevel, pose: &PoseSpec, sym: Symmetry, depth_mm: f64, round_core: bool) -> TissueMesh {
    let (tx, tz) = pose.lateral_travel(depth_mm);
    let (hx, hz) = (block.size_x_mm / 2.0, block.size_z_mm / 2.0);
    let xc = if sym.plane_x { 0.0 } else { pose.x_mm + 0.5 * tx };
    let zc = if sym.plane_z { 0.0 } else { pose.z_mm + 0.5 * tz };
    let c = m.core_half_mm;
    let nc = m.core_elements as f64;
    let cx = c + 0.5 * tx.abs();
    let cz = c + 0.5 * tz.abs();
    let even = |v: f64| ((2.0 * (nc * v / c / 2.0).round()) as usize).max(2);
    let (ncx, ncz) = (even(cx), even(cz));
    let d_xp = hx - xc;
    let d_xm = xc + hx;
    let d_zp = hz - zc;
    let d_zm = zc + hz;
    let dref = d_xp.max(d_xm).max(d_zp).max(d_zm);
    let hmax = 5.0;
    // ring thicknesses: geometric from the fine size
    let mut th = Vec::new();
    let (mut acc, mut d) = (0.0, m.fine_size_mm);
    while acc < dref - cx.min(cz) - 1e-9 {
        th.push(d);
        acc += d;
        d = (d * m.growth).min(hmax);
    }
    if th.len() > 1 && th[th.len() - 1] < 0.5 * th[th.len() - 2] {
        th.pop();
    }
    let total: f64 = th.iter().sum();
    let mut frac = Vec::with_capacity(th.len());
    let mut s = 0.0;
    for t in &th {
        s += t;
        frac.push(s / total);
    }
    let rings = frac.len();
    let ext = |ring: usize, c0: f64, dd: f64| -> f64 {
        let f = if ring == 0 { 0.0 } else { frac[ring - 1] };
        c0 + f * (dd - c0)
    };
    let mut pat = Pattern { pts: Vec::new(), key: HashMap::new() };
    let mut quads: Vec<[usize; 4]> = Vec::new();
    let core: Vec<Vec<usize>> = (0..=ncx)
        .map(|i| {
            (0..=ncz)
                .map(|j| pat.node(xc + cx * (-1.0 + 2.0 * i as f64 / ncx as f64), zc + cz * (-1.0 + 2.0 * j as f64 / ncz as f64)))
                .collect()
        })
        .collect();
    for i in 0..ncx {
        for j in 0..ncz {
            quads.push([core[i][j], core[i + 1][j], core[i + 1][j + 1], core[i][j + 1]]);
        }
    }
    let ring_pts = |pat: &mut Pattern, r: usize| -> Vec<usize> {
        let (exp, exm) = (ext(r, cx, d_xp), ext(r, cx, d_xm));
        let (ezp, ezm) = (ext(r, cz, d_zp), ext(r, cz, d_zm));
        let side = |t: f64, plus: f64, minus: f64| if t < 0.0 { t * minus } else { t * plus };
        let mut ids = Vec::new();
        for i in 0..ncz {
            let t = -1.0 + 2.0 * i as f64 / ncz as f64;
            ids.push(pat.node(xc + exp, zc + side(t, ezp, ezm)));
        }
        for i in 0..ncx {
            let t = -1.0 + 2.0 * i as f64 / ncx as f64;
            ids.push(pat.node(xc + side(-t, exp, exm), zc + ezp));
        }
        for i in 0..ncz {
            let t = -1.0 + 2.0 * i as f64 / ncz as f64;
            ids.push(pat.node(xc - exm, zc + side(-t, ezp, ezm)));
        }
        for i in 0..ncx {
            let t = -1.0 + 2.0 * i as f64 / ncx as f64;
            ids.push(pat.node(xc + side(t, exp, exm), zc - ezm));
        }
        ids
    };
    let mut prev = ring_pts(&mut pat, 0);
    for r in 1..=rings {
        let cur = ring_pts(&mut pat, r);
        let l = cur.len();
        for q in 0..l {
            quads.push([prev[q], cur[q], cur[(q + 1) % l], prev[(q + 1) % l]]);
        }
        prev = cur;
    }
    // clip to the modelled part
    let mut pts = pat.pts;
    if round_core {
        for p in &mut pts {
            *p = round(*p, [xc, zc], c);
        }
    }
    let quads: Vec<[usize; 4]> = quads
        .into_iter()
        .filter(|q| {
            let cxq = q.iter().map(|&i| pts[i][0]).sum::<f64>() / 4.0;
            let czq = q.iter().map(|&i| pts[i][1]).sum::<f64>() / 4.0;
            let mirrored_away = (sym.plane_z && czq < 0.0) || (sym.plane_x && cxq < 0.0);
            !mirrored_away
        })
        .collect();
    let mut used: Vec<usize> = quads.iter().flatten().copied().collect();
    used.sort_unstable();
    used.dedup();
    let remap: HashMap<usize, usize> = used.iter().enumerate().map(|(n, &o)| (o, n)).collect();
    let p2: Vec<[f64; 2]> = used.iter().map(|&o| pts[o]).collect();
    let quads: Vec<[usize; 4]> = quads.iter().map(|q| q.map(|i| remap[&i])).collect();
    let n2 = p2.len();

    let ys = graded(-block.depth_mm, 0.0, -m.fine_depth_mm, 0.0, m.fine_size_mm, m.growth, hmax);
    let ny = ys.len();
    let mut mesh = TissueMesh::default();
    for &y in &ys {
        for p in &p2 {
            mesh.nodes.push([p[0], y, p[1]]);
        }
    }
    let id = |q: usize, j: usize| q + n2 * j;
    let centre = [pose.x_mm + 0.5 * tx, pose.z_mm + 0.5 * tz];
    let reach = [CONTACT_RADIUS_MM + 0.5 * tx.abs(), CONTACT_RADIUS_MM + 0.5 * tz.abs()];
    for j in 0..ny - 1 {
        for &[a, b, cc, dd] in &quads {
            let n = [id(a, j), id(b, j), id(b, j + 1), id(a, j + 1), id(dd, j), id(cc, j), id(cc, j + 1), id(dd, j + 1)];
            let n = orient(n, |i| mesh.nodes[i]);
            mesh.elements.push(n);
            if j == ny - 2 {
                let e = mesh.elements.len() - 1;
                let cq = [(p2[a][0] + p2[b][0] + p2[cc][0] + p2[dd][0]) / 4.0, (p2[a][1] + p2[b][1] + p2[cc][1] + p2[dd][1]) / 4.0];
                if (cq[0] - centre[0]).abs() <= reach[0] && (cq[1] - centre[1]).abs() <= reach[1] {
                    for (f, fnodes) in FACES.iter().enumerate() {
                        if fnodes.iter().all(|&k| mesh.nodes[n[k]][1].abs() < 1e-9) {
                            mesh.top_faces.push((e, f as u8 + 1));
                        }
                    }
                }
            }
        }
    }
    let eps = 1e-6;
    for (i, p) in mesh.nodes.iter().enumerate() {
        if (p[1] + block.depth_mm).abs() < eps {
            mesh.bottom.push(i);
        }
        if (p[0].abs() - hx).abs() < eps || (p[2].abs() - hz).abs() < eps {
            mesh.sides.push(i);
        }
        if sym.plane_x && p[0].abs() < eps {
            mesh.plane_x.push(i);
        }
        if sym.plane_z && p[2].abs() < eps {
            mesh.plane_z.push(i);
        }
    }
    mesh.info =
        format!("O-grid core {:.3} x {:.3} mm / {} x {} elements, {} rings, {} layers", 2.0 * cx, 2.0 * cz, ncx, ncz, rings, ny - 1);
    mesh
}

/// Mesh the needle for `pose` at depth 0. The cross-section is a square core and four
/// outer blocks (an O-grid) with `4 * needle_facets_per_quarter` facets, scaled so that
/// the faceted section has the circle's area. Layers: graded over the wedge, then
/// `needle_axial_mm`... up to `depth + 3` mm, then 4 mm layers up to `mesh_len_mm`.
pub fn needle(nd: &Needle, m: &MeshLevel, pose: &PoseSpec, depth_mm: f64, sym: Symmetry) -> NeedleMesh {
    let ns = m.needle_facets_per_quarter as usize;
    let nf = 4.0 * ns as f64;
    let r0 = nd.diameter_mm / 2.0;
    let r = r0 * (2.0 * std::f64::consts::PI / (nf * (2.0 * std::f64::consts::PI / nf).sin())).sqrt();
    let s_core = 0.45 * r;
    // cross-section (p = wedge thickness direction = local x, q = edge direction = local z)
    let mut cs: Vec<[f64; 2]> = Vec::new();
    let mut outer: Vec<bool> = Vec::new();
    let mut key: HashMap<(i64, i64), usize> = HashMap::new();
    let mut node = |p: f64, q: f64, is_outer: bool, cs: &mut Vec<[f64; 2]>, outer: &mut Vec<bool>| -> usize {
        let k = ((p * 1e9).round() as i64, (q * 1e9).round() as i64);
        let i = *key.entry(k).or_insert_with(|| {
            cs.push([p, q]);
            outer.push(false);
            cs.len() - 1
        });
        if is_outer {
            outer[i] = true;
        }
        i
    };
    let mut quads: Vec<[usize; 4]> = Vec::new();
    let core: Vec<Vec<usize>> = (0..=ns)
        .map(|i| {
            (0..=ns)
                .map(|j| {
                    let p = s_core * (-1.0 + 2.0 * i as f64 / ns as f64);
                    let q = s_core * (-1.0 + 2.0 * j as f64 / ns as f64);
                    node(p, q, false, &mut cs, &mut outer)
                })
                .collect()
        })
        .collect();
    for i in 0..ns {
        for j in 0..ns {
            quads.push([core[i][j], core[i + 1][j], core[i + 1][j + 1], core[i][j + 1]]);
        }
    }
    for rot in 0..4 {
        let ang = rot as f64 * std::f64::consts::FRAC_PI_2;
        let (s, c) = ang.sin_cos();
        let mut blk = Vec::new();
        for it in 0..=ns {
            let t = -1.0 + 2.0 * it as f64 / ns as f64;
            let phi = t * std::f64::consts::FRAC_PI_4;
            let mut row = Vec::new();
            for (ir, rho) in [0.0, 1.0].into_iter().enumerate() {
                let pin = [s_core, s_core * t];
                let pout = [r * phi.cos(), r * phi.sin()];
                let p = (1.0 - rho) * pin[0] + rho * pout[0];
                let q = (1.0 - rho) * pin[1] + rho * pout[1];
                row.push(node(c * p - s * q, s * p + c * q, ir == 1, &mut cs, &mut outer));
            }
            blk.push(row);
        }
        for it in 0..ns {
            quads.push([blk[it][0], blk[it][1], blk[it + 1][1], blk[it + 1][0]]);
        }
    }
    // axial layers (distance h from the tip along the axis)
    let beta = nd.wedge_half_angle_deg.to_radians();
    let (tb, sb) = (beta.tan(), beta.sin());
    let rho = nd.tip_edge_radius_mm;
    let h_apex = rho - rho / sb;
    let h_tan = rho - rho * sb;
    let l_tip = r / tb + h_apex;
    let wmin = 0.01;
    let half_width = |h: f64| -> f64 {
        if h < h_tan {
            (rho * rho - (rho - h) * (rho - h)).max(0.0).sqrt().max(wmin)
        } else {
            (h - h_apex) * tb
        }
    };
    let nt = ((l_tip / m.needle_axial_mm).ceil() as usize).max(4);
    let mut hl: Vec<f64> = (0..=nt).map(|i| l_tip * (i as f64 / nt as f64).powf(1.5)).collect();
    let zone = (depth_mm + 2.0).max(l_tip + 1.0);
    let mut h = l_tip;
    let shaft_step = (2.0 * m.needle_axial_mm).max(0.3);
    while h < zone - 1e-9 {
        h = (h + shaft_step).min(zone);
        hl.push(h);
    }
    let wedge = |p: f64, q: f64, h: f64| -> f64 {
        let w = half_width(h);
        if w >= r {
            return p;
        }
        let cq = (r * r - q * q).max(0.0).sqrt();
        if cq < 1e-12 {
            0.0
        } else {
            p * (w / cq).min(1.0)
        }
    };
    let (sx, cx) = pose.theta_x_deg.to_radians().sin_cos();
    let (sz, cz) = pose.theta_z_deg.to_radians().sin_cos();
    // R = Rz(theta_z) * Rx(theta_x)
    let rot = |v: P3| -> P3 {
        let a = [v[0], cx * v[1] - sx * v[2], sx * v[1] + cx * v[2]];
        [cz * a[0] - sz * a[1], sz * a[0] + cz * a[1], a[2]]
    };
    let ncs = cs.len();
    let mut pts: Vec<P3> = Vec::with_capacity(hl.len() * ncs);
    for &h in &hl {
        for &[p, q] in &cs {
            pts.push(rot([wedge(p, q, h), h, q]));
        }
    }
    let ymin = pts.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min);
    for p in &mut pts {
        p[0] += pose.x_mm;
        p[1] -= ymin;
        p[2] += pose.z_mm;
    }
    let mut mesh = NeedleMesh { tip: [pose.x_mm, -ymin, pose.z_mm], axis: rot([0.0, 1.0, 0.0]), ..Default::default() };
    let nid = |l: usize, c: usize| l * ncs + c;
    let margin = 0.5 * r;
    let mut on_surface = vec![false; pts.len()];
    for l in 0..hl.len() - 1 {
        for &[a, b, c, d] in &quads {
            let n = [nid(l, a), nid(l, b), nid(l + 1, b), nid(l + 1, a), nid(l, d), nid(l, c), nid(l + 1, c), nid(l + 1, d)];
            let n = orient(n, |i| pts[i]);
            mesh.elements.push(n);
            let e = mesh.elements.len() - 1;
            for (f, fnodes) in FACES.iter().enumerate() {
                let fnn: Vec<usize> = fnodes.iter().map(|&k| n[k]).collect();
                let lay: Vec<usize> = fnn.iter().map(|&i| i / ncs).collect();
                let cc: Vec<usize> = fnn.iter().map(|&i| i % ncs).collect();
                let ctr: P3 = [0, 1, 2].map(|k| fnn.iter().map(|&i| pts[i][k]).sum::<f64>() / 4.0);
                if (sym.plane_z && ctr[2] < -margin) || (sym.plane_x && ctr[0] < -margin) {
                    continue;
                }
                let mut distinct = cc.clone();
                distinct.sort_unstable();
                distinct.dedup();
                let lateral = cc.iter().all(|&k| outer[k]) && distinct.len() == 2;
                let tip_end = lay.iter().all(|&k| k == 0);
                if lateral || tip_end {
                    mesh.faces.push((e, f as u8 + 1));
                    for &i in &fnn {
                        on_surface[i] = true;
                    }
                }
            }
        }
    }
    mesh.surface_nodes = (0..pts.len()).filter(|&i| on_surface[i]).collect();
    mesh.nodes = pts;
    mesh
}

/// Map a point of the square O-grid to the rounded one: inside the core square of half
/// side `c` by the elliptical grid mapping onto the disc of radius `c`; outside, rings of
/// square radius s (in units of c) move towards the circle of radius s, fully at s = 1
/// and not at all from s = 3 on.
fn round(p: [f64; 2], centre: [f64; 2], c: f64) -> [f64; 2] {
    let (dx, dz) = (p[0] - centre[0], p[1] - centre[1]);
    let s = dx.abs().max(dz.abs()) / c;
    if s < 1e-12 {
        return p;
    }
    let (q, b) = if s <= 1.0 {
        let (u, v) = (dx / c, dz / c);
        ([c * u * (1.0 - v * v / 2.0).sqrt(), c * v * (1.0 - u * u / 2.0).sqrt()], 0.0)
    } else {
        let r = (dx * dx + dz * dz).sqrt();
        ([dx * s * c / r, dz * s * c / r], ((s - 1.0) / 2.0).clamp(0.0, 1.0))
    };
    [centre[0] + (1.0 - b) * q[0] + b * dx, centre[1] + (1.0 - b) * q[1] + b * dz]
}
