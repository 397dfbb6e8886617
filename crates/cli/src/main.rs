//! `needle`: the needle-haptics command-line tool (FE campaign, fitter, model queries).

use clap::{Parser, Subcommand};
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "needle", version, about = "needle-haptics: FE campaign, fitter and model tool")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// FE campaign (FEBio or CalculiX): run, verify.
    #[command(subcommand)]
    Fe(needle_cli::fe::FeCommand),
    /// Fit the paper model to a set's FE sweeps and write model.toml and golden vectors.
    Fit(needle_cli::fit::FitArgs),
    /// Evaluate the wrench at one pose with the library (the firmware's code).
    Eval(needle_cli::model::EvalArgs),
    /// Fit a tissue stack (<set>/tissue/<name>.toml) to a measured axial force against needle position.
    Calibrate(needle_cli::calibrate::CalibrateArgs),
    /// Compare the model with the FE runs it was not fitted on.
    Validate(needle_cli::fit::ValidateArgs),
    /// Serve the model explorer (the firmware's evaluator compiled to wasm) on a local port.
    Explore(needle_cli::explore::ExploreArgs),
    /// The set's figures as SVG (the paper's Figs 4, 6, 7, 8, parity, FE verification).
    Plot(needle_cli::plot::PlotArgs),
    /// The fixed-point evaluator's error against f64 on a grid and random poses, beside
    /// its generated bound.
    FixedError(needle_cli::fixed::FixedErrorArgs),
    /// Copy the generated C header out for C users.
    Header(needle_cli::model::HeaderArgs),
    /// The library on Cortex-M under QEMU: size, bench, golden, check.
    #[command(subcommand)]
    Firmware(needle_cli::firmware::FirmwareCommand),
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
    if !matches!(cli.command, Command::Fe(_) | Command::Explore(_)) {
        default_sigpipe();
    }
    let result = match cli.command {
        Command::Fe(c) => needle_cli::fe::run(c),
        Command::Fit(a) => needle_cli::fit::fit(a),
        Command::Eval(a) => needle_cli::model::eval(a),
        Command::Validate(a) => needle_cli::fit::validate(a),
        Command::Calibrate(a) => needle_cli::calibrate::calibrate(a),
        Command::Explore(a) => needle_cli::explore::explore(a),
        Command::Plot(a) => needle_cli::plot::plot(a),
        Command::Header(a) => needle_cli::model::header(a),
        Command::FixedError(a) => needle_cli::fixed::fixed_error(a),
        Command::Firmware(c) => needle_cli::firmware::run(c),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}
