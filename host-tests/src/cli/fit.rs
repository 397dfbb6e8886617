//! `needle fit`, `needle validate`: fit the model, compare it with FE.
use clap::Args;
use std::process::ExitCode;

/// Arguments of `needle fit` (in progress).
#[derive(Args)]
pub struct FitArgs {}
/// Arguments of `needle validate` (in progress).
#[derive(Args)]
pub struct ValidateArgs {}

/// `needle fit`.
///
/// # Errors
/// Any failure, with its context.
pub fn fit(_a: FitArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("not implemented yet")
}
/// `needle validate`.
///
/// # Errors
/// Any failure, with its context.
pub fn validate(_a: ValidateArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("not implemented yet")
}
