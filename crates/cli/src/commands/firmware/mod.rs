//! `needle firmware ...`: the library on Cortex-M under QEMU (examples/ firmware), one
//! module per subcommand; [`goals`] holds the goals `size` and `bench` print.
pub mod bench;
pub mod check;
pub mod goals;
pub mod golden;
pub mod size;

use clap::{Args, Subcommand};
use needle_firmware_host::{self as firmware};
use std::path::PathBuf;
use std::process::ExitCode;

/// `needle firmware` subcommands.
#[derive(Subcommand)]
pub enum FirmwareCommand {
    /// Flash and RAM of the model per core and evaluator, with the goals.
    #[command(after_help = "From arm-none-eabi-size and -nm on the no_panic (f32) and no_panic_fixed example ELFs \
(release): evaluator code, tables, compiler runtime, static RAM; goals: model flash <= 8 KiB (coupled form 16 KiB), \
no static RAM.")]
    Size(FirmwareArgs),
    /// Instructions per wrench and stack per core, f32 and fixed point, with the goals.
    #[command(after_help = "The bench example under QEMU -icount shift=0 (SysTick counts instructions). Goals of the \
set's model form: paper f32 <= 900 instructions on the M4F, fixed point <= 10,000 on the M0; coupled 1,500 and \
15,000; stack <= 512 B.")]
    Bench(FirmwareArgs),
    /// Run the golden vectors on each core under QEMU; exit 1 when a bit differs.
    #[command(after_help = "The golden example's output against the set's golden-f32.csv, golden-fixed.csv, \
golden-stiffness-f32.csv and golden-stiffness-fixed.csv, bit for bit.")]
    Golden(FirmwareArgs),
    /// Build the library for each core with every feature combination, and the no-panic proofs.
    #[command(after_help = "The no_panic and no_panic_fixed examples link only if the evaluators have no panic path.")]
    Check(FirmwareArgs),
}

/// Arguments common to the `needle firmware` commands.
#[derive(Args, Debug)]
pub struct FirmwareArgs {
    /// Coefficient set to build the firmware with (NEEDLE_COEFFS of the nested build);
    /// default: the set compiled into this `needle`.
    #[arg(long, value_name = "DIR")]
    pub set: Option<PathBuf>,
    /// Core to use: m4f (thumbv7em-none-eabihf), m3 (thumbv7m-none-eabi) or m0
    /// (thumbv6m-none-eabi); repeat for several; default all three.
    #[arg(long = "core", value_name = "CORE")]
    pub cores: Vec<String>,
}

impl FirmwareArgs {
    /// The set of `--set`, or the one compiled into this `needle`.
    pub fn set(&self) -> PathBuf {
        self.set.clone().unwrap_or_else(firmware::compiled_set)
    }
}

/// Run a `firmware` subcommand.
///
/// # Errors
/// A build, QEMU run or binutils call failed, or the set is not fitted.
pub fn run(c: FirmwareCommand) -> anyhow::Result<ExitCode> {
    match c {
        FirmwareCommand::Size(a) => size::run(&a),
        FirmwareCommand::Bench(a) => bench::run(&a),
        FirmwareCommand::Golden(a) => golden::run(&a),
        FirmwareCommand::Check(a) => check::run(&a),
    }
}

/// `met` or `MISSED`.
pub fn goal(ok: bool) -> &'static str {
    if ok {
        "met"
    } else {
        "MISSED"
    }
}

/// The first line of a report: what, the set, its fe_sha256.
pub fn banner(what: &str, set: &std::path::Path) -> anyhow::Result<()> {
    let model = needle_codegen::parse_model(&set.join(needle_codegen::MODEL_FILE)).map_err(anyhow::Error::new)?;
    println!("{what}: set {:?} ({}), fe_sha256 {}", model.set, set.display(), model.fe_sha256);
    Ok(())
}
