//! The FE campaign: spec, material check, mesh, the engines behind the `Backend` trait
//! (`ccx/`: deck writer, runner, result parser, reduction of nodal reactions to the needle
//! wrench; `febio/`), and the campaign driver (manifest, report, progress, launchers).
#![forbid(unsafe_code)]

pub mod backend;
pub mod campaign;
pub mod ccx;
pub mod deep;
pub mod engines;
pub mod family;
pub mod febio;
pub mod launcher;
pub mod manifest;
pub mod material;
pub mod mesh;
pub mod mesh_summary;
pub mod partial;
pub mod process;
mod progress;
pub mod read_count;
pub mod report;
pub mod results;
pub mod results_error;
pub mod resume;
pub mod set_folder;
pub mod spec;
pub mod verify;
pub mod versions;
pub mod visco;
pub mod wrench;
