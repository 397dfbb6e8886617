//! The size of a pose's model and the name of the part of the block it covers, for the
//! manifest and the wall-time projection, whatever the engine.

use super::{NeedleMesh, TissueMesh};
use crate::spec::Symmetry;
use serde::Serialize;

/// Size of the model, for the manifest.
#[derive(Debug, Clone, Serialize)]
pub struct MeshSummary {
    /// Tissue nodes.
    pub tissue_nodes: usize,
    /// Tissue elements (C3D8).
    pub tissue_elements: usize,
    /// Needle nodes (all with prescribed motion).
    pub needle_nodes: usize,
    /// Needle elements (C3D8, contact master faces only).
    pub needle_elements: usize,
    /// Which part of the block is modelled, e.g. "half, mirror plane z = 0".
    pub model: String,
    /// The tissue mesh in words.
    pub tissue_mesh: String,
}

impl MeshSummary {
    /// The summary of a pose's tissue and needle meshes with mirror planes `sym`.
    pub fn of(t: &TissueMesh, n: &NeedleMesh, sym: Symmetry) -> Self {
        MeshSummary {
            tissue_nodes: t.nodes.len(),
            tissue_elements: t.elements.len(),
            needle_nodes: n.nodes.len(),
            needle_elements: n.elements.len(),
            model: model_name(sym).to_string(),
            tissue_mesh: t.info.clone(),
        }
    }
}

/// Describe the modelled part for a symmetry.
pub fn model_name(sym: Symmetry) -> &'static str {
    match (sym.plane_x, sym.plane_z) {
        (true, true) => "quarter, mirror planes x = 0 and z = 0",
        (false, true) => "half, mirror plane z = 0",
        (true, false) => "half, mirror plane x = 0",
        (false, false) => "full block, no mirror plane",
    }
}
