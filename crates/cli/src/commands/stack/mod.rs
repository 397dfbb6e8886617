//! `needle stack ...`: tissue stack files, one module per subcommand.
pub mod sample;

use clap::Subcommand;
use std::process::ExitCode;

/// The `needle stack` subcommands.
#[derive(Subcommand)]
// The doc comments and after_help are the --help text: <name> is a placeholder there.
#[allow(rustdoc::invalid_html_tags)]
pub enum StackCommand {
    /// Draw a plausible tissue within the spread over the trials a stack was fitted on.
    #[command(after_help = "The spread is the file `needle calibrate --trials` writes beside the stack \
(<name>.spread.csv: per layer, each value fitted per trial, its mean and standard deviation; coeffs/README.md, \
\"Spread over the trials\"). Each value is moved by its standard deviation times a standard normal draw held \
within 2 standard deviations, independently; the track stiffness follows the scale, the static friction the \
Coulomb level. The same seed gives the same file.")]
    Sample(sample::SampleArgs),
}

/// Runs `needle stack ...`.
///
/// # Errors
/// As the subcommand's `run`.
pub fn run(c: StackCommand) -> anyhow::Result<ExitCode> {
    match c {
        StackCommand::Sample(a) => sample::run(a),
    }
}
