//! The tissue block's mesh: an O-grid in plan (a square core around the middle of the
//! tip's path, rings growing geometrically out to the block's sides), clipped to the
//! modelled part (half or quarter models), extruded through the depth with grading
//! towards the top, with the contact faces and the boundary node sets.

use super::{orient, Symmetry, TissueMesh, FACES};
use crate::spec::{Block, MeshLevel, PoseSpec};
use std::collections::HashMap;

/// Contact slave region around the needle path: radius in mm beyond the path's centre.
const CONTACT_RADIUS_MM: f64 = 4.0;

/// The largest ring thickness and layer height, mm.
const HMAX_MM: f64 = 5.0;

/// Mesh the tissue block for `pose`: an O-grid centred on the middle of the tip's path.
pub fn tissue(block: &Block, m: &MeshLevel, pose: &PoseSpec, sym: Symmetry, depth_mm: f64) -> TissueMesh {
    tissue_shaped(block, m, pose, sym, depth_mm, false)
}

/// As [`tissue`]; with `round_core` the square core is mapped onto a disc of radius
/// `core_half_mm` (elliptical grid mapping) and the first rings blend from that circle
/// back to squares, so that a circular footprint of radius `core_half_mm` is meshed
/// exactly (used by the flat-punch verification; needs a pose without tilt).
pub fn tissue_shaped(block: &Block, m: &MeshLevel, pose: &PoseSpec, sym: Symmetry, depth_mm: f64, round_core: bool) -> TissueMesh {
    let grid = OGrid::plan(block, m, pose, sym, depth_mm);
    let (mut pts, quads) = grid.pattern();
    if round_core {
        for p in &mut pts {
            *p = round(*p, [grid.xc, grid.zc], m.core_half_mm);
        }
    }
    let (plan_pts, quads) = clip(&pts, quads, sym);
    let (mut mesh, layers) = extrude(block, m, pose, depth_mm, &plan_pts, &quads);
    boundary_sets(&mut mesh, block, sym);
    mesh.info = format!(
        "O-grid core {:.3} x {:.3} mm / {} x {} elements, {} rings, {} layers",
        2.0 * grid.cx,
        2.0 * grid.cz,
        grid.ncx,
        grid.ncz,
        grid.frac.len(),
        layers
    );
    mesh
}

/// The plan view of the O-grid: its centre, the core's half sides and element counts,
/// the distances from the centre to the four sides and the rings' cumulative fractions.
struct OGrid {
    xc: f64,
    zc: f64,
    /// Core half sides along x and z, mm.
    cx: f64,
    cz: f64,
    /// Core elements along x and z (even).
    ncx: usize,
    ncz: usize,
    /// Distances from the centre to the sides +x, -x, +z, -z, mm.
    d_xp: f64,
    d_xm: f64,
    d_zp: f64,
    d_zm: f64,
    /// Where ring `r + 1` ends, as a fraction of the way from the core to the sides.
    frac: Vec<f64>,
}

impl OGrid {
    fn plan(block: &Block, m: &MeshLevel, pose: &PoseSpec, sym: Symmetry, depth_mm: f64) -> Self {
        let (tx, tz) = pose.lateral_travel(depth_mm);
        let (hx, hz) = (block.size_x_mm / 2.0, block.size_z_mm / 2.0);
        let xc = if sym.plane_x { 0.0 } else { pose.x_mm + 0.5 * tx };
        let zc = if sym.plane_z { 0.0 } else { pose.z_mm + 0.5 * tz };
        let c = m.core_half_mm;
        let nc = m.core_elements as f64;
        let cx = c + 0.5 * tx.abs();
        let cz = c + 0.5 * tz.abs();
        let even = |v: f64| ((2.0 * (nc * v / c / 2.0).round()) as usize).max(2);
        let (d_xp, d_xm, d_zp, d_zm) = (hx - xc, xc + hx, hz - zc, zc + hz);
        let dref = d_xp.max(d_xm).max(d_zp).max(d_zm);
        let frac = ring_fractions(m, dref - cx.min(cz));
        Self { xc, zc, cx, cz, ncx: even(cx), ncz: even(cz), d_xp, d_xm, d_zp, d_zm, frac }
    }

    /// The square core's points and quads, then the rings'.
    fn pattern(&self) -> (Vec<[f64; 2]>, Vec<[usize; 4]>) {
        let (xc, zc, cx, cz, ncx, ncz) = (self.xc, self.zc, self.cx, self.cz, self.ncx, self.ncz);
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
        let mut prev = self.ring(&mut pat, 0);
        for r in 1..=self.frac.len() {
            let cur = self.ring(&mut pat, r);
            let l = cur.len();
            for q in 0..l {
                quads.push([prev[q], cur[q], cur[(q + 1) % l], prev[(q + 1) % l]]);
            }
            prev = cur;
        }
        (pat.pts, quads)
    }

    /// Half side of ring `ring` towards a side at distance `dd` from a core half side `c0`.
    fn extent(&self, ring: usize, c0: f64, dd: f64) -> f64 {
        let f = if ring == 0 { 0.0 } else { self.frac[ring - 1] };
        c0 + f * (dd - c0)
    }

    /// The points of ring `r` (0: the core's boundary), counter-clockwise from +x.
    fn ring(&self, pat: &mut Pattern, r: usize) -> Vec<usize> {
        let (xc, zc, ncx, ncz) = (self.xc, self.zc, self.ncx, self.ncz);
        let (exp, exm) = (self.extent(r, self.cx, self.d_xp), self.extent(r, self.cx, self.d_xm));
        let (ezp, ezm) = (self.extent(r, self.cz, self.d_zp), self.extent(r, self.cz, self.d_zm));
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
    }
}

/// The rings' cumulative fractions of the way `span_mm` from the core to the farthest
/// side: thicknesses geometric from the fine size (growth, capped at [`HMAX_MM`]), a last
/// ring under half the one before merged into it.
fn ring_fractions(m: &MeshLevel, span_mm: f64) -> Vec<f64> {
    let mut th = Vec::new();
    let (mut acc, mut d) = (0.0, m.fine_size_mm);
    while acc < span_mm - 1e-9 {
        th.push(d);
        acc += d;
        d = (d * m.growth).min(HMAX_MM);
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
    frac
}

/// Points of the plan, each once (keyed by its coordinates to 1e-7 mm).
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

/// The quads of the modelled part (a half or quarter model drops those whose centre is
/// across a mirror plane) and the points they use, renumbered in their order.
fn clip(pts: &[[f64; 2]], quads: Vec<[usize; 4]>, sym: Symmetry) -> (Vec<[f64; 2]>, Vec<[usize; 4]>) {
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
    let kept: Vec<[f64; 2]> = used.iter().map(|&o| pts[o]).collect();
    let quads: Vec<[usize; 4]> = quads.iter().map(|q| q.map(|i| remap[&i])).collect();
    (kept, quads)
}

/// The plan extruded through the block's depth (layers graded towards the top), with the
/// top faces within [`CONTACT_RADIUS_MM`] of the path's middle as the contact faces; and
/// the number of layers.
fn extrude(block: &Block, m: &MeshLevel, pose: &PoseSpec, depth_mm: f64, plan: &[[f64; 2]], quads: &[[usize; 4]]) -> (TissueMesh, usize) {
    let (tx, tz) = pose.lateral_travel(depth_mm);
    let n2 = plan.len();
    let ys = super::graded(-block.depth_mm, 0.0, -m.fine_depth_mm, 0.0, m.fine_size_mm, m.growth, HMAX_MM);
    let ny = ys.len();
    let mut mesh = TissueMesh::default();
    for &y in &ys {
        for p in plan {
            mesh.nodes.push([p[0], y, p[1]]);
        }
    }
    let id = |q: usize, j: usize| q + n2 * j;
    let centre = [pose.x_mm + 0.5 * tx, pose.z_mm + 0.5 * tz];
    let reach = [CONTACT_RADIUS_MM + 0.5 * tx.abs(), CONTACT_RADIUS_MM + 0.5 * tz.abs()];
    for j in 0..ny - 1 {
        for &[a, b, cc, dd] in quads {
            let n = [id(a, j), id(b, j), id(b, j + 1), id(a, j + 1), id(dd, j), id(cc, j), id(cc, j + 1), id(dd, j + 1)];
            let n = orient(n, |i| mesh.nodes[i]);
            mesh.elements.push(n);
            if j == ny - 2 {
                let e = mesh.elements.len() - 1;
                let cq = [
                    (plan[a][0] + plan[b][0] + plan[cc][0] + plan[dd][0]) / 4.0,
                    (plan[a][1] + plan[b][1] + plan[cc][1] + plan[dd][1]) / 4.0,
                ];
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
    (mesh, ny - 1)
}

/// The bottom, side and mirror-plane node sets.
fn boundary_sets(mesh: &mut TissueMesh, block: &Block, sym: Symmetry) {
    let (hx, hz) = (block.size_x_mm / 2.0, block.size_z_mm / 2.0);
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
