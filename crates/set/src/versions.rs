//! The versions of the two input generators, part of every run's spec hash
//! ([`Campaign::run_hash`](crate::spec::Campaign::run_hash)): bump one when its
//! generator's output changes, and the campaign reruns that engine's poses. Defined here,
//! apart from the generators, so that the spec does not depend on them.

/// Version of the CalculiX mesh and deck generator (`needle_fe::ccx::deck`).
///
/// History: 1, tissue surface as contact slave; 2, needle surface as contact slave (v1 lost
/// contact when the wedge's edge landed between tissue nodes, the theta_z sweep).
pub const CCX_DECK: u32 = 2;

/// Version of the FEBio input generator (`needle_fe::febio::feb`).
pub const FEBIO_INPUT: u32 = 1;
