//! The `needle` command line: one module per command group.
#![forbid(unsafe_code)]

pub mod calibrate;
pub mod calibrate_figure;
pub mod calibrate_published;
pub mod eval_batch;
pub mod eval_insertion;
pub mod eval_stream;
pub mod explore;
pub mod fe;
pub mod fe_qlv;
pub mod fe_qlv_figure;
pub mod firmware;
pub mod fit;
pub mod fixed;
pub mod fixed_error;
pub mod float_text;
pub mod insertion_paths;
pub mod model;
pub mod plot;
pub mod qlv_filtered;
