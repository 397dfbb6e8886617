//! The pre-puncture shape fit (`shape::fit`) on every rig trial of `../shared/data/stokes-needle-rig/`:
//! each trial's insertion up to its first puncture, fitted on itself; prints per trial the
//! member, softening, pre-puncture RMS (% of the puncture force, measured onset to the
//! peak) and the puncture force error. Usage: cargo run --release -p needle-calibrate
//! --example rig_shape [DIR] [NEEDLE_MM]
use needle_calibrate::{events, measured::Point, shape, trial};
use needle_haptics::{insertion, Pose};
use std::time::Instant;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let dir = args.get(1).cloned().unwrap_or_else(|| "../shared/data/stokes-needle-rig".into());
    let needle_mm: f64 = args.get(2).map_or(Ok(1.27), |s| s.parse())?;
    let lambda = needle_mm / f64::from(insertion::FE_NEEDLE_DIAMETER_MM);
    let surrogate = |d: f64| f64::from(insertion::deflection(&Pose::default(), d as f32, 1.0, lambda as f32).wrench.fy_n);
    let mut files: Vec<_> =
        std::fs::read_dir(&dir)?.filter_map(|e| e.ok().map(|e| e.path())).filter(|p| p.extension().is_some_and(|x| x == "csv")).collect();
    files.sort();
    println!("{:<44} {:>6} {:>6} {:>5} {:>7} {:>7} {:>7} {:>6}", "trial", "w", "delta", "r0", "rms %", "Fp %", "plain %", "s");
    for f in files {
        let s = trial::read_trial(&f)?;
        let ph = trial::phases(&s, &f.display().to_string())?;
        let pts: Vec<Point> =
            s[ph.insertion.clone()].iter().map(|x| Point { position_mm: x.position_mm, force_n: x.force_n, line: x.line }).collect();
        let ev = events::punctures(&pts, events::EventRule::default());
        let Some(first) = ev.first() else {
            println!("{}: no puncture", f.display());
            continue;
        };
        let pre = &pts[..=first.peak];
        let t0 = Instant::now();
        let Some(fit) = shape::fit(pre, &surrogate, lambda) else {
            println!("{}: no fit", f.display());
            continue;
        };
        let secs = t0.elapsed().as_secs_f64();
        let peak = pre[pre.len() - 1];
        let thr = 0.05 * peak.force_n;
        let last_below = pre.iter().rposition(|p| p.force_n <= thr).unwrap_or(0);
        let window = &pre[last_below..];
        let rms = (window
            .iter()
            .map(|p| (shape::force_at(&fit, &surrogate, lambda, peak.position_mm, p.position_mm) - p.force_n).powi(2))
            .sum::<f64>()
            / window.len() as f64)
            .sqrt();
        let fp = fit.critical_force_n * (1.0 - fit.softening.fraction);
        // the same with w = 1 and no softening (today's shape)
        let plain = {
            let b: Vec<f64> = window.iter().map(|p| surrogate(p.position_mm - fit.onset_mm).max(0.0)).collect();
            let sc = b.iter().zip(window).map(|(x, p)| x * p.force_n).sum::<f64>() / b.iter().map(|x| x * x).sum::<f64>();
            (b.iter().zip(window).map(|(x, p)| (sc * x - p.force_n).powi(2)).sum::<f64>() / window.len() as f64).sqrt()
        };
        if std::env::var("PROFILE").is_ok() {
            let prof: Vec<String> = [0.1f64, 0.2, 0.3, 0.5, 0.7, 1.0]
                .iter()
                .map(|&t| {
                    shape::fit_members(pre, &surrogate, lambda, &[t]).map_or("-".into(), |f| {
                        let r = (window
                            .iter()
                            .map(|p| (shape::force_at(&f, &surrogate, lambda, peak.position_mm, p.position_mm) - p.force_n).powi(2))
                            .sum::<f64>()
                            / window.len() as f64)
                            .sqrt();
                        format!("w{:.2}:{:.2}%/d{:.2}", t * t, 100.0 * r / peak.force_n, f.softening.fraction)
                    })
                })
                .collect();
            println!("   {}", prof.join(" "));
        }
        println!(
            "{:<44} {:>6.3} {:>6.2} {:>5.2} {:>7.2} {:>7.2} {:>7.2} {:>6.3}  ({:.1} s)",
            f.file_name().map(|n| n.to_string_lossy().to_string()).unwrap_or_default(),
            fit.weight,
            fit.softening.fraction,
            fit.softening.onset_ratio,
            100.0 * rms / peak.force_n,
            100.0 * (fp - peak.force_n) / peak.force_n,
            100.0 * plain / peak.force_n,
            fit.scale,
            secs
        );
    }
    Ok(())
}
