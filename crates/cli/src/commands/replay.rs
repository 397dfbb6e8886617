//! `needle replay`: a tissue stack (a file loaded at run time, or a compiled-in name)
//! driven through the library's f32 insertion model by a measured trial's position
//! against time; the measured and the model force per row, the phases and punctures,
//! and the trial's checks (the goals of a predicted trial).
use anyhow::Result;
use clap::Args;
use needle_calibrate::events::EventRule;
use needle_calibrate::runtime_stack::OwnedStack;
use needle_calibrate::whole::trials;
use needle_haptics::insertion;
use needle_haptics::Pose;
use std::path::PathBuf;
use std::process::ExitCode;

/// Replay a measured trial through a tissue stack.
#[derive(Args)]
pub struct ReplayArgs {
    /// The stack: a tissue file (checked as the build checks one, file:line) or the name
    /// of a compiled-in stack.
    #[arg(long)]
    pub stack: String,
    /// The trial: CSV with columns time_s, position_mm (stage travel) and force_n, each
    /// force taken from the force at rest before the stage moves and each position from
    /// the stage's start (the notes say when either is not zero).
    #[arg(long)]
    pub trial: PathBuf,
    /// Print one JSON document (notes, rows, punctures, checks) instead of the text.
    #[arg(long)]
    pub json: bool,
    /// Also write the figure here (SVG): the measured and the model force against time
    /// over insertion, hold and withdrawal, the punctures, the residual.
    #[arg(long, value_name = "SVG")]
    pub figure: Option<PathBuf>,
    /// Replace an existing figure (without it, an existing one is refused before the run).
    #[arg(long)]
    pub force: bool,
}

/// Runs `needle replay`: exit 0 whether or not the checks are met (they are printed);
/// with `--figure`, the figure written ([`super::calibrate::trials_figure`]).
///
/// # Errors
/// The stack or the trial is refused (file:line).
pub fn run(a: ReplayArgs) -> Result<ExitCode> {
    if let Some(figure) = &a.figure {
        let planned = [crate::planned_outputs::Planned { option: "--figure", path: figure }];
        crate::planned_outputs::check(&planned, None, &[("--trial", &a.trial), ("--stack", std::path::Path::new(&a.stack))], a.force)?;
    }
    let owned = OwnedStack::resolve("--stack", &a.stack)?;
    let stack = owned.as_stack();
    let lambda = stack.needle_diameter_mm / insertion::FE_NEEDLE_DIAMETER_MM;
    let u = move |d: f64| f64::from(insertion::deflection(&Pose::default(), d as f32, 1.0, lambda).wrench.fy_n);
    let t = trials::prepare(&a.trial, EventRule::default(), &u, f64::from(lambda), false)?;
    let r = needle_calibrate::trial_replay::replay(&stack, t.onset_mm(), &t.samples).map_err(|e| anyhow::anyhow!("{}: {e}", t.name()))?;
    let checks = needle_calibrate::goals::checks(&t, &r, &needle_calibrate::goals::PREDICTED);
    if let Some(figure) = &a.figure {
        let caption = format!("needle replay: stack {} on {}, measured and model", stack.name, t.name());
        let svg = super::calibrate::trials_figure::svg(&caption, &[(&t, &r)])?;
        needle_stdx::fs::write_all_atomic(&[(figure.as_path(), svg.as_bytes())])?;
        let say = format!("wrote {}", figure.display());
        if a.json {
            eprintln!("{say}");
        } else {
            println!("{say}");
        }
    }
    if a.json {
        let doc = serde_json::json!({
            "stack": stack.name, "trial": t.name(), "notes": t.phases.notes, "contact_mm": t.onset_mm(),
            "phases": {"insertion_lines": line_range(&t, &t.phases.insertion), "hold_lines": line_range(&t, &t.phases.hold),
                       "withdrawal_lines": line_range(&t, &t.phases.withdrawal)},
            "measured_punctures": (0..t.events.len()).filter_map(|k| t.peak(k)).map(|(p, f)| serde_json::json!({"position_mm": p, "force_n": f})).collect::<Vec<_>>(),
            "checks": super::calibrate::json::checks(&checks),
            "model": super::calibrate::json::rows(&t.samples, &r),
        });
        println!("{}", serde_json::to_string_pretty(&doc)?);
        return Ok(ExitCode::SUCCESS);
    }
    for note in &t.phases.notes {
        println!("note: {note}");
    }
    let p = &t.phases;
    println!("stack {} on {}: contact at {:.3} mm of travel", stack.name, t.name(), t.onset_mm());
    println!(
        "phases: insertion lines {:?} at {:.3} mm/s, hold lines {:?} ({:.2} s), withdrawal lines {:?} at {:.3} mm/s",
        line_range(&t, &p.insertion),
        p.insertion_speed_mm_per_s,
        line_range(&t, &p.hold),
        p.hold_s,
        line_range(&t, &p.withdrawal),
        p.withdrawal_speed_mm_per_s
    );
    for k in 0..t.events.len() {
        if let Some((pos, f)) = t.peak(k) {
            println!("measured puncture {}: {f:.4} N at {pos:.3} mm", k + 1);
        }
    }
    for (k, m) in r.punctures.iter().enumerate() {
        println!("model puncture {}: {:.4} N at {:.3} mm ({:.3} s)", k + 1, m.force_n, m.position_mm, m.time_s);
    }
    println!("time_s,position_mm,force_n,model_force_n,model_phase");
    for (s, m) in t.samples.iter().zip(&r.rows) {
        println!("{},{},{},{:.6},{:#06x}", s.time_s, s.position_mm, s.force_n, m.force_n, m.phase.code());
    }
    println!("checks (the goals of a predicted trial):");
    super::calibrate::print_checks(&checks);
    Ok(ExitCode::SUCCESS)
}

/// The first and last file lines of a phase (`None`: the trial has no such phase).
fn line_range(t: &trials::Trial, r: &std::ops::Range<usize>) -> Option<(usize, usize)> {
    Some((t.samples.get(r.start)?.line, t.samples.get(r.end.checked_sub(1)?)?.line))
}
