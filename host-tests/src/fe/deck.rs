//! CalculiX deck writer (in progress).

/// Version of the mesh and deck generator; part of every run's spec hash, so that a
/// change of the generator reruns the campaign.
pub const GENERATOR_VERSION: u32 = 1;
