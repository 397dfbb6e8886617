//! `needle`: the needle-haptics command-line tool (FE campaign, fitter, model queries).

use clap::{Parser, Subcommand};
use needle_cli::commands;
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "needle", version, about = "needle-haptics: FE campaign, model fit, evaluation and firmware checks")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
// The variants' doc comments are the --help text, written for the terminal: <set> and
// [fit] are placeholders and campaign.toml sections there, not HTML or links.
#[allow(rustdoc::invalid_html_tags, rustdoc::broken_intra_doc_links)]
enum Command {
    /// FE campaign of a set (FEBio or CalculiX): run, verify, status.
    #[command(subcommand)]
    Fe(needle_cli::commands::fe::FeCommand),
    /// Fit the set's model in its [fit] form (paper or coupled); write model.toml and golden vectors.
    #[command(after_help = "The form is campaign.toml's [fit] form: paper (the paper's single-axis sweeps, superposed) \
or coupled (those terms plus cross terms, fitted together on the centre, sweep and training runs, sized per \
component by cross-validation). Writes model.toml and the four golden files all or nothing; refuses stale FE runs.")]
    Fit(needle_cli::commands::fit::FitArgs),
    /// The wrench at one pose, or at every row of a CSV, from the library (the firmware's code).
    Eval(needle_cli::commands::eval::EvalArgs),
    /// Write the golden insertion paths as scripts for `needle eval --poses FILE --insertion STACK`.
    InsertionPaths(needle_cli::commands::insertion_paths::InsertionPathsArgs),
    /// Fit a tissue stack (<set>/tissue/<name>.toml) to a measured force against needle position.
    Calibrate(needle_cli::commands::calibrate::CalibrateArgs),
    /// Drive a tissue stack with a measured trial (time, position): measured and model force per row.
    Replay(needle_cli::commands::replay::ReplayArgs),
    /// Derive a tissue stack from a published model's force polynomials per layer (no measured curve).
    CalibratePublished(needle_cli::commands::calibrate_published::CalibratePublishedArgs),
    /// Compare the model with the FE runs it was not fitted on; exit 1 when a goal is missed.
    Validate(needle_cli::commands::validate::ValidateArgs),
    /// Serve the model explorer (the library compiled to wasm) to a browser on a local port.
    Explore(needle_cli::commands::explore::ExploreArgs),
    /// Draw the set's figures as SVG (Figs 4, 6, 7, 8, parity, FE verification, the material family).
    Plot(needle_cli::commands::plot::PlotArgs),
    /// The fixed-point evaluator's largest error against f64 on a grid and random poses, beside its bound.
    FixedError(needle_cli::commands::fixed_error::FixedErrorArgs),
    /// Write the C headers: needle.h (the C API) and needle_coeffs.h (the model's tables).
    Header(needle_cli::commands::header::HeaderArgs),
    /// Tissue stack files: draw a plausible tissue within a stack's spread over its trials.
    #[command(subcommand)]
    Stack(needle_cli::commands::stack::StackCommand),
    /// The library on Cortex-M under QEMU: size, bench, golden, check.
    #[command(subcommand)]
    Firmware(needle_cli::commands::firmware::FirmwareCommand),
}

/// SIGPIPE to its default action: a reader that closes the pipe early (`| head`) ends
/// this process quietly, as it ends `cat` or `grep`. The Rust runtime ignores SIGPIPE,
/// which turns every later `println!` into a panic (exit 101). Not for the long-running
/// commands (`fe`, `explore`): a campaign or a server keeps going when its log reader
/// goes away.
#[cfg(unix)]
fn default_sigpipe() {
    // SAFETY: called first in main, before any thread is started; SIG_DFL is a valid
    // disposition for SIGPIPE.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

#[cfg(not(unix))]
fn default_sigpipe() {}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // the library crates print nothing themselves: their text goes to the terminal here
    needle_cli::output::terminal::install();
    if !matches!(cli.command, Command::Fe(_) | Command::Explore(_)) {
        default_sigpipe();
    }
    let result = match cli.command {
        Command::Fe(c) => commands::fe::run(c),
        Command::Fit(a) => commands::fit::run(a),
        Command::Eval(a) => commands::eval::run(a),
        Command::Validate(a) => commands::validate::run(a),
        Command::InsertionPaths(a) => commands::insertion_paths::run(a),
        Command::Calibrate(a) => commands::calibrate::run(a),
        Command::CalibratePublished(a) => commands::calibrate_published::run(a),
        Command::Replay(a) => commands::replay::run(a),
        Command::Explore(a) => commands::explore::run(a),
        Command::Plot(a) => commands::plot::run(a),
        Command::Header(a) => commands::header::run(a),
        Command::FixedError(a) => commands::fixed_error::run(a),
        Command::Stack(c) => commands::stack::run(c),
        Command::Firmware(c) => commands::firmware::run(c),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}
