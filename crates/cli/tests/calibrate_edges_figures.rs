//! `needle calibrate` on measured data: a fitted shape value on its range's edge is said
//! (issue 64, bad input), and the figures of a calibration (issue 64 item 6, issue 65
//! item 6) are written with their panels and ticks as people read numbers. The rig
//! trials are read in place from `../shared/data/stokes-needle-rig/` (no licence to copy
//! them); Okamura's curve is the shipped set's.

mod common;
use common::{needle, shipped_set, shipped_set_arg, show};
use std::path::{Path, PathBuf};

fn rig(name: &str) -> PathBuf {
    let p = needle_stdx::workspace_root().join("../shared/data/stokes-needle-rig").join(name);
    assert!(p.is_file(), "{}: the measured rig trials live beside the checkout", p.display());
    p
}

fn okamura() -> PathBuf {
    shipped_set().join("measured/okamura2004-bovine-liver/position_force.csv")
}

/// The smallest member the family law was fitted on (`family.toml`, written by `needle
/// fit` from the FE runs): the lower edge of the member's range.
fn softest_fitted_member() -> f64 {
    let text = std::fs::read_to_string(shipped_set().join("family.toml")).expect("family.toml");
    let line = text.lines().find_map(|l| l.strip_prefix("fitted_weights = [")).expect("family.toml: fitted_weights");
    line.trim_end_matches(']').split(',').map(|w| w.trim().parse::<f64>().expect("a weight")).fold(f64::INFINITY, f64::min)
}

/// The text of every `<text>` element of an SVG.
fn svg_texts(svg: &str) -> Vec<String> {
    svg.split("<text")
        .skip(1)
        .filter_map(|s| s.split_once('>'))
        .filter_map(|(_, rest)| rest.split_once("</text>"))
        .map(|(t, _)| t.trim().to_string())
        .collect()
}

/// Every numeric label (a tick) reads as people write numbers: no exponent, no
/// trailing zeros after a decimal point (`5.000e0`, `2.50`); returns how many there are.
fn assert_human_ticks(svg: &str, what: &str) -> usize {
    let ticks: Vec<String> = svg_texts(svg).into_iter().filter(|t| t.parse::<f64>().is_ok()).collect();
    for t in &ticks {
        assert!(!t.contains(['e', 'E']), "{what}: tick label {t:?} in exponent form");
        assert!(!(t.contains('.') && t.ends_with('0')), "{what}: tick label {t:?} with trailing zeros");
    }
    ticks.len()
}

fn calibrate_trials(dir: &Path, trials: &[PathBuf], extra: &[&str]) -> std::process::Output {
    let (out, fig) = (dir.join("rig.toml"), dir.join("rig.svg"));
    let mut args: Vec<String> = vec!["calibrate".into(), "--trials".into()];
    args.extend(trials.iter().map(|p| p.to_string_lossy().into_owned()));
    for a in ["--name", "rig", "--needle-diameter-mm", "1.27", "--write-on-miss", "--set"] {
        args.push(a.into());
    }
    args.push(shipped_set_arg());
    args.extend(["--out".into(), out.to_string_lossy().into_owned(), "--figure".into(), fig.to_string_lossy().into_owned()]);
    args.extend(extra.iter().map(|s| (*s).to_string()));
    needle(&args)
}

fn warnings(stdout: &str) -> Vec<&str> {
    stdout.lines().filter(|l| l.starts_with("warning: ")).collect()
}

/// Skin, trial 1: its pre-puncture curve stiffens less than every member the FE covers,
/// so the fit lands on the softest one and says so, in the text and in the JSON.
#[test]
fn a_rig_trial_fitted_on_the_softest_member_is_warned_about() {
    let d = tempfile::tempdir().expect("tempdir");
    let trial = rig("skin_2mmps_0deg_needle2_trial1.csv");
    let lo = softest_fitted_member();
    let o = calibrate_trials(d.path(), std::slice::from_ref(&trial), &[]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    let w = warnings(&stdout);
    let member = w.iter().find(|l| l.contains("family_weight = ")).unwrap_or_else(|| panic!("no member warning:\n{}", show(&o)));
    assert!(member.contains(&format!("family_weight = {lo} ")), "the value: {member}");
    assert!(member.contains(&format!("lower edge of its range {lo} to 1 (dimensionless)")), "the range and unit: {member}");
    assert!(member.contains("1 of 1 trials"), "{member}");
    // the JSON carries the same, with its numbers
    let j = calibrate_trials(d.path(), &[trial], &["--json", "--force"]);
    let doc: serde_json::Value = serde_json::from_slice(&j.stdout).unwrap_or_else(|e| panic!("{e}\n{}", show(&j)));
    let ws = doc["warnings"].as_array().expect("warnings");
    let m = ws.iter().find(|w| w["key"] == "family_weight").unwrap_or_else(|| panic!("{ws:?}"));
    // the scan's grid is sqrt(w): its squares carry round-off (0.1 * 0.1)
    let near = |v: &serde_json::Value, want: f64| v.as_f64().is_some_and(|x| (x - want).abs() < 1e-12);
    assert!(near(&m["value"], lo) && m["edge"] == "lower" && m["unit"] == "(dimensionless)", "{m}");
    assert!(near(&m["range"][0], lo) && near(&m["range"][1], 1.0), "{m}");
    assert!(String::from_utf8_lossy(&j.stderr).contains("warning: family_weight"), "{}", show(&j));
}

/// Muscle, trial 1: its member lies inside the range (and its softening's onset too):
/// no warning, in the text or in the JSON.
#[test]
fn a_rig_trial_fitted_inside_the_range_has_no_warning() {
    let d = tempfile::tempdir().expect("tempdir");
    let trial = rig("muscle_2mmps_0deg_needle2_trial1.csv");
    let o = calibrate_trials(d.path(), std::slice::from_ref(&trial), &[]);
    assert!(String::from_utf8_lossy(&o.stdout).contains("wrote "), "a stack was fitted and written: {}", show(&o));
    assert_eq!(warnings(&String::from_utf8_lossy(&o.stdout)), Vec::<&str>::new(), "{}", show(&o));
    let j = calibrate_trials(d.path(), &[trial], &["--json", "--force"]);
    let doc: serde_json::Value = serde_json::from_slice(&j.stdout).unwrap_or_else(|e| panic!("{e}\n{}", show(&j)));
    assert_eq!(doc["warnings"].as_array().map(Vec::len), Some(0), "{}", doc["warnings"]);
}

/// Okamura's liver: the least-squares best member is the paper's tissue itself, the
/// range's upper edge (the family has no stiffer member): said once, with the range.
#[test]
fn okamura_s_curve_on_the_paper_s_tissue_says_it_is_the_upper_edge() {
    let d = tempfile::tempdir().expect("tempdir");
    let (out, fig) = (d.path().join("liver.toml"), d.path().join("liver.svg"));
    let o = needle(&[
        "calibrate",
        "--curve",
        &okamura().to_string_lossy(),
        "--name",
        "liver",
        "--needle-diameter-mm",
        "1.27",
        "--speed-mm-per-s",
        "3",
        "--set",
        &shipped_set_arg(),
        "--out",
        &out.to_string_lossy(),
        "--figure",
        &fig.to_string_lossy(),
    ]);
    assert!(o.status.success(), "{}", show(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    let w = warnings(&stdout);
    assert_eq!(w.len(), 1, "{}", show(&o));
    assert!(
        w[0].contains("family_weight = 1 ") && w[0].contains(&format!("upper edge of its range {} to 1", softest_fitted_member())),
        "{}",
        w[0]
    );
    // the figure: the curve and its residual, the shape before the first puncture and its residual
    let svg = std::fs::read_to_string(&fig).expect("figure written");
    let texts = svg_texts(&svg);
    let titles = [
        "axial force against needle position",
        "residual: measured - model",
        "before the first puncture: member w = 1",
        "before the first puncture: residual",
    ];
    for t in titles {
        assert_eq!(texts.iter().filter(|x| x.contains(t)).count(), 1, "panel {t:?} once: {texts:?}");
    }
    assert!(assert_human_ticks(&svg, "liver figure") >= 16, "four panels with their ticks");
    // the figure docs/insertion.md shows is this one (regenerate it with the command
    // there, `--figure coeffs/default/figures/calibration-liver.svg`)
    let committed = std::fs::read_to_string(shipped_set().join("figures/calibration-liver.svg")).expect("committed figure");
    assert!(committed == svg, "coeffs/default/figures/calibration-liver.svg is stale: rerun docs/insertion.md's needle calibrate");
    // --json: the same warning with its numbers, the model per measured point
    let j = needle(&[
        "calibrate",
        "--curve",
        &okamura().to_string_lossy(),
        "--name",
        "liver",
        "--needle-diameter-mm",
        "1.27",
        "--speed-mm-per-s",
        "3",
        "--set",
        &shipped_set_arg(),
        "--out",
        &out.to_string_lossy(),
        "--figure",
        &fig.to_string_lossy(),
        "--force",
        "--json",
    ]);
    let doc: serde_json::Value = serde_json::from_slice(&j.stdout).unwrap_or_else(|e| panic!("{e}\n{}", show(&j)));
    let ws = doc["warnings"].as_array().expect("warnings");
    assert!(ws.len() == 1 && ws[0]["key"] == "family_weight" && ws[0]["edge"] == "upper" && ws[0]["value"] == 1.0, "{ws:?}");
    let points = std::fs::read_to_string(okamura()).expect("curve").lines().skip(1).filter(|l| !l.trim().is_empty()).count();
    assert_eq!(doc["model"]["rows"].as_array().map(Vec::len), Some(points), "one model row per measured point");
}

/// A whole-trial calibration's figure: per trial the force against time, the residual,
/// and the rise before the first puncture against depth; the phases and punctures in
/// the legend; `needle replay --figure` draws one
/// trial through a stack file the same way.
#[test]
fn a_whole_trial_calibration_writes_its_figure() {
    let d = tempfile::tempdir().expect("tempdir");
    let trials = [rig("skin_2mmps_0deg_needle2_trial4.csv"), rig("skin_2mmps_0deg_needle2_trial5.csv")];
    let o = calibrate_trials(d.path(), &trials, &[]);
    let fig = d.path().join("rig.svg");
    assert!(String::from_utf8_lossy(&o.stdout).contains(&format!("wrote {}", fig.display())), "{}", show(&o));
    let svg = std::fs::read_to_string(&fig).expect("figure written");
    let texts = svg_texts(&svg);
    let count = |s: &str| texts.iter().filter(|x| x.contains(s)).count();
    assert_eq!(count("axial force against time (insertion, hold, withdrawal)"), 2, "{texts:?}");
    assert_eq!(texts.iter().filter(|x| x.ends_with(".csv: residual, measured - model")).count(), 2, "{texts:?}");
    assert_eq!(count("before the first puncture, against depth"), 2, "{texts:?}");
    assert_eq!(count("first layer: member w = "), 1, "the caption names the shape: {texts:?}");
    for legend in ["measured punctures", "model punctures", "hold starts", "withdrawal starts", "model (calibrated stack)"] {
        assert_eq!(count(legend), 2, "{legend} in each trial's panel: {texts:?}");
    }
    assert!(assert_human_ticks(&svg, "trials figure") >= 30, "six panels with their ticks");
    // the stack just written, replayed on a third repeat, with its figure
    let replayed = d.path().join("replay.svg");
    let r = needle(&[
        "replay",
        "--stack",
        &d.path().join("rig.toml").to_string_lossy(),
        "--trial",
        &rig("skin_2mmps_0deg_needle2_trial1.csv").to_string_lossy(),
        "--figure",
        &replayed.to_string_lossy(),
        "--json",
    ]);
    assert!(r.status.success(), "{}", show(&r));
    let svg = std::fs::read_to_string(&replayed).expect("replay figure written");
    assert_eq!(svg_texts(&svg).iter().filter(|x| x.contains("axial force against time")).count(), 1);
    assert_human_ticks(&svg, "replay figure");
    // an existing figure is refused without --force, before the run
    let again = needle(&[
        "replay",
        "--stack",
        &d.path().join("rig.toml").to_string_lossy(),
        "--trial",
        &rig("skin_2mmps_0deg_needle2_trial1.csv").to_string_lossy(),
        "--figure",
        &replayed.to_string_lossy(),
    ]);
    assert_eq!(again.status.code(), Some(2), "{}", show(&again));
}

/// The shipped rig-derived stack (`coeffs/default/calibrated/rig_skin_2mmps_t1.toml`,
/// coeffs/README.md) and its committed spread and figure are what its command writes.
#[test]
fn the_shipped_rig_stack_s_spread_and_figure_are_up_to_date() {
    let d = tempfile::tempdir().expect("tempdir");
    let out = d.path().join("rig_skin_2mmps_t1.toml");
    let fig = d.path().join("fig.svg");
    let trial = rig("skin_2mmps_0deg_needle2_trial1.csv");
    let o = needle(&[
        "calibrate",
        "--trials",
        &trial.to_string_lossy(),
        "--name",
        "rig_skin_2mmps_t1",
        "--needle-diameter-mm",
        "1.27",
        "--write-on-miss",
        "--set",
        &shipped_set_arg(),
        "--out",
        &out.to_string_lossy(),
        "--figure",
        &fig.to_string_lossy(),
    ]);
    let set = shipped_set();
    let pairs = [
        (out.clone(), set.join("calibrated/rig_skin_2mmps_t1.toml")),
        (d.path().join("rig_skin_2mmps_t1.spread.csv"), set.join("calibrated/rig_skin_2mmps_t1.spread.csv")),
        (fig, set.join("figures/calibration-rig_skin_2mmps_t1.svg")),
    ];
    for (fresh, committed) in pairs {
        let a = std::fs::read_to_string(&fresh).unwrap_or_else(|e| panic!("{}: {e}\n{}", fresh.display(), show(&o)));
        let b = std::fs::read_to_string(&committed).unwrap_or_else(|e| panic!("{}: {e}", committed.display()));
        // the stack's header names the trial as given; compare from its first value on
        let body = |t: &str| t.lines().filter(|l| !l.starts_with("# Trials:")).collect::<Vec<_>>().join("\n");
        assert!(body(&a) == body(&b), "{} is stale: rerun coeffs/README.md's command for it", committed.display());
    }
}
