//! From the needle nodes' reaction forces of one CalculiX step to the wrench on the needle.
//!
//! CalculiX's RF at a node with prescribed motion is the force the *constraint* applies
//! to the needle; the tissue applies the opposite. The wrench reported everywhere in this
//! project is the force and moment the **tissue exerts on the needle** (what the haptic
//! device must push back on the hand with): `F = -sum RF_i`, `M = sum (X_i - H) x (-RF_i)`,
//! about the reference point H on the needle axis (the hub), which moves with the needle.
//! The needle only translates, so `X_i - H` is the same at every step as at depth 0.
//! Half and quarter models are expanded with [`expand_mirrors`].

use super::deck::Deck;
use crate::spec::{Campaign, PoseSpec};
use crate::wrench::expand_mirrors;
use anyhow::{bail, Result};
use needle_contract::COMPONENT_COUNT;
use std::collections::HashMap;

/// The wrench `[fx_n, fy_n, fz_n, mx_nmm, my_nmm, mz_nmm]` on the whole needle from the
/// reaction forces `rf` (node id, N) of one step of `deck`.
///
/// # Errors
/// A node in `rf` that is not one of the deck's printed needle nodes, or a non-finite force.
pub fn reduce(deck: &Deck, _pose: &PoseSpec, _c: &Campaign, rf: &[(u32, [f64; 3])]) -> Result<[f64; COMPONENT_COUNT]> {
    let pos: HashMap<u32, [f64; 3]> = deck.print_nodes.iter().copied().collect();
    let h = deck.reference_mm;
    let mut w = [0.0f64; COMPONENT_COUNT];
    for (id, f) in rf {
        let Some(x) = pos.get(id) else {
            bail!("reaction force for node {id}, which is not a printed needle node");
        };
        if !f.iter().all(|v| v.is_finite()) {
            bail!("reaction force of node {id} is not finite: {f:?}");
        }
        let f = [-f[0], -f[1], -f[2]];
        let r = [x[0] - h[0], x[1] - h[1], x[2] - h[2]];
        w[0] += f[0];
        w[1] += f[1];
        w[2] += f[2];
        w[3] += r[1] * f[2] - r[2] * f[1];
        w[4] += r[2] * f[0] - r[0] * f[2];
        w[5] += r[0] * f[1] - r[1] * f[0];
    }
    Ok(expand_mirrors(w, deck.symmetry))
}
