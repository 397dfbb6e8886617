//! The FE campaign: material check, mesh, the engines behind the `Backend` trait
//! (`ccx/`: deck writer, runner, result parser, reduction of nodal reactions to the needle
//! wrench; `febio/`), and the campaign driver (report, progress, launchers). The set it
//! writes (spec, manifest, result and partial-record formats) is `needle-set`'s,
//! re-exported here under its old paths for the engine's own code.
#![forbid(unsafe_code)]

pub mod backend;
pub mod campaign;
pub mod ccx;
pub mod deep;
pub mod engines;
pub mod family;
pub mod febio;
pub mod launcher;
pub mod material;
pub mod mesh;
pub mod pose_rows;
pub mod process;
mod progress_bar;
pub mod report;
pub mod resume;
pub mod verify;
pub mod visco;

// The set (needle-set) under the paths the engine code has always used.
pub use needle_set::{failures, manifest, partial, read_count, results, results_error, set_folder, spec, versions, wrench};
