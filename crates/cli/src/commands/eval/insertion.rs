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

/// The stack compiled in under `name` (its file's stem).
///
/// # Errors
/// No such stack (the compiled-in ones are listed).
pub fn stack(name: &str) -> Result<&'static needle_haptics::insertion::Stack<'static>> {
    stacks::by_name(name).with_context(|| {
        let names: Vec<&str> = stacks::ALL.iter().map(|s| s.name).collect();
        format!("--insertion {name:?}: no such tissue stack in the compiled-in set (it has: {})", names.join(", "))
    })
}

/// The Prony terms of `--prony`: "g:tau_s" pairs, comma-separated, checked as a tissue
/// file's are (`PronyTerms::new`).
///
/// # Errors
/// A pair that is not two numbers, or terms out of range (the message says which).
pub fn parse_prony(text: &str) -> Result<needle_haptics::viscoelastic::PronyTerms> {
    use needle_haptics::viscoelastic::{PronyTerm, PronyTerms};
    let mut terms = Vec::new();
    for pair in text.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        let parsed = pair.split_once(':').and_then(|(g, tau)| Some((g.trim().parse::<f32>().ok()?, tau.trim().parse::<f32>().ok()?)));
        let Some((g, tau_s)) = parsed else {
            bail!("--prony {text:?}: {pair:?} is not g:tau_s (two numbers, e.g. 0.6:0.5)");
        };
        terms.push(PronyTerm { g, tau_s });
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

/// `needle eval --poses FILE --insertion STACK [--prony G:TAU_S,...] [--out F]`.
///
/// # Errors
/// As [`parse_poses`], [`parse_times`], [`stack`], [`parse_prony`]; the output cannot be
/// written.
pub fn eval_script(file: &Path, stack_name: &str, prony: Option<&str>, out: Option<&Path>) -> Result<()> {
    let compiled = stack(stack_name)?;
    let terms = prony.map(parse_prony).transpose()?;
    let layers: Vec<needle_haptics::insertion::Layer> =
        compiled.layers.iter().map(|l| needle_haptics::insertion::Layer { prony: terms.unwrap_or(l.prony), ..*l }).collect();
    let stack = &needle_haptics::insertion::Stack { layers: &layers, ..*compiled };
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
