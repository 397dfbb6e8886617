//! [`Evaluation`]: a wrench and the status of how it was obtained.
use crate::{Status, Wrench};

/// The result of evaluating a model at a pose.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Evaluation {
    /// The reaction wrench (N, N·mm); zero when `status.is_error()`.
    pub wrench: Wrench,
    /// What the evaluation had to do: [`Status::OK`], saturation flags, or an error.
    pub status: Status,
}
