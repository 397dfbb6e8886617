//! `needle eval`, `needle header`: query the library's compiled-in model.
//!
//! Both use `needle-haptics` itself (the code and tables the firmware runs), not a host
//! re-implementation. The library has one coefficient set compiled in (chosen by
//! `NEEDLE_COEFFS` at build time); `needle eval --set DIR` checks that `DIR` is that set.
use anyhow::{bail, Context};
use clap::Args;
use needle_haptics::{model_info, wrench, Evaluation, Pose, Status};
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
    /// With --poses: a scripted insertion through this compiled-in tissue stack (e.g.
    /// liver): the file needs a time_s column, one row per tick; one wrench row per tick.
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

/// Arguments of `needle header`.
#[derive(Args, Debug)]
pub struct HeaderArgs {
    /// Folder to write needle_coeffs.h (the model's tables) and needle.h (the C API) into
    /// (created if missing).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
}

/// Checks that the set folder `dir` is the one compiled into the library: same
/// `fe_sha256` and the same f32 coefficient bits as its `model.toml`, and the same
/// unsolved region (`unsolved.toml`, or none).
///
/// # Errors
/// The library has no fitted model, `dir` has no valid model.toml, or it is another set
/// (or another fit of the same FE data) than the one compiled in.
pub fn check_compiled_set(dir: &Path) -> anyhow::Result<()> {
    let model_path = dir.join(needle_codegen::MODEL_FILE);
    let rebuild = format!(
        "rebuild with NEEDLE_COEFFS={} (e.g. `NEEDLE_COEFFS={} cargo build --release -p needle-cli`)",
        dir.display(),
        dir.display()
    );
    if !model_info::FITTED {
        bail!(
            "this build of needle-haptics has no fitted model: it was built from {}, which had no model.toml (run `needle fit --set {}`, then rebuild); {rebuild}",
            model_info::SET_DIR,
            model_info::SET_DIR
        );
    }
    if !model_path.is_file() {
        bail!("{}: no such file: --set names a coefficient set folder holding model.toml", model_path.display());
    }
    let model = needle_codegen::parse_model(&model_path).map_err(anyhow::Error::new)?;
    let built =
        format!("this build has set {:?} compiled in, from {} (fe_sha256 {})", model_info::SET, model_info::SET_DIR, model_info::FE_SHA256);
    if model.fe_sha256 != model_info::FE_SHA256 {
        bail!(
            "{} is fitted on other FE data (fe_sha256 {}) than the compiled-in model: {built}; {rebuild}",
            model_path.display(),
            model.fe_sha256
        );
    }
    let same_bits = |a: &[f32], b: &[f32]| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
    let base_same = model.baseline_f32().iter().zip(model_info::BASELINE.iter()).all(|(a, b)| same_bits(a, b));
    let dev_same = model
        .deviation_f32()
        .iter()
        .flatten()
        .flatten()
        .zip(model_info::DEVIATION.iter().flatten().flatten())
        .all(|(a, b)| same_bits(a, b));
    if !(base_same && dev_same) {
        bail!("{} has other coefficients than the compiled-in model (same FE data, refitted?): {built}; {rebuild}", model_path.display());
    }
    // the unsolved region beside it (FE_UNSOLVED): the compiled-in one, or none for both
    let region_path = dir.join(needle_codegen::unsolved::FILE);
    let region = if region_path.is_file() {
        needle_codegen::unsolved::parse(&region_path).map_err(anyhow::Error::new)?
    } else {
        needle_codegen::unsolved::Region::default()
    };
    if needle_codegen::unsolved::render(&region) != model_info::UNSOLVED_RS {
        bail!(
            "{} is another unsolved region than the compiled-in one ({} balls compiled in; refitted after new FE records?): {built}; {rebuild}",
            region_path.display(),
            model_info::UNSOLVED_BALLS
        );
    }
    Ok(())
}

/// Names of the flags set in `status` (empty for OK).
pub fn status_names(status: Status) -> Vec<&'static str> {
    Status::FLAGS.iter().filter(|(f, _)| status.contains(*f)).map(|(_, n)| *n).collect()
}

/// Each component's name and unit, in the contract's order.
fn names() -> impl Iterator<Item = (&'static str, &'static str)> {
    needle_contract::COMPONENTS.into_iter().zip(needle_contract::UNITS)
}

/// The compiled-in model's form: `paper` or `coupled`.
pub fn form_name() -> &'static str {
    if model_info::COUPLED {
        "coupled"
    } else {
        "paper"
    }
}

/// The stated accuracy of the compiled-in model (`[coupled]` of its model.toml): the
/// cross-validated RMS error per component, in % and in N or N*mm; `null` for the paper
/// form, whose model.toml records none.
pub fn accuracy_json() -> serde_json::Value {
    if !model_info::COUPLED {
        return serde_json::Value::Null;
    }
    let mut pct = serde_json::Map::new();
    let mut abs = serde_json::Map::new();
    for (((name, _), p), scale) in names().zip(model_info::CV_RMS_PCT).zip(model_info::CV_SCALE) {
        pct.insert((*name).to_string(), serde_json::json!(p));
        abs.insert((*name).to_string(), serde_json::json!(p * scale / 100.0));
    }
    serde_json::json!({
        "method": format!("{}-fold cross-validation over the sweep runs and {} training runs (role train)", needle_fit::coupled::FOLDS, model_info::TRAINING_RUNS),
        "rms_pct_of_scale": pct,
        "rms": abs,
        "scale": "peak |Fy| of the training runs (N) for the forces, times the hub lever arm (N*mm) for the moments",
    })
}

/// The JSON form of `needle eval --poses FILE --json`: an array of [`eval_json`] objects.
pub fn to_json(poses: &[Pose], evals: &[Evaluation]) -> serde_json::Value {
    serde_json::Value::Array(poses.iter().zip(evals).map(|(p, e)| eval_json(p, e)).collect())
}

/// The JSON object `needle eval --json` prints.
pub fn eval_json(pose: &Pose, e: &Evaluation) -> serde_json::Value {
    let mut wrench = serde_json::Map::new();
    let mut bits = serde_json::Map::new();
    for ((name, _), v) in names().zip(e.wrench.to_array()) {
        wrench.insert((*name).to_string(), serde_json::json!(v));
        bits.insert((*name).to_string(), serde_json::json!(format!("{:#010x}", v.to_bits())));
    }
    let pose_bits = [pose.x_mm, pose.z_mm, pose.theta_x_deg, pose.theta_z_deg, pose.depth_mm].map(|v| format!("{:#010x}", v.to_bits()));
    serde_json::json!({
        "set": model_info::SET,
        "fe_sha256": model_info::FE_SHA256,
        "form": form_name(),
        "accuracy": accuracy_json(),
        "pose": {
            "x_mm": pose.x_mm, "z_mm": pose.z_mm, "theta_x_deg": pose.theta_x_deg,
            "theta_z_deg": pose.theta_z_deg, "depth_mm": pose.depth_mm,
        },
        "pose_bits": pose_bits,
        "wrench": wrench,
        "wrench_bits": bits,
        "reference_point": "needle hub (on the axis, needle.reference_from_tip_mm from the tip)",
        "status": {
            "bits": format!("{:#04x}", e.status.bits()),
            "flags": status_names(e.status),
            "ok": e.status.is_ok(),
            "saturated": e.status.saturated(),
            "fe_unsolved": e.status.fe_unsolved(),
            "error": e.status.is_error(),
        },
    })
}

/// `needle eval`: the wrench at one pose from the library. Exit code 0 for a wrench
/// (in the domain or saturated), 1 when the status is an error (NaN/infinite input).
///
/// # Errors
/// `--set` is not the set compiled into this build (see [`check_compiled_set`]).
pub fn eval(a: EvalArgs) -> anyhow::Result<ExitCode> {
    check_compiled_set(&a.set)?;
    if let (Some(out), None) = (&a.out, &a.poses) {
        bail!(
            "--out {} writes the rows of --poses FILE.csv; a single pose is printed (redirect standard output to keep it)",
            out.display()
        );
    }
    if let (Some(file), Some(stack)) = (&a.poses, &a.insertion) {
        super::eval_insertion::eval_script(file, stack, a.prony.as_deref(), a.out.as_deref())?;
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

/// `needle eval --poses FILE`: every row of the file (see [`super::eval_batch`]). Exit
/// code 0; the rows with an error status carry it in their status column.
///
/// # Errors
/// The file cannot be read, has a bad header or bad rows (all listed, by line), or the
/// output cannot be written.
fn eval_file(file: &Path, out: Option<&Path>, json: bool) -> anyhow::Result<ExitCode> {
    use super::eval_batch::{evaluate, parse_poses};
    if !json {
        // CSV: streamed, chunk by chunk (memory bounded), on every core
        let rows = super::eval_stream::eval_csv(file, out)?;
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

/// `needle header`: writes the C headers to `DIR`: `needle_coeffs.h` (generated with the
/// compiled-in tables) and `needle.h` (the C API's header, from `needle-capi`).
///
/// # Errors
/// The folder cannot be created or the file cannot be written.
pub fn header(a: HeaderArgs) -> anyhow::Result<ExitCode> {
    std::fs::create_dir_all(&a.out).with_context(|| format!("creating {}", a.out.display()))?;
    let path = a.out.join(needle_codegen::C_HEADER_FILE);
    // the C API's own header (functions, types, NEEDLE_STATUS_* / NEEDLE_LOOP_* constants)
    let api = a.out.join("needle.h");
    // both or neither: a failure leaves the old pair as it was
    needle_stdx::fs::write_all_atomic(&[(&path, model_info::C_HEADER.as_bytes()), (&api, needle_capi::HEADER.as_bytes())])?;
    println!("wrote {} (the C API: link libneedle_capi.a from `cargo build --release -p needle-capi`)", api.display());
    if model_info::FITTED {
        println!("wrote {} (set {}, fe_sha256 {})", path.display(), model_info::SET, model_info::FE_SHA256);
    } else {
        eprintln!(
            "warning: this build has no fitted model ({} had no model.toml): the header's tables are all zero (NEEDLE_COEFFS_FITTED 0)",
            model_info::SET_DIR
        );
        println!("wrote {}", path.display());
    }
    Ok(ExitCode::SUCCESS)
}
