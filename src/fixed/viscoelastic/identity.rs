//! The fixed-point insertion's filter without the `viscoelastic` feature: the identity,
//! with the API of [`QlvCoefficients`](super::QlvCoefficients) and
//! [`QlvState`](super::QlvState) that [`crate::fixed::insertion`] uses. Zero-sized: an
//! elastic build carries no filter code or state (flash). A stack with terms is refused
//! ([`Stack::from_f32`](crate::fixed::insertion::Stack::from_f32)).

use needle_contract::COMPONENT_COUNT;

/// Coefficients of the identity: there are none.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct QlvCoefficients;

impl QlvCoefficients {
    /// No terms.
    pub const NONE: Self = Self;
}

/// The identity's state: none.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct QlvState;

impl QlvState {
    /// At rest.
    pub const REST: Self = Self;

    /// The input.
    #[inline]
    pub fn step(&mut self, _coefficients: &QlvCoefficients, elastic_q16: [i64; COMPONENT_COUNT]) -> [i64; COMPONENT_COUNT] {
        elastic_q16
    }

    /// Nothing to hold.
    #[inline]
    pub fn hold(&mut self, _coefficients: &QlvCoefficients) {}

    /// Nothing to reset.
    #[inline]
    pub fn reset(&mut self) {}
}
