//! The needle's mesh: an O-grid cross-section (a square core and four outer blocks) swept
//! along the axis, the wedge tip cut into it, rotated to the pose's tilt and placed with
//! its lowest point on the top surface; the outer faces are the contact faces.

use super::{orient, NeedleMesh, Symmetry, FACES, P3};
use crate::spec::{MeshLevel, Needle, PoseSpec};
use std::collections::HashMap;

/// Mesh the needle for `pose` at depth 0. The cross-section is a square core and four
/// outer blocks (an O-grid) with `4 * needle_facets_per_quarter` facets, scaled so that
/// the faceted section has the circle's area. Layers: graded over the wedge, then
/// `needle_axial_mm`... up to `depth + 3` mm, then 4 mm layers up to `mesh_len_mm`.
pub fn needle(nd: &Needle, m: &MeshLevel, pose: &PoseSpec, depth_mm: f64, sym: Symmetry) -> NeedleMesh {
    let ns = m.needle_facets_per_quarter as usize;
    let nf = 4.0 * ns as f64;
    let r0 = nd.diameter_mm / 2.0;
    let r = r0 * (2.0 * std::f64::consts::PI / (nf * (2.0 * std::f64::consts::PI / nf).sin())).sqrt();
    let section = Section::new(ns, r);
    let tip = Tip::new(nd, r);
    let layers = tip.layers(m, depth_mm);
    let placed = place(&section, &tip, &layers, pose);
    let mut mesh = NeedleMesh { tip: placed.tip, axis: placed.axis, ..Default::default() };
    let on_surface = extrude(&mut mesh, &section, &placed.pts, layers.len(), 0.5 * r, sym);
    mesh.surface_nodes = (0..placed.pts.len()).filter(|&i| on_surface[i]).collect();
    mesh.nodes = placed.pts;
    mesh
}

/// The cross-section (p = wedge thickness direction = local x, q = edge direction =
/// local z): its points, which of them are on the outer circle, its quads.
struct Section {
    pts: Vec<[f64; 2]>,
    outer: Vec<bool>,
    quads: Vec<[usize; 4]>,
}

impl Section {
    /// `ns` facets per quarter on the circle of radius `r`, a core square of half side
    /// 0.45 r.
    fn new(ns: usize, r: f64) -> Self {
        let s_core = 0.45 * r;
        let mut s = Self { pts: Vec::new(), outer: Vec::new(), quads: Vec::new() };
        let mut key: HashMap<(i64, i64), usize> = HashMap::new();
        let core: Vec<Vec<usize>> = (0..=ns)
            .map(|i| {
                (0..=ns)
                    .map(|j| {
                        let p = s_core * (-1.0 + 2.0 * i as f64 / ns as f64);
                        let q = s_core * (-1.0 + 2.0 * j as f64 / ns as f64);
                        s.node(&mut key, p, q, false)
                    })
                    .collect()
            })
            .collect();
        for i in 0..ns {
            for j in 0..ns {
                s.quads.push([core[i][j], core[i + 1][j], core[i + 1][j + 1], core[i][j + 1]]);
            }
        }
        for rot in 0..4 {
            let ang = rot as f64 * std::f64::consts::FRAC_PI_2;
            let (sn, c) = ang.sin_cos();
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
                    row.push(s.node(&mut key, c * p - sn * q, sn * p + c * q, ir == 1));
                }
                blk.push(row);
            }
            for it in 0..ns {
                s.quads.push([blk[it][0], blk[it][1], blk[it + 1][1], blk[it + 1][0]]);
            }
        }
        s
    }

    /// The point at (p, q), each once (keyed to 1e-9 mm); `is_outer` marks it as on the
    /// circle (a point met again keeps the mark).
    fn node(&mut self, key: &mut HashMap<(i64, i64), usize>, p: f64, q: f64, is_outer: bool) -> usize {
        let k = ((p * 1e9).round() as i64, (q * 1e9).round() as i64);
        let i = *key.entry(k).or_insert_with(|| {
            self.pts.push([p, q]);
            self.outer.push(false);
            self.pts.len() - 1
        });
        if is_outer {
            self.outer[i] = true;
        }
        i
    }
}

/// The wedge tip of a section of radius `r`: a wedge of half angle beta whose edge is
/// rounded with radius rho.
struct Tip {
    r: f64,
    tan_beta: f64,
    rho: f64,
    /// Distance from the tip to the wedge's apex (negative: behind the rounded edge), mm.
    h_apex: f64,
    /// Distance from the tip to where the rounding meets the wedge's faces, mm.
    h_tan: f64,
    /// Length of the wedge, mm.
    length: f64,
}

impl Tip {
    fn new(nd: &Needle, r: f64) -> Self {
        let beta = nd.wedge_half_angle_deg.to_radians();
        let (tb, sb) = (beta.tan(), beta.sin());
        let rho = nd.tip_edge_radius_mm;
        let h_apex = rho - rho / sb;
        let h_tan = rho - rho * sb;
        Self { r, tan_beta: tb, rho, h_apex, h_tan, length: r / tb + h_apex }
    }

    /// Half thickness of the section at distance `h` from the tip (at least 0.01 mm).
    fn half_width(&self, h: f64) -> f64 {
        let rho = self.rho;
        if h < self.h_tan {
            (rho * rho - (rho - h) * (rho - h)).max(0.0).sqrt().max(0.01)
        } else {
            (h - self.h_apex) * self.tan_beta
        }
    }

    /// The thickness coordinate `p` of a section point at (p, q), squeezed into the
    /// wedge at distance `h` from the tip.
    fn wedge(&self, p: f64, q: f64, h: f64) -> f64 {
        let w = self.half_width(h);
        let r = self.r;
        if w >= r {
            return p;
        }
        let cq = (r * r - q * q).max(0.0).sqrt();
        if cq < 1e-12 {
            0.0
        } else {
            p * (w / cq).min(1.0)
        }
    }

    /// Distances of the layers from the tip: graded (power 1.5) over the wedge, then
    /// steps of twice `needle_axial_mm` (at least 0.3 mm) to 2 mm past the depth.
    fn layers(&self, m: &MeshLevel, depth_mm: f64) -> Vec<f64> {
        let l_tip = self.length;
        let nt = ((l_tip / m.needle_axial_mm).ceil() as usize).max(4);
        let mut hl: Vec<f64> = (0..=nt).map(|i| l_tip * (i as f64 / nt as f64).powf(1.5)).collect();
        let zone = (depth_mm + 2.0).max(l_tip + 1.0);
        let mut h = l_tip;
        let shaft_step = (2.0 * m.needle_axial_mm).max(0.3);
        while h < zone - 1e-9 {
            h = (h + shaft_step).min(zone);
            hl.push(h);
        }
        hl
    }
}

/// The needle's points in the block frame at depth 0, its tip and axis.
struct Placed {
    pts: Vec<P3>,
    tip: P3,
    axis: P3,
}

/// The swept points rotated by R = Rz(theta_z) * Rx(theta_x) and moved so that the
/// lowest point touches y = 0 above the pose's (x, z).
fn place(section: &Section, tip: &Tip, layers: &[f64], pose: &PoseSpec) -> Placed {
    let (sx, cx) = pose.theta_x_deg.to_radians().sin_cos();
    let (sz, cz) = pose.theta_z_deg.to_radians().sin_cos();
    let rot = |v: P3| -> P3 {
        let a = [v[0], cx * v[1] - sx * v[2], sx * v[1] + cx * v[2]];
        [cz * a[0] - sz * a[1], sz * a[0] + cz * a[1], a[2]]
    };
    let mut pts: Vec<P3> = Vec::with_capacity(layers.len() * section.pts.len());
    for &h in layers {
        for &[p, q] in &section.pts {
            pts.push(rot([tip.wedge(p, q, h), h, q]));
        }
    }
    let ymin = pts.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min);
    for p in &mut pts {
        p[0] += pose.x_mm;
        p[1] -= ymin;
        p[2] += pose.z_mm;
    }
    Placed { pts, tip: [pose.x_mm, -ymin, pose.z_mm], axis: rot([0.0, 1.0, 0.0]) }
}

/// The hexahedra between successive layers into `mesh`, with the lateral faces and the
/// tip's end as the contact faces (those beyond `margin` across a mirror plane left
/// out); which points are on those faces.
fn extrude(mesh: &mut NeedleMesh, section: &Section, pts: &[P3], n_layers: usize, margin: f64, sym: Symmetry) -> Vec<bool> {
    let ncs = section.pts.len();
    let nid = |l: usize, c: usize| l * ncs + c;
    let mut on_surface = vec![false; pts.len()];
    for l in 0..n_layers - 1 {
        for &[a, b, c, d] in &section.quads {
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
                let lateral = cc.iter().all(|&k| section.outer[k]) && distinct.len() == 2;
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
    on_surface
}
