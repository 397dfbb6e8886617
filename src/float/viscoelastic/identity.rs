//! The insertion's filter without the `viscoelastic` feature: the identity, with the
//! API of [`QlvCoefficients`](super::QlvCoefficients) and [`QlvState`](super::QlvState)
//! that [`crate::float::insertion`] uses. Zero-sized: an elastic build carries no filter code
//! or state (flash; `docs/firmware.md`, "Features"). Terms are refused, not ignored.

use needle_contract::COMPONENT_COUNT;

use super::PronyTerms;

/// Coefficients of the identity: there are none.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct QlvCoefficients;

/// Why the identity refused: the layer has Prony terms and the library was built
/// without the `viscoelastic` feature.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NeedsFeature;

impl QlvCoefficients {
    /// No terms.
    pub const NONE: Self = Self;

    /// Whether there are terms: never.
    #[must_use]
    pub const fn is_active(&self) -> bool {
        false
    }

    /// The identity for terms without any term.
    ///
    /// # Errors
    /// [`NeedsFeature`] for any term.
    pub fn new(terms: &PronyTerms, _tick: f32) -> Result<Self, NeedsFeature> {
        if terms.as_slice().is_empty() {
            Ok(Self)
        } else {
            Err(NeedsFeature)
        }
    }

    /// `1`: the identity renders its input's stiffness.
    #[must_use]
    pub fn effective_stiffness_ratio(&self) -> f32 {
        1.0
    }
}

/// The identity's state: none.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct QlvState;

impl QlvState {
    /// At rest.
    pub const REST: Self = Self;

    /// The input.
    #[inline]
    pub fn step(&mut self, _coefficients: &QlvCoefficients, elastic: [f32; COMPONENT_COUNT]) -> [f32; COMPONENT_COUNT] {
        elastic
    }

    /// Nothing to hold.
    #[inline]
    pub fn hold(&mut self, _coefficients: &QlvCoefficients) {}

    /// Nothing to reset.
    #[inline]
    pub fn reset(&mut self) {}
}
