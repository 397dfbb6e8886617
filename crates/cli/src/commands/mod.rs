//! One module per `needle` command, named as the command with `-` as `_` (a file, or a
//! folder with its helpers). Each command's module has one entry,
//! `pub fn run(args) -> anyhow::Result<ExitCode>`, and its clap arguments beside it;
//! a command group (`fe`, `firmware`, `stack`) is a folder with one module per subcommand and a
//! `run` that dispatches. `tests/cli_layout.rs` checks this against `needle --help`.
pub mod calibrate;
pub mod calibrate_published;
pub mod eval;
pub mod explore;
pub mod fe;
pub mod firmware;
pub mod fit;
pub mod fixed_error;
pub mod header;
pub mod insertion_paths;
pub mod plot;
pub mod replay;
pub mod stack;
pub mod validate;
