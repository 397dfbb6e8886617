//! The `needle` command line: [`commands`] has one module per command, named as the
//! command (`needle calibrate-published` is [`commands::calibrate_published`]); the
//! helpers several commands share are [`compiled_set`] and [`output`].
#![forbid(unsafe_code)]

pub mod commands;
pub mod compiled_set;
pub mod output;

// The former paths of the modules that host-tests (`benches/eval_batch.rs`,
// `tests/fixed_error.rs`) import; to go when those use the paths above.
#[doc(hidden)]
pub use commands::eval::batch as eval_batch;
#[doc(hidden)]
pub use commands::eval::stream as eval_stream;
#[doc(hidden)]
pub use commands::fixed_error::measure as fixed_error;
