//! Issue 65's repeats goal on the rig's measured trials: in every group of at least three
//! trials (one sample, one speed, one needle), a stack calibrated on each pair of its
//! trials predicts each other trial of the group within 1.5 times the group's own spread
//! (`needle_calibrate::whole::repeats`: the pairwise RMS of its measured trials, each
//! phase aligned by its own coordinate, over the group's common window, in % of its mean
//! peak force; the prediction the RMS of the library's insertion driven by the trial's
//! measured position against time). Every pair -> trial ratio and each group's median
//! and worst are printed (`--nocapture`); a case that misses the goal fails unless it is
//! one of [`MISSED`], which are printed as `MISSED (issue 65, open)`.
mod common;

use common::{calibrate, name, prepare, replay};
use needle_calibrate::whole::repeats::{GroupSpread, Rms, RATIO_GOAL};
use std::path::PathBuf;

/// The cases that miss the goal today (`group: calibrated on -> predicted`; each one's
/// figures are printed): muscle 19 of 30 (ratio 1.52-3.09); every other group meets it in
/// every case (since the tent's level is met between the grid points,
/// `whole::tent::level_crossings`). Where they come from (the muscle's insertion, and its
/// withdrawal's pull, which lets go near the surface; the tent's level read over the
/// goals' withdrawal window, which costs the muscle's pull near its peak; the slow shaft
/// terms' own slip distances, which turn the withdrawal over as the rig's but cost the
/// skin's and the 3 mm/s pulls a little; the tent's stiffness refined between its grid
/// points, which gains three of the muscle's): `docs/insertion.md`, "Repeats". Not a
/// tolerance: every other case must meet the goal.
const MISSED: &[&str] = &[
    "muscle_2mmps_0deg_needle2: trial1+trial2 -> trial3",
    "muscle_2mmps_0deg_needle2: trial1+trial2 -> trial5",
    "muscle_2mmps_0deg_needle2: trial1+trial3 -> trial2",
    "muscle_2mmps_0deg_needle2: trial1+trial3 -> trial4",
    "muscle_2mmps_0deg_needle2: trial1+trial3 -> trial5",
    "muscle_2mmps_0deg_needle2: trial1+trial4 -> trial2",
    "muscle_2mmps_0deg_needle2: trial1+trial4 -> trial3",
    "muscle_2mmps_0deg_needle2: trial1+trial4 -> trial5",
    "muscle_2mmps_0deg_needle2: trial1+trial5 -> trial2",
    "muscle_2mmps_0deg_needle2: trial2+trial3 -> trial1",
    "muscle_2mmps_0deg_needle2: trial2+trial3 -> trial5",
    "muscle_2mmps_0deg_needle2: trial2+trial4 -> trial1",
    "muscle_2mmps_0deg_needle2: trial2+trial4 -> trial3",
    "muscle_2mmps_0deg_needle2: trial2+trial4 -> trial5",
    "muscle_2mmps_0deg_needle2: trial2+trial5 -> trial1",
    "muscle_2mmps_0deg_needle2: trial3+trial4 -> trial1",
    "muscle_2mmps_0deg_needle2: trial3+trial4 -> trial2",
    "muscle_2mmps_0deg_needle2: trial3+trial4 -> trial5",
    "muscle_2mmps_0deg_needle2: trial3+trial5 -> trial1",
];

/// The rig's trials by group: the file name without its `_trial<k>` (sample, speed,
/// angle, needle).
fn groups() -> Vec<(String, Vec<PathBuf>)> {
    let mut out: Vec<(String, Vec<PathBuf>)> = Vec::new();
    for f in common::all_trials() {
        let stem = f.file_stem().and_then(|s| s.to_str()).unwrap_or_default().to_string();
        let key = stem.rsplit_once("_trial").map_or(stem.clone(), |(g, _)| g.to_string());
        match out.iter_mut().find(|(g, _)| *g == key) {
            Some((_, files)) => files.push(f),
            None => out.push((key, vec![f])),
        }
    }
    out
}

/// `trial<k>` of a rig file name (the whole name when it has none).
fn short(f: &std::path::Path) -> String {
    let n = name(f);
    n.rsplit_once('_').map_or(n.clone(), |(_, t)| t.trim_end_matches(".csv").to_string())
}

/// An RMS and its phases, for the printed lines.
fn show(r: &Rms) -> String {
    let [i, h, w] = r.stage_pct;
    format!("{:.2} % (insertion {i:.2}, hold {h:.2}, withdrawal {w:.2})", r.all_pct)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        return f64::NAN;
    }
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Without the withdrawal: the insertion and the hold (a diagnosis, printed).
const NO_WITHDRAWAL: [bool; 3] = [true, true, false];

/// One prediction: its case name, its ratio, the ratio on the insertion and hold alone,
/// and its printed line.
struct Case {
    name: String,
    ratio: f64,
    no_withdrawal: f64,
    line: String,
}

/// One group: its spread, then every pair calibrated, held against itself (printed) and
/// each other trial predicted.
fn group_cases(key: &str, files: &[PathBuf]) -> Vec<Case> {
    let trials: Vec<_> = files.iter().map(|f| prepare(f)).collect();
    let spread = GroupSpread::of(&trials).unwrap_or_else(|| panic!("{key}: no spread over {} trials", trials.len()));
    // asserted: every phase is in the window and the spread is a positive number
    assert!(spread.window.reach.iter().all(Option::is_some), "{key}: a phase missing from the window: {:?}", spread.window);
    assert!(spread.rms.all_pct.is_finite() && spread.rms.all_pct > 0.0, "{key}: spread {:?}", spread.rms);
    let [d, h, w] = spread.window.reach.map(|r| r.unwrap_or(f64::NAN));
    eprintln!(
        "{key}: {} trials, window: insertion {d:.2} mm from contact, hold {h:.2} s, withdrawal {w:.2} mm; mean peak {:.3} N; spread (pairwise RMS) {}",
        trials.len(),
        spread.mean_peak_n,
        show(&spread.rms)
    );
    for p in &spread.pairs {
        eprintln!("  measured {} vs {}: RMS {}", short(&files[p.trials.0]), short(&files[p.trials.1]), show(&p.rms));
    }
    let (mut cases, mut own) = (Vec::new(), Vec::new());
    for a in 0..files.len() {
        for b in a + 1..files.len() {
            let started = std::time::Instant::now();
            let c = calibrate(&[files[a].clone(), files[b].clone()]);
            let secs = started.elapsed().as_secs_f64();
            for k in [a, b] {
                own.push(spread.ratio(&spread.model_rms(&trials[k], &replay(&c, &trials[k]))));
            }
            for (k, t) in trials.iter().enumerate().filter(|(k, _)| *k != a && *k != b) {
                let rms = spread.model_rms(t, &replay(&c, t));
                let ratio = spread.ratio(&rms);
                let no_withdrawal = rms.over(NO_WITHDRAWAL) / spread.rms.over(NO_WITHDRAWAL);
                let name = format!("{key}: {}+{} -> {}", short(&files[a]), short(&files[b]), short(&files[k]));
                let line = format!(
                    "{name}: model RMS {} / spread {:.2} % = {ratio:.3} (goal <= {RATIO_GOAL}; without the withdrawal {no_withdrawal:.3}; calibrated in {secs:.2} s)",
                    show(&rms),
                    spread.rms.all_pct
                );
                eprintln!("  {line} {}", if ratio <= RATIO_GOAL { "ok" } else { "MISSED" });
                cases.push(Case { name, ratio, no_withdrawal, line });
            }
        }
    }
    let ratios: Vec<f64> = cases.iter().map(|c| c.ratio).collect();
    let inner: Vec<f64> = cases.iter().map(|c| c.no_withdrawal).collect();
    let met = |v: &[f64]| v.iter().filter(|r| **r <= RATIO_GOAL).count();
    let worst = |v: &[f64]| v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    eprintln!(
        "{key}: {} of {} predictions met; ratio median {:.2}, worst {:.2}; the calibrated pairs on themselves: median {:.2}, worst {:.2}; without the withdrawal: {} met, median {:.2}, worst {:.2}",
        met(&ratios),
        ratios.len(),
        median(ratios.clone()),
        worst(&ratios),
        median(own.clone()),
        worst(&own),
        met(&inner),
        median(inner.clone()),
        worst(&inner)
    );
    cases
}

#[test]
fn repeats_predicted_within_the_groups_spread() {
    let mut all = Vec::new();
    for (key, files) in groups().into_iter().filter(|(_, f)| f.len() >= 3) {
        all.extend(group_cases(&key, &files));
    }
    // asserted: the rig's folder gave groups to test (a missing folder already failed)
    assert!(!all.is_empty(), "no group of three trials or more in {}", common::rig().display());
    let met = all.iter().filter(|c| c.ratio <= RATIO_GOAL).count();
    let inner = all.iter().filter(|c| c.no_withdrawal <= RATIO_GOAL).count();
    eprintln!("repeats: {met} of {} predictions within {RATIO_GOAL}x their group's spread (without the withdrawal: {inner})", all.len());
    let mut new = Vec::new();
    for c in &all {
        let listed = MISSED.contains(&c.name.as_str());
        if c.ratio <= RATIO_GOAL {
            if listed {
                eprintln!("met now (remove from MISSED): {}", c.line);
            }
        } else if listed {
            eprintln!("MISSED (issue 65, open): {}", c.line);
        } else {
            new.push(c.line.clone());
        }
    }
    // asserted: every case meets the goal but the listed ones (NaN is a miss)
    assert!(new.is_empty(), "new misses of the repeats goal:\n{}", new.join("\n"));
}
