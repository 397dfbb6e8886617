//! `needle eval --poses FILE.csv --insertion STACK [--prony G:TAU_S,...]`: a scripted
//! insertion through one of the compiled-in tissue stacks, one wrench row per tick; with
//! `--prony`, those terms on every layer (the viscoelastic filter: the force relaxes
//! while the needle is still).
//!
//! Input: the pose file of [`super::batch`] with one more column, `time_s`, equally
//! spaced (the tick period; within 1e-6 s); rows in time order. Each row is one tick of
//! [`Insertion::step`]: the wrench depends on the rows before it (punctures, the track,
//! the velocity). Output: `time_s`, the pose, the wrench, the status byte, the phase
//! (`approach`, `deflecting:<layer>`, `cutting:<layer>`, `in-track:<layer>`), the
//! punctures of the tick and the step's flags byte (`InsertionFlags`: a glitch the
//! model did not integrate, or a wrench scaled down to its bound; their names on stderr).
use super::batch::{parse_poses, push_pose_wrench_status, POSE_COLUMNS};
use anyhow::{bail, Context, Result};
use needle_haptics::insertion::{stacks, Insertion, InsertionConfig, InsertionEvaluation, Phase};
use needle_haptics::Pose;
use std::fmt::Write as _;
use std::path::Path;

/// The time column.
pub const TIME_COLUMN: &str = "time_s";
/// Output header.
pub const OUTPUT_HEADER: &str =
    "time_s,x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm,fx_n,fy_n,fz_n,mx_nmm,my_nmm,mz_nmm,status,phase,punctures,flags";
/// Largest departure of a time step from the first one, s.
pub const PERIOD_TOLERANCE_S: f64 = 1e-6;
/// A tick longer than this many control periods (`InsertionConfig::DEFAULT_1KHZ`,
/// 0.001 s) is warned on stderr as a likely unit problem (time_s in ms?): 0.01 s, a
/// haptic loop slower than 100 Hz.
pub const WARN_TICK_PERIODS: f64 = 10.0;
/// A tick longer than this many control periods is refused: 0.1 s, a loop slower than
/// 10 Hz is no haptic rendering (time in ms gives ticks of 1 s).
pub const MAX_TICK_PERIODS: f64 = 100.0;

/// The stack compiled in under `name` (its file's stem), named by `option` (`--insertion`,
/// `--stack`) in the message.
///
/// # Errors
/// No such stack (the compiled-in ones are listed).
pub fn stack(option: &str, name: &str) -> Result<&'static needle_haptics::insertion::Stack<'static>> {
    stacks::by_name(name).with_context(|| {
        let names: Vec<&str> = stacks::ALL.iter().map(|s| s.name).collect();
        format!("{option} {name:?}: no such tissue stack in the compiled-in set (it has: {})", names.join(", "))
    })
}

/// The Prony terms of `--prony`: "g:tau_s" pairs, comma-separated, checked as a tissue
/// file's are (`PronyTerms::new`). At least one term: an empty value (`""`, `","`: an
/// unset shell variable) would silently remove the stack's own terms.
///
/// # Errors
/// No term, a pair that is not two numbers, a number beyond f32, or terms out of range
/// (the message says which).
pub fn parse_prony(text: &str) -> Result<needle_haptics::viscoelastic::PronyTerms> {
    use needle_haptics::viscoelastic::{PronyTerm, PronyTerms};
    let mut terms = Vec::new();
    for pair in text.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        let parsed = pair.split_once(':').and_then(|(g, tau)| Some((g.trim().parse::<f64>().ok()?, tau.trim().parse::<f64>().ok()?)));
        let Some((g, tau_s)) = parsed else {
            bail!("--prony {text:?}: {pair:?} is not g:tau_s (two numbers, e.g. 0.6:0.5)");
        };
        for (name, v, rule) in [("g", g, "g is at most 9 (the weights' sum)"), ("tau_s", tau_s, "tau_s is a time constant in s")] {
            if v.is_finite() && !(v as f32).is_finite() {
                bail!("--prony {text:?}: {pair:?}: {name} = {v} is beyond the library's f32 numbers (|x| <= 3.4e38); {rule}");
            }
        }
        terms.push(PronyTerm { g: g as f32, tau_s: tau_s as f32 });
    }
    if terms.is_empty() {
        bail!(
            "--prony {text:?}: no term (an unset shell variable?): give g:tau_s pairs (e.g. 0.6:0.5), or leave --prony out to keep the stack's own terms"
        );
    }
    PronyTerms::new(&terms).map_err(|e| anyhow::anyhow!("--prony {text:?}: {e}"))
}

/// The time column of `text`, checked: numbers, equally spaced, increasing; the period.
///
/// # Errors
/// A missing column, a value that is not a number (by line), fewer than two rows, or
/// steps that are not equal (the first offending line).
pub fn parse_times(text: &str, path: &Path) -> Result<(Vec<f64>, f64)> {
    let mut rdr = csv::ReaderBuilder::new().trim(csv::Trim::All).flexible(true).from_reader(text.as_bytes());
    let header = rdr.headers().with_context(|| format!("{}:1: cannot read the header", path.display()))?.clone();
    let col = header.iter().position(|h| h == TIME_COLUMN).with_context(|| {
        format!("{}:1: no column {TIME_COLUMN:?}: a scripted insertion needs it beside {}", path.display(), POSE_COLUMNS.join(", "))
    })?;
    let count = header.iter().filter(|h| *h == TIME_COLUMN).count();
    if count > 1 {
        bail!("{}:1: column {TIME_COLUMN:?} appears {count} times: which one is the time is not clear", path.display());
    }
    let mut times: Vec<(u64, f64)> = Vec::new();
    for rec in rdr.records() {
        let rec = rec.with_context(|| format!("{}: malformed CSV", path.display()))?;
        let line = rec.position().map_or(0, |p| p.line());
        let t = rec.get(col).unwrap_or("");
        let v: f64 = t.parse().ok().filter(|v: &f64| v.is_finite()).with_context(|| {
            let shown: String = t.chars().take(40).collect();
            format!("{}:{line}: column {TIME_COLUMN}: {shown:?} is not a finite number", path.display())
        })?;
        times.push((line, v));
    }
    let [(_, t0), (_, t1), ..] = times.as_slice() else {
        bail!("{}: {} rows: a scripted insertion needs at least two", path.display(), times.len());
    };
    let period = t1 - t0;
    if period <= 0.0 {
        bail!("{}: time_s does not increase ({t0} then {t1})", path.display());
    }
    check_tick(period, path)?;
    for pair in times.windows(2) {
        let [(_, a), (line, b)] = pair else { continue };
        if ((b - a) - period).abs() > PERIOD_TOLERANCE_S {
            bail!(
                "{}:{line}: column {TIME_COLUMN}: step {} s, the first step was {period} s (a script is one row per tick)",
                path.display(),
                b - a
            );
        }
    }
    Ok((times.into_iter().map(|(_, t)| t).collect(), period))
}

/// Warns on stderr of a tick longer than [`WARN_TICK_PERIODS`] control periods and
/// refuses one longer than [`MAX_TICK_PERIODS`]: a unit problem (time_s in ms?), not a
/// haptic loop.
///
/// # Errors
/// The tick is longer than the limit.
pub fn check_tick(period_s: f64, path: &Path) -> Result<()> {
    let control = f64::from(InsertionConfig::DEFAULT_1KHZ.period_s);
    let unit = format!("the control period is {control} s (1 kHz): time_s in milliseconds?");
    if period_s > MAX_TICK_PERIODS * control {
        bail!(
            "{}: column {TIME_COLUMN}: ticks of {period_s} s, more than {} s ({MAX_TICK_PERIODS} control periods): {unit}",
            path.display(),
            MAX_TICK_PERIODS * control
        );
    }
    if period_s > WARN_TICK_PERIODS * control {
        eprintln!(
            "warning: {}: ticks of {period_s} s, more than {WARN_TICK_PERIODS} control periods: {unit} (the model integrates each tick as one step)",
            path.display()
        );
    }
    Ok(())
}

/// Runs the script through `stack`: one evaluation per row.
///
/// # Errors
/// The period is not a usable tick (the insertion's configuration check).
pub fn step_all(stack: &needle_haptics::insertion::Stack<'_>, poses: &[Pose], period_s: f64) -> Result<Vec<InsertionEvaluation>> {
    let config = InsertionConfig { period_s: period_s as f32, ..InsertionConfig::DEFAULT_1KHZ };
    let mut insertion = Insertion::new(stack, config).map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok(poses.iter().map(|p| insertion.step(p)).collect())
}

fn phase_name(p: Phase) -> String {
    match p {
        Phase::Approach => "approach".into(),
        Phase::Deflecting(l) => format!("deflecting:{l}"),
        Phase::Cutting(l) => format!("cutting:{l}"),
        Phase::InTrack(l) => format!("in-track:{l}"),
    }
}

/// What the step flagged, for stderr: per flag its name, the ticks it was set in and the
/// first row (1-based, the header being row 0); `None` when no tick was flagged.
#[must_use]
pub fn flags_note(evals: &[InsertionEvaluation]) -> Option<String> {
    let parts: Vec<String> = needle_haptics::InsertionFlags::FLAGS
        .iter()
        .filter_map(|&(flag, name)| {
            let mut rows = evals.iter().enumerate().filter(|(_, e)| e.flags.contains(flag)).map(|(i, _)| i + 1);
            let first = rows.next()?;
            Some(format!("{name} in {} ticks (first at row {first})", 1 + rows.count()))
        })
        .collect();
    (!parts.is_empty())
        .then(|| format!("insertion flags: {} (a glitch is not integrated: the wrench of the tick before is held)", parts.join(", ")))
}

/// The CSV form ([`OUTPUT_HEADER`]).
#[must_use]
pub fn to_csv(times: &[f64], poses: &[Pose], evals: &[InsertionEvaluation]) -> String {
    let mut s = String::with_capacity(poses.len() * 180);
    s.push_str(OUTPUT_HEADER);
    s.push('\n');
    for ((t, p), e) in times.iter().zip(poses).zip(evals) {
        let _ = write!(s, "{t:?},");
        push_pose_wrench_status(&mut s, p, &e.wrench, e.status);
        let _ = writeln!(s, ",{},{},{:#04x}", phase_name(e.phase), e.punctures, e.flags.bits());
    }
    s
}

/// `needle eval --poses FILE --insertion STACK [--prony G:TAU_S,...] [--out F]`; STACK a
/// compiled-in name or a tissue file loaded at run time.
///
/// # Errors
/// As [`parse_poses`], [`parse_times`], [`stack`], [`parse_prony`]; the output cannot be
/// written.
pub fn eval_script(file: &Path, stack_name: &str, prony: Option<&str>, out: Option<&Path>) -> Result<()> {
    // a tissue file loaded at run time (checked as the build checks it) or a compiled-in name
    let loaded = needle_calibrate::runtime_stack::OwnedStack::resolve("--insertion", stack_name)?;
    let terms = prony.map(parse_prony).transpose()?;
    let layers: Vec<needle_haptics::insertion::Layer> =
        loaded.layers.iter().map(|l| needle_haptics::insertion::Layer { prony: terms.unwrap_or(l.prony), ..*l }).collect();
    let stack = &needle_haptics::insertion::Stack { layers: &layers, ..loaded.as_stack() };
    let text = std::fs::read_to_string(file).with_context(|| format!("{}: cannot read", file.display()))?;
    let (times, period) = parse_times(&text, file)?;
    let poses = parse_poses(&text, file)?;
    let evals = step_all(stack, &poses, period)?;
    let body = to_csv(&times, &poses, &evals);
    if let Some(note) = flags_note(&evals) {
        eprintln!("{}: {note}", file.display());
    }
    match out {
        Some(path) => {
            needle_stdx::fs::write_atomic(path, body.as_bytes())?;
            eprintln!("wrote {} ({} ticks of {} s through {})", path.display(), poses.len(), period, stack.name);
        }
        None => {
            use std::io::Write as _;
            std::io::stdout().lock().write_all(body.as_bytes()).context("writing to standard output")?;
        }
    }
    Ok(())
}
