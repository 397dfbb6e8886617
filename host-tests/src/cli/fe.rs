//! `needle fe ...`: the FE campaign commands.
use clap::Subcommand;
use std::process::ExitCode;

/// `needle fe` subcommands.
#[derive(Subcommand)]
pub enum FeCommand {
    /// Run the FE campaign (in progress).
    Run,
}

/// Run an `fe` subcommand.
///
/// # Errors
/// Any failure, with its context.
pub fn run(_c: FeCommand) -> anyhow::Result<ExitCode> {
    anyhow::bail!("not implemented yet")
}
