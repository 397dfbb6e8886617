//! [`Stack`] and [`Layer`]: the tissue a needle passes, from the surface down, as
//! compiled in from the set's `tissue/*.toml` (format: `coeffs/README.md`, "Tissue
//! stacks") into [`stacks`].

#[cfg(feature = "shaft-presliding")]
pub use super::presliding::Presliding;
pub use super::softening::Softening;
pub use crate::float::family::FamilyMember;
use crate::float::viscoelastic::{PronyTerm, PronyTerms};

/// Shaft friction per mm of shaft in a layer: Karnopp's static and Coulomb levels, a
/// viscous term and the stick band (Okamura, Simone and O'Leary 2004, modified: inside
/// the band the force rises linearly from zero, so it never acts on a needle at rest).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Karnopp {
    /// Static level, reached at the edge of the stick band, N/mm.
    pub static_n_per_mm: f32,
    /// Coulomb (sliding) level above the band, N/mm.
    pub coulomb_n_per_mm: f32,
    /// Viscous term above the band, N per (mm/s) per mm.
    pub viscous_n_s_per_mm2: f32,
    /// Half width of the stick band of axial speed, mm/s (> 0).
    pub stick_band_mm_per_s: f32,
}

impl Karnopp {
    /// Friction per mm of shaft at axial speed `v_mm_per_s`, N/mm: odd in the speed, of
    /// the speed's sign (the force on the needle is its negative along the motion):
    /// `static * v / band` inside the band, `sign(v) * (coulomb + viscous * |v|)` above.
    #[inline]
    #[must_use]
    pub fn per_mm(&self, v_mm_per_s: f32) -> f32 {
        let speed = libm::fabsf(v_mm_per_s);
        let band = self.stick_band_mm_per_s;
        let level = if speed < band {
            // band > 0 (checked at build time and by `Insertion::set_scales` callers'
            // stacks); a zero band never reaches this branch (speed < 0 is impossible)
            self.static_n_per_mm * (speed / band)
        } else {
            self.coulomb_n_per_mm + self.viscous_n_s_per_mm2 * speed
        };
        libm::copysignf(level, v_mm_per_s)
    }
}

/// One layer, from its upper boundary down.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Layer {
    /// Thickness along the block's vertical, mm (the last layer extends below it).
    pub thickness_mm: f32,
    /// Stiffness scale s against the set's FE tissue: the upper boundary deflects with s
    /// times the FE surrogate's wrench.
    pub stiffness_scale: f32,
    /// Axial force at which the upper boundary is punctured, N.
    pub puncture_force_n: f32,
    /// Axial force at the tip while it cuts through the layer, N.
    pub cutting_force_n: f32,
    /// Shaft friction in the layer.
    pub friction: Karnopp,
    /// Lateral stiffness of the cut track per mm of shaft in the layer, N/mm per mm.
    pub track_stiffness_n_per_mm2: f32,
    /// The relaxation function of the layer's boundary deflection (quasi-linear
    /// viscoelasticity, [`viscoelastic`](crate::float::viscoelastic)); [`PronyTerms::NONE`]:
    /// elastic.
    pub prony: PronyTerms,
    /// The material family's member the boundary deflects as (the FE surrogate times the
    /// family's ratio `g(d, w)`, [`crate::float::family`]); [`FamilyMember::PAPER`]: the
    /// paper's tissue.
    pub family: FamilyMember,
    /// The boundary's pre-puncture softening; [`Softening::NONE`]: none.
    pub softening: Softening,
    /// The shaft's presliding (stuck) friction and held cutting in the layer
    /// ([`Presliding::NONE`]: the Karnopp friction, zero at rest); only with the
    /// `shaft-presliding` feature (a default build's layers carry none: flash).
    #[cfg(feature = "shaft-presliding")]
    pub presliding: Presliding,
}

/// A stack of layers and the needle its values belong to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stack<'a> {
    /// The stack's name (its file's stem).
    pub name: &'a str,
    /// Diameter of the needle the values belong to, mm: the FE surrogate is carried over
    /// from the set's needle ([`FE_NEEDLE_DIAMETER_MM`]) by geometric similarity.
    pub needle_diameter_mm: f32,
    /// The layers from the surface down (1 to [`MAX_LAYERS`]).
    pub layers: &'a [Layer],
}

/// Most layers a stack has (the insertion state is sized for it).
pub const MAX_LAYERS: usize = needle_contract::MAX_TISSUE_LAYERS;

/// The stacks of the compiled-in set, generated from its `tissue/*.toml`, and the FE
/// needle they are scaled from.
pub mod stacks {
    // `panic!` only in constant evaluation (a refused Prony set is a compile error)
    #![allow(clippy::unreadable_literal, clippy::excessive_precision, clippy::panic)]
    #[cfg(feature = "shaft-presliding")]
    #[allow(unused_imports)] // a set without presliding stacks uses none
    use super::Presliding;
    #[allow(unused_imports)] // a set without tissue files uses none
    use super::{FamilyMember, Karnopp, Layer, PronyTerm, PronyTerms, Softening, Stack};
    include!(concat!(env!("OUT_DIR"), "/tissue_stacks.rs"));

    /// The compiled-in stack named `name` (its file's stem), `None` when [`ALL`] has no
    /// such stack (the fixed-point twin: `fixed::insertion::stacks::by_name`).
    #[must_use]
    pub fn by_name(name: &str) -> Option<&'static Stack<'static>> {
        ALL.iter().find(|s| s.name == name)
    }

    /// Whether no layer of `stacks` has a Prony term: a build without the `viscoelastic`
    /// feature holds only such stacks (a stack with terms is compiled with the feature
    /// alone, and `ALL` then lists the others), checked at compile time.
    #[cfg(not(feature = "viscoelastic"))]
    #[allow(clippy::indexing_slicing)] // const evaluation only: out of range is a compile error
    const fn elastic(stacks: &[Stack<'static>]) -> bool {
        let mut i = 0;
        while i < stacks.len() {
            let layers = stacks[i].layers;
            let mut j = 0;
            while j < layers.len() {
                if layers[j].prony.as_array().1 > 0 {
                    return false;
                }
                j += 1;
            }
            i += 1;
        }
        true
    }

    #[cfg(not(feature = "viscoelastic"))]
    const _: () = assert!(
        elastic(&ALL),
        "the elastic build's ALL holds a stack with Prony terms (needle-codegen gates such stacks behind the `viscoelastic` feature)"
    );
}

pub use stacks::{FE_NEEDLE_DIAMETER_MM, HUB_FROM_TIP_MM};
