//! The FE campaign: spec, material check, mesh and deck writer, the ccx runner and
//! result parser, and the reduction of nodal reactions to the needle wrench.

pub mod spec;
pub mod material;
pub mod mesh;
pub mod deck;
pub mod dat;
pub mod wrench;
pub mod ccx;
pub mod results;
pub mod campaign;
pub mod verify;
