//! The `needle` command line: one module per command group.

pub mod eval_batch;
pub mod explore;
pub mod fe;
pub mod firmware;
pub mod fit;
pub mod fixed;
pub mod model;
pub mod plot;
