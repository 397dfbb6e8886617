//! Hexahedral meshes of the tissue block (an O-grid refined around the needle's path)
//! and of the needle (an O-grid cross-section swept along the axis, wedge tip): the
//! types and the shared geometry here, the tissue's steps in `tissue`, the needle's in
//! `needle`; `summary` the model's size; the mesh study in `study` (its levels' runs
//! through the campaign, compared by `shape`).
//!
//! Frame (docs/architecture.md section 3): origin at the centre of the top surface, y up, the
//! block occupies |x| <= size_x/2, |z| <= size_z/2, -depth <= y <= 0.

mod needle;
pub mod shape;
pub mod study;
pub mod summary;
mod tissue;

pub use needle::needle;
pub use tissue::{tissue, tissue_shaped};

use super::spec::{Campaign, MeshLevel, PoseSpec, Symmetry};
use anyhow::{bail, Result};

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
