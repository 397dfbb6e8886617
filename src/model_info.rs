//! Identity, domain and tables of the model compiled into this build.
//!
//! Everything here comes from the coefficient set selected at build time
//! (`NEEDLE_COEFFS`, default `coeffs/default`), through `build.rs` and `needle-codegen`.

pub use crate::float::tables::{BASELINE, DEPTH_MAX_MM, DEVIATION, FE_SHA256, FITTED, FORMAT, SET, THETA_MAX_DEG, X_MAX_MM, Z_MAX_MM};
use needle_contract::COMPONENT_COUNT;

pub use crate::float::cross::{COUPLED, CROSS_SCALES, CROSS_TERMS, CV_RMS_PCT, CV_SCALE, TRAINING_RUNS};

/// `ODD[k][c]`: wrench component `c` (fx, fy, fz, mx, my, mz) changes sign under the
/// mirror of sweep `k` (x, z, theta_x, theta_z). Fixed by the geometry (coeffs/README.md);
/// every model file is checked against it at build time.
pub const ODD: [[bool; COMPONENT_COUNT]; 4] = crate::float::eval::ODD;

/// Absolute path of the set folder this build was generated from (on the build machine).
pub const SET_DIR: &str = env!("NEEDLE_SET_DIR");

/// The C header `needle_coeffs.h` generated with these tables: the same coefficients as
/// `static const float` with their bits, the domain, the normalisation constants and the
/// status bits. `needle header --out DIR` writes it out.
pub const C_HEADER: &str = include_str!(concat!(env!("OUT_DIR"), "/needle_coeffs.h"));

/// The generated Rust source of the tables compiled into this build (for audits and the
/// regeneration test).
pub const TABLES_RS: &str = include_str!(concat!(env!("OUT_DIR"), "/tables_f32.rs"));

/// The generated Rust source of the coupled form's cross terms compiled into this build
/// (for audits and the regeneration test).
pub const CROSS_RS: &str = include_str!(concat!(env!("OUT_DIR"), "/cross_f32.rs"));

/// Balls of the compiled-in unsolved region (every failed pose of the set's FE campaign
/// and its mirror images, `unsolved.toml`); 0: the set has no region and no pose is
/// flagged [`Status::FE_UNSOLVED`](crate::Status::FE_UNSOLVED).
pub const UNSOLVED_BALLS: usize = crate::unsolved::tables::COUNT;

/// The generated Rust source of the unsolved region compiled into this build (for audits
/// and the regeneration test).
pub const UNSOLVED_RS: &str = include_str!(concat!(env!("OUT_DIR"), "/unsolved.rs"));

/// The generated Rust source of the tissue stacks compiled into this build (the set's
/// `tissue/*.toml`; for the check that a set's files are the compiled-in ones).
pub const TISSUE_RS: &str = include_str!(concat!(env!("OUT_DIR"), "/tissue_stacks.rs"));
