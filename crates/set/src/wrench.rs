//! The wrench on the whole needle from the wrench on the modelled part, whatever the
//! engine (CalculiX's reduction of the nodal reactions: `ccx::reactions`).
//!
//! Half and quarter models are expanded to the whole block with the mirror symmetries
//! (coeffs/README.md): plane z = 0 doubles Fx, Fy, Mz and zeroes Fz, Mx, My; plane x = 0
//! doubles Fy, Fz, Mx and zeroes Fx, My, Mz.

use crate::spec::Symmetry;
use needle_contract::COMPONENT_COUNT;

/// The wrench on the whole needle from the wrench `w` on the modelled part of a mirror
/// model: plane z = 0 doubles Fx, Fy, Mz and zeroes Fz, Mx, My; plane x = 0 doubles Fy,
/// Fz, Mx and zeroes Fx, My, Mz (the components odd under a mirror vanish exactly).
pub fn expand_mirrors(mut w: [f64; COMPONENT_COUNT], sym: Symmetry) -> [f64; COMPONENT_COUNT] {
    let mut k = [1.0f64; COMPONENT_COUNT];
    if sym.plane_z {
        for (i, f) in [2.0, 2.0, 0.0, 0.0, 0.0, 2.0].iter().enumerate() {
            k[i] *= f;
        }
    }
    if sym.plane_x {
        for (i, f) in [0.0, 2.0, 2.0, 2.0, 0.0, 0.0].iter().enumerate() {
            k[i] *= f;
        }
    }
    for (v, f) in w.iter_mut().zip(k) {
        *v *= f;
    }
    w
}
