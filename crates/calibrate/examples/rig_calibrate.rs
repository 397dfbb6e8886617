//! `needle calibrate`'s single-curve path (`calibrate_points`: the shape fit, the layers
//! below, the replay through the library's insertion model and its checks) on every rig
//! trial of `../shared/data/stokes-needle-rig/` (each trial's insertion phase, fitted on
//! itself), then each trial's stack replayed against the group's other repeats (same
//! sample and speed). Prints per trial the pre-puncture RMS (% of the puncture force),
//! the first puncture's position error (mm) and force error (%), the member and the
//! softening. Usage: cargo run --release -p needle-calibrate --example rig_calibrate
//! [DIR] [NEEDLE_MM] [SET]
use needle_calibrate::{calibrate_points, events, measured::Point, replay, to_layer, trial, Options};
use needle_haptics::insertion::Stack;
use std::path::{Path, PathBuf};

/// The insertion phase's points, its speed (mm/s) and the measured contact position (mm:
/// where the force leaves the tare's noise, `trial::phases`).
fn insertion_points(path: &Path) -> anyhow::Result<(Vec<Point>, f64, f64)> {
    let s = trial::read_trial(path)?;
    let ph = trial::phases(&s, &path.display().to_string())?;
    let pts = s[ph.insertion.clone()].iter().map(|x| Point { position_mm: x.position_mm, force_n: x.force_n, line: x.line }).collect();
    Ok((pts, ph.insertion_speed_mm_per_s, s.get(ph.contact).map_or(f64::NAN, |x| x.position_mm)))
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let dir = PathBuf::from(args.get(1).cloned().unwrap_or_else(|| "../shared/data/stokes-needle-rig".into()));
    let needle_mm: f64 = args.get(2).map_or(Ok(1.27), |s| s.parse())?;
    let set = PathBuf::from(args.get(3).cloned().unwrap_or_else(|| "coeffs/default".into()));
    let mu0 = needle_codegen::tissue::read_fe_shear_modulus(&set)?.unwrap_or(1.0);
    let mut files: Vec<PathBuf> =
        std::fs::read_dir(&dir)?.filter_map(|e| e.ok().map(|e| e.path())).filter(|p| p.extension().is_some_and(|x| x == "csv")).collect();
    files.sort();
    println!(
        "{:<44} {:>7} {:>7} {:>7} {:>6} {:>6} {:>5} {:>8} {:>8}  checks missed",
        "trial (self)", "rms %", "dpos mm", "dF %", "w", "delta", "r0", "s", "onset"
    );
    let mut stacks = Vec::new();
    for f in &files {
        let (points, speed, contact) = insertion_points(f)?;
        let opts = Options {
            curve: f,
            name: "rig".into(),
            needle_diameter_mm: needle_mm,
            speed_mm_per_s: speed,
            rule: events::EventRule::default(),
            fe_shear_modulus_n_per_mm2: mu0,
        };
        let name = f.file_name().map(|n| n.to_string_lossy().to_string()).unwrap_or_default();
        let c = match calibrate_points(&opts, points) {
            Ok(c) => c,
            Err(e) => {
                println!("{name}: {e:#}");
                continue;
            }
        };
        let get = |w: &str| c.checks.iter().find(|k| k.what.starts_with(w)).map_or(f64::NAN, |k| k.error);
        let missed: Vec<String> = c.checks.iter().filter(|k| !k.met()).map(|k| format!("{} {:.2}{}", k.what, k.error, k.unit)).collect();
        let l0 = &c.stack.layers[0];
        println!(
            "{:<44} {:>7.2} {:>7.2} {:>7.2} {:>6.3} {:>6.3} {:>5.2} {:>8.4} {:>8.4}  {}",
            name,
            get("pre-puncture RMS"),
            get("puncture 1 position"),
            get("puncture 1 force"),
            l0.family_weight,
            l0.softening_fraction,
            l0.softening_onset_ratio,
            l0.stiffness_scale,
            c.fit.onset_mm,
            missed.join("; ")
        );
        stacks.push((name, c, speed, contact));
    }
    // repeats: each trial's stack replayed on the other trials of its group (same sample and speed)
    println!("\n{:<44} {:>9} {:>9} {:>9} {:>12}", "calibrated on -> replayed on", "rms %", "dpos mm", "dF %", "floor rms %");
    let group = |n: &str| n.rsplit_once("_trial").map_or(n.to_string(), |(g, _)| g.to_string());
    let (mut worst, mut all, mut floors) = (0.0f64, Vec::new(), Vec::new());
    for (a, ca, _, contact_a) in &stacks {
        let layers: Vec<_> = ca.stack.layers.iter().map(to_layer).collect();
        let stack = Stack { name: "rig", needle_diameter_mm: ca.stack.needle_diameter_mm as f32, layers: &layers };
        for (b, cb, speed_b, contact_b) in &stacks {
            if a == b || group(a) != group(b) {
                continue;
            }
            let pts = &cb.points;
            let (start, end) = (pts.first().map_or(0.0, |p| p.position_mm), pts.last().map_or(0.0, |p| p.position_mm));
            // the replayed trial's contact from its measured contact (where its force leaves the
            // tare's noise), offset as in the calibrated trial: nothing of its own fit is used
            let onset = if std::env::var("ALIGN5").is_ok() {
                let cross = |c: &needle_calibrate::Calibration| {
                    let peak = c.events.first().map_or(0, |e| e.peak);
                    let f = c.points.get(peak).map_or(0.0, |p| p.force_n);
                    replay::measured_onset(&c.points, peak, replay::ONSET_FRACTION * f).unwrap_or(f64::NAN)
                };
                ca.fit.onset_mm + (cross(cb) - cross(ca))
            } else {
                ca.fit.onset_mm + (contact_b - contact_a)
            };
            let model = replay::replay(&stack, onset, start, end, *speed_b);
            // the repeats' own floor: trial a's measured curve, shifted as the model is, as the
            // model of trial b over the same window (b's onset to its first puncture)
            let floor = measured_as_model(&ca.points, &cb.points, cb.events.first().map_or(0, |e| e.peak), onset - ca.fit.onset_mm);
            let checks = replay::checks(pts, &cb.events, &model);
            let get = |w: &str| checks.iter().find(|k| k.what.starts_with(w)).map_or(f64::NAN, |k| k.error);
            worst = worst.max(get("pre-puncture RMS"));
            all.push(get("pre-puncture RMS"));
            floors.push(floor);
            println!(
                "{:<44} {:>9.2} {:>9.2} {:>9.2} {:>12.2}",
                format!("{} -> {}", short(a), short(b)),
                get("pre-puncture RMS"),
                get("puncture 1 position"),
                get("puncture 1 force"),
                floor
            );
        }
    }
    println!("worst replayed pre-puncture RMS: {worst:.2} %");
    let summary = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        let at = |q: f64| v.get(((v.len() as f64 - 1.0) * q).round() as usize).copied().unwrap_or(f64::NAN);
        format!("median {:.2} %, 90th percentile {:.2} %, worst {:.2} % ({} pairs)", at(0.5), at(0.9), at(1.0), v.len())
    };
    println!("replayed stacks: {}", summary(&mut all));
    println!("floor (the calibrated trial's measured curve as the model): {}", summary(&mut floors));
    Ok(())
}

/// The pre-puncture RMS (% of `b`'s first puncture force, over `b`'s points from its 5 %
/// onset to that puncture, as `replay::checks` measures a model) of `a`'s measured curve
/// shifted by `shift_mm` (linear between its points; `a`'s insertion, its punctures too)
/// as the model of `b`.
fn measured_as_model(a: &[Point], b: &[Point], b_peak: usize, shift_mm: f64) -> f64 {
    let peak = b.get(b_peak).map_or(f64::NAN, |p| p.force_n);
    let onset = replay::measured_onset(b, b_peak, replay::ONSET_FRACTION * peak).unwrap_or(f64::NEG_INFINITY);
    let at = |p: f64| {
        let x = p - shift_mm;
        let i = a.partition_point(|q| q.position_mm < x);
        match (i.checked_sub(1).and_then(|k| a.get(k)), a.get(i)) {
            (Some(l), Some(r)) if r.position_mm > l.position_mm => {
                l.force_n + (r.force_n - l.force_n) * (x - l.position_mm) / (r.position_mm - l.position_mm)
            }
            (_, Some(r)) => r.force_n,
            (Some(l), None) => l.force_n,
            (None, None) => f64::NAN,
        }
    };
    let pre: Vec<&Point> = b.iter().take(b_peak + 1).filter(|p| p.position_mm >= onset).collect();
    let ss: f64 = pre.iter().map(|p| (at(p.position_mm) - p.force_n).powi(2)).sum();
    100.0 * (ss / pre.len().max(1) as f64).sqrt() / peak
}

fn short(n: &str) -> String {
    n.replace("_0deg_needle2", "").replace(".csv", "")
}
