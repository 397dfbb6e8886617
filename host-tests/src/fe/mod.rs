//! The FE campaign: spec, material check, mesh and deck writer, the ccx runner and
//! result parser, the reduction of nodal reactions to the needle wrench, and the campaign
//! driver (backend, manifest, report, progress).

pub mod spec;
pub mod material;
pub mod mesh;
pub mod deck;
pub mod dat;
pub mod wrench;
pub mod process;
pub mod ccx;
pub mod febio;
pub mod results;
pub mod backend;
pub mod manifest;
pub mod report;
mod progress;
pub mod campaign;
pub mod launcher;
pub mod verify;
