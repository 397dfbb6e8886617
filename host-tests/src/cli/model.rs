//! `needle eval`, `needle header`: query the library's model.
use clap::Args;
use std::process::ExitCode;

/// Arguments of `needle eval` (in progress).
#[derive(Args)]
pub struct EvalArgs {}
/// Arguments of `needle header` (in progress).
#[derive(Args)]
pub struct HeaderArgs {}

/// `needle eval`.
///
/// # Errors
/// Any failure, with its context.
pub fn eval(_a: EvalArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("not implemented yet")
}
/// `needle header`.
///
/// # Errors
/// Any failure, with its context.
pub fn header(_a: HeaderArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("not implemented yet")
}
