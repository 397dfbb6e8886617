//! `needle eval`: the wrench of the library's compiled-in model at one pose or at every
//! row of a pose file.
//!
//! It uses `needle-haptics` itself (the code and tables the firmware runs), not a host
//! re-implementation. The library has one coefficient set compiled in (chosen by
//! `NEEDLE_COEFFS` at build time); `needle eval --set DIR` checks that `DIR` is that set.
pub mod batch;
pub mod insertion;
pub mod json;
pub mod stream;

use crate::compiled_set::check_compiled_set;
use anyhow::{bail, Context};
use clap::Args;
use json::{eval_json, form_name, names, to_json};
use needle_haptics::{model_info, wrench, Pose};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Arguments of `needle eval`.
#[derive(Args, Debug)]
pub struct EvalArgs {
    /// The coefficient set folder (e.g. coeffs/default); must be the set this build has
    /// compiled in (rebuild with NEEDLE_COEFFS=DIR to use another).
    #[arg(long, value_name = "DIR")]
    pub set: PathBuf,
    /// x of the insertion point on the top surface, mm.
    #[arg(long, allow_hyphen_values = true, required_unless_present = "poses", conflicts_with = "poses")]
    pub x_mm: Option<f32>,
    /// z of the insertion point on the top surface, mm.
    #[arg(long, allow_hyphen_values = true, required_unless_present = "poses", conflicts_with = "poses")]
    pub z_mm: Option<f32>,
    /// Tilt about x away from vertical, degrees.
    #[arg(long, allow_hyphen_values = true, required_unless_present = "poses", conflicts_with = "poses")]
    pub theta_x_deg: Option<f32>,
    /// Tilt about z away from vertical, degrees.
    #[arg(long, allow_hyphen_values = true, required_unless_present = "poses", conflicts_with = "poses")]
    pub theta_z_deg: Option<f32>,
    /// Insertion depth along the needle axis, mm.
    #[arg(long, allow_hyphen_values = true, required_unless_present = "poses", conflicts_with = "poses")]
    pub depth_mm: Option<f32>,
    /// Evaluate every row of this CSV file (columns x_mm, z_mm, theta_x_deg,
    /// theta_z_deg, depth_mm) instead of one pose; one output row per input row.
    #[arg(long, value_name = "FILE.csv")]
    pub poses: Option<PathBuf>,
    /// With --poses: a scripted insertion through this tissue stack, a compiled-in name
    /// (e.g. liver) or a tissue file (e.g. my_tissue.toml, loaded at run time and checked
    /// as the build checks one): the file needs a time_s column, one row per tick; one
    /// wrench row per tick.
    #[arg(long, value_name = "STACK", requires = "poses", conflicts_with = "json")]
    pub insertion: Option<String>,
    /// With --insertion: these Prony terms on every layer of the stack in place of its
    /// own, "g:tau_s" pairs comma-separated (e.g. "0.6:0.5, 0.4:5"; at most 3, g >= 0,
    /// tau_s > 0 s, the long-term normalisation of coeffs/README.md): the scripted
    /// insertion with the viscoelastic filter (of the shipped stacks only the epidural
    /// skin has terms of its own).
    #[arg(long, value_name = "G:TAU_S,...", requires = "insertion", allow_hyphen_values = true)]
    pub prony: Option<String>,
    /// With --poses: write the rows to this file instead of standard output.
    #[arg(long, value_name = "FILE", requires = "poses")]
    pub out: Option<PathBuf>,
    /// Print JSON (one object; with --poses an array) instead of the table (CSV).
    #[arg(long)]
    pub json: bool,
}

/// `needle eval`: the wrench at one pose from the library. Exit code 0 for a wrench
/// (in the domain or saturated), 1 when the status is an error (NaN/infinite input).
///
/// # Errors
/// `--set` is not the set compiled into this build (see [`check_compiled_set`]).
pub fn run(a: EvalArgs) -> anyhow::Result<ExitCode> {
    check_compiled_set(&a.set)?;
    if let (Some(out), None) = (&a.out, &a.poses) {
        bail!(
            "--out {} writes the rows of --poses FILE.csv; a single pose is printed (redirect standard output to keep it)",
            out.display()
        );
    }
    if let (Some(file), Some(stack)) = (&a.poses, &a.insertion) {
        insertion::eval_script(file, stack, a.prony.as_deref(), a.out.as_deref())?;
        return Ok(ExitCode::SUCCESS);
    }
    if let Some(file) = &a.poses {
        return eval_file(file, a.out.as_deref(), a.json);
    }
    let (Some(x_mm), Some(z_mm), Some(theta_x_deg), Some(theta_z_deg), Some(depth_mm)) =
        (a.x_mm, a.z_mm, a.theta_x_deg, a.theta_z_deg, a.depth_mm)
    else {
        bail!("give the five pose values (--x-mm, --z-mm, --theta-x-deg, --theta-z-deg, --depth-mm) or --poses FILE.csv");
    };
    let pose = Pose { x_mm, z_mm, theta_x_deg, theta_z_deg, depth_mm };
    let e = wrench(&pose);
    if a.json {
        println!("{}", serde_json::to_string_pretty(&eval_json(&pose, &e))?);
    } else {
        println!("set {} ({}), f32 {} model", model_info::SET, model_info::SET_DIR, form_name());
        println!(
            "pose: x_mm = {} z_mm = {} theta_x_deg = {} theta_z_deg = {} depth_mm = {}",
            pose.x_mm, pose.z_mm, pose.theta_x_deg, pose.theta_z_deg, pose.depth_mm
        );
        println!("wrench on the needle, moments about the hub:");
        for ((name, unit), v) in names().zip(e.wrench.to_array()) {
            println!("  {name:<7} = {:>15} {unit:<5} ({:#010x})", format!("{v:?}"), v.to_bits());
        }
        let meaning = if e.status.is_error() {
            "error: no wrench"
        } else if e.status.saturated() {
            "saturated: the wrench of the pose clamped to the domain"
        } else {
            "in the domain"
        };
        let unsolved = if e.status.fe_unsolved() {
            "; FE_UNSOLVED: the pose lies where the set's FE campaign could not solve (unsolved.toml), the wrench is the model's extrapolation"
        } else {
            ""
        };
        println!("status  = {:#04x} ({}): {meaning}{unsolved}", e.status.bits(), e.status);
    }
    Ok(if e.status.is_error() { ExitCode::from(1) } else { ExitCode::SUCCESS })
}

/// `needle eval --poses FILE`: every row of the file (see [`batch`]). Exit
/// code 0; the rows with an error status carry it in their status column.
///
/// # Errors
/// The file cannot be read, has a bad header or bad rows (all listed, by line), or the
/// output cannot be written.
fn eval_file(file: &Path, out: Option<&Path>, json: bool) -> anyhow::Result<ExitCode> {
    use batch::{evaluate, parse_poses};
    if !json {
        // CSV: streamed, chunk by chunk (memory bounded), on every core
        let rows = stream::eval_csv(file, out)?;
        if let Some(path) = out {
            eprintln!("wrote {} ({rows} poses)", path.display());
        }
        return Ok(ExitCode::SUCCESS);
    }
    let text = std::fs::read_to_string(file).with_context(|| format!("{}: cannot read", file.display()))?;
    let poses = parse_poses(&text, file)?;
    let evals = evaluate(&poses);
    let body = serde_json::to_string_pretty(&to_json(&poses, &evals))? + "\n";
    match out {
        Some(path) => {
            needle_stdx::fs::write_atomic(path, body.as_bytes())?;
            eprintln!("wrote {} ({} poses)", path.display(), poses.len());
        }
        None => {
            use std::io::Write as _;
            std::io::stdout().lock().write_all(body.as_bytes()).context("writing to standard output")?;
        }
    }
    Ok(ExitCode::SUCCESS)
}
