//! `needle calibrate --trials`: whole measured trials in, one stack fitted to them
//! together (needle-calibrate's `whole`), each value with its uncertainty beside it,
//! replayed along every trial and held against it.
use super::{check_name, CalibrateArgs};
use crate::compiled_set::check_compiled_set_except;
use crate::planned_outputs::{self, Planned};
use anyhow::{Context, Result};
use needle_calibrate::events::EventRule;
use needle_calibrate::whole::{annotate::annotate, calibrate_trials, TrialsCalibration, TrialsOptions};
use std::process::ExitCode;

/// Runs the `--trials` form: the name, set and outputs are checked first, the trials
/// read and fitted, the text (or `--json`) printed, the stack and its figure
/// ([`super::trials_figure`]) written last, together (nothing on an error; on a missed
/// goal only with `--write-on-miss`); exit 1 when a goal is missed.
///
/// # Errors
/// The set is not the compiled-in one, an output is refused, a trial is refused (its
/// `FILE:LINE`), or the file cannot be written.
pub fn run_trials(a: &CalibrateArgs) -> Result<ExitCode> {
    check_name(&a.name)?;
    check_compiled_set_except(&a.set, Some(&a.name))?;
    let mu0 = needle_codegen::tissue::read_fe_shear_modulus(&a.set)?
        .with_context(|| format!("{}: no campaign.toml: the FE tissue's shear modulus sets the track stiffness", a.set.display()))?;
    let (out, figure) = super::output_paths(&a.set, &a.name, a.out.as_deref(), a.figure.as_deref());
    let inputs: Vec<(&str, &std::path::Path)> = a.trials.iter().map(|p| ("--trials", p.as_path())).collect();
    let spread_out = needle_calibrate::spread::beside(&out);
    let planned = [
        Planned { option: "--out", path: &out },
        Planned { option: "--figure", path: &figure },
        Planned { option: "--out (its spread)", path: &spread_out },
    ];
    planned_outputs::check(&planned, Some(&a.set), &inputs, a.force)?;
    let opts = TrialsOptions {
        trials: &a.trials,
        name: a.name.clone(),
        needle_diameter_mm: &a.needle_diameter_mm,
        rule: EventRule { drop_fraction: a.drop_fraction, ..EventRule::default() },
        fe_shear_modulus_n_per_mm2: mu0,
    };
    let c = calibrate_trials(&opts)?;
    let all_met = c.checks.iter().flatten().all(needle_calibrate::replay::Check::met);
    if a.json {
        println!("{}", serde_json::to_string_pretty(&super::json::calibration(&c))?);
        for e in &c.edges {
            eprintln!("warning: {e}");
        }
    } else {
        print_text(&c);
    }
    let say = |s: String| if a.json { eprintln!("{s}") } else { println!("{s}") };
    if !all_met && !a.write_on_miss {
        say("result: FAIL (a goal is missed): nothing written (--write-on-miss writes the stack and figure anyway)".into());
        return Ok(ExitCode::from(1));
    }
    let names: Vec<String> = a.trials.iter().map(|p| p.display().to_string()).collect();
    let header = format!(
        "Tissue stack `{}`, written by `needle calibrate --trials` (format: coeffs/README.md, \"Tissue stacks\").\nTrials: {}.\nBeside each fitted value: its uncertainty (standard error over the trials).",
        a.name,
        names.join(", ")
    );
    let text = annotate(&c.fitted.stack.to_toml(&header), &c.fitted.uncertainty);
    let shown: Vec<_> = c.trials.iter().zip(&c.replays).collect();
    let caption = match c.fitted.stack.layers.first() {
        Some(l) => format!(
            "needle calibrate --trials: {} on {} trials; first layer: member w = {}, scale s = {}, softening {}",
            a.name,
            c.trials.len(),
            needle_plot::panel::tick_label(l.family_weight),
            needle_plot::panel::tick_label(l.stiffness_scale),
            if l.softening_fraction > 0.0 {
                format!(
                    "{} from {}",
                    needle_plot::panel::tick_label(l.softening_fraction),
                    needle_plot::panel::tick_label(l.softening_onset_ratio)
                )
            } else {
                "none".into()
            }
        ),
        None => format!("needle calibrate --trials: {} on {} trials", a.name, c.trials.len()),
    };
    let svg = super::trials_figure::svg(&caption, &shown)?;
    let spread = needle_calibrate::spread::to_csv(&c.fitted.spread);
    needle_stdx::fs::write_all_atomic(&[(&out, text.as_bytes()), (&spread_out, spread.as_bytes()), (&figure, svg.as_bytes())])?;
    say(format!("wrote {}", out.display()));
    say(format!("wrote {} (the values' spread over the trials: needle stack sample)", spread_out.display()));
    say(format!("wrote {}", figure.display()));
    say(format!(
        "result: {}",
        if all_met { "every calibration goal met" } else { "FAIL (a goal is missed; written with --write-on-miss)" }
    ));
    Ok(if all_met { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

fn print_text(c: &TrialsCalibration) {
    for note in &c.notes {
        println!("note: {note}");
    }
    for e in &c.edges {
        println!("warning: {e}");
    }
    println!(
        "{} trials, {} punctures each; geometric similarity {:.4}; stick band {:.3} mm/s (half the slowest speed, at most 1)",
        c.trials.len(),
        c.fitted.punctures,
        c.similarity,
        c.fitted.stick_band_mm_per_s
    );
    for (k, (l, u)) in c.fitted.stack.layers.iter().zip(&c.fitted.uncertainty).enumerate() {
        let note = |key: &str| u.iter().find(|(k, _)| *k == key).map_or(String::new(), |(_, n)| format!(" [{n}]"));
        println!("layer {k}: {} thick {:.3} mm", l.name, l.thickness_mm);
        println!("  stiffness scale {:.4}{}", l.stiffness_scale, note("stiffness_scale"));
        println!("  puncture {:.4} N{}", l.puncture_force_n, note("puncture_force_n"));
        println!("  cutting {:.4} N{}", l.cutting_force_n, note("cutting_force_n"));
        println!(
            "  friction: static {:.5} N/mm, Coulomb {:.5} N/mm{}, viscous {:.5} N s/mm^2{}",
            l.friction_static_n_per_mm,
            l.friction_coulomb_n_per_mm,
            note("friction_coulomb_n_per_mm"),
            l.friction_viscous_n_s_per_mm2,
            note("friction_viscous_n_s_per_mm2")
        );
        for t in &l.prony {
            println!("  Prony term g {:.4}, tau {:.4} s", t.g, t.tau_s);
        }
        if !l.prony.is_empty() {
            println!("  {}", note("prony").trim());
        }
        if let Some(p) = l.presliding_mm {
            println!("  presliding {p:.3} mm{}", note("presliding_mm"));
            for t in &l.shaft_prony {
                println!("  shaft Prony term g {:.4}, tau {:.4} s", t.g, t.tau_s);
            }
            if !l.shaft_prony.is_empty() {
                println!("  {}", note("shaft_prony").trim());
            }
        }
    }
    for (t, checks) in c.trials.iter().zip(&c.checks) {
        println!("trial {} (contact at {:.3} mm of travel, {:.3} mm/s):", t.name(), t.onset_mm(), t.phases.insertion_speed_mm_per_s);
        super::print_checks(checks);
    }
}
