//! `needle plot`: the committed figures of the default set are what a fresh rendering of
//! its model and FE runs gives (byte for byte), and a changed model makes them stale.

use std::path::Path;

mod common;
use common::{needle, shipped_set, show};

fn plot(args: &[&str]) -> std::process::Output {
    needle(&[&["plot"], args].concat())
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).expect("mkdir");
    for e in std::fs::read_dir(from).expect("read_dir").flatten() {
        let p = e.path();
        let name = e.file_name();
        if name.to_string_lossy().starts_with('.') {
            continue;
        }
        if p.is_dir() {
            copy_dir(&p, &to.join(&name));
        } else {
            std::fs::copy(&p, to.join(&name)).expect("copy");
        }
    }
}

/// The README and docs/usage.md show coeffs/default/figures: they must be current.
#[test]
fn committed_figures_are_up_to_date() {
    let set = shipped_set();
    let o = plot(&["--set", &set.to_string_lossy(), "--check"]);
    assert!(o.status.success(), "stale or missing figures (regenerate with `needle plot --set coeffs/default`):\n{}", show(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    for f in ["fig4-centre.svg", "fig6-forces.svg", "fig7-moments.svg", "fig8-validation.svg", "parity.svg", "fe-verification.svg"] {
        assert!(out.contains(&format!("{f}: up to date")), "{f} checked: {out}");
    }
}

/// The family figure with measured curves placed among its members
/// (`family-measured.svg`, issue 64 item 6) is what the command draws from Okamura's
/// curve and one rig trial of each sample (read in place from
/// `../shared/data/stokes-needle-rig/`: derived figures are committed, the data not),
/// with the command docs/usage.md gives.
#[test]
fn the_committed_family_figure_with_measured_shapes_is_up_to_date() {
    let set = shipped_set();
    let rig = needle_stdx::workspace_root().join("../shared/data/stokes-needle-rig");
    let files = [
        set.join("measured/okamura2004-bovine-liver/position_force.csv"),
        rig.join("skin_2mmps_0deg_needle2_trial1.csv"),
        rig.join("muscle_2mmps_0deg_needle2_trial1.csv"),
        rig.join("skin-on-muscle_2mmps_0deg_needle2_trial2.csv"),
    ];
    let mut args: Vec<String> = vec!["--set".into(), set.to_string_lossy().into_owned(), "--check".into(), "--measured".into()];
    args.extend(files.iter().map(|p| p.to_string_lossy().into_owned()));
    args.extend(["--needle-diameter-mm".into(), "1.27".into()]);
    let o = plot(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(o.status.success(), "{}", show(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("family-measured.svg: up to date"), "{out}");
    let svg = std::fs::read_to_string(set.join("figures/family-measured.svg")).expect("committed");
    for f in &files {
        let tail: Vec<String> = f.iter().rev().take(2).map(|c| c.to_string_lossy().into_owned()).collect();
        let label = format!("measured: {}/{}", tail[1], tail[0]);
        assert!(svg.contains(&label), "{label}: placed among the members");
    }
}

/// Changing one coefficient of model.toml changes the model curves: --check fails and
/// names the figure.
#[test]
fn a_changed_model_makes_the_figures_stale() {
    let d = tempfile::tempdir().expect("tempdir");
    let set = d.path().join("default");
    copy_dir(&shipped_set(), &set);
    let model = set.join("model.toml");
    let text = std::fs::read_to_string(&model).expect("model.toml");
    // the Fy baseline's constant term (second [[baseline]]) times 1.01, and its f32 twin
    let mut seen = 0;
    let mut new_f32: Option<f32> = None;
    let changed: Vec<String> = text
        .lines()
        .map(|l| {
            if l.starts_with("coeffs = [") {
                seen += 1;
                if seen == 2 {
                    let inner = l.trim_start_matches("coeffs = [").trim_end_matches(']');
                    let mut v: Vec<f64> = inner.split(',').map(|x| x.trim().parse().expect("number")).collect();
                    v[0] *= 1.01;
                    new_f32 = Some(v[0] as f32);
                    return format!("coeffs = [{}]", v.iter().map(|x| format!("{x:?}")).collect::<Vec<_>>().join(", "));
                }
            }
            if l.starts_with("coeffs_f32 = [") {
                if let Some(f) = new_f32.take() {
                    let rest = &l[l.find(',').expect("five values")..];
                    return format!("coeffs_f32 = [\"0x{:08x}\"{rest}", f.to_bits());
                }
            }
            l.to_string()
        })
        .collect();
    assert!(seen >= 2, "model.toml has baselines");
    std::fs::write(&model, changed.join("\n") + "\n").expect("write model.toml");
    let o = plot(&["--set", &set.to_string_lossy(), "--check"]);
    assert_eq!(o.status.code(), Some(1), "{}", show(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("fig4-centre.svg: stale"), "{}", show(&o));
    // and writing them makes the check pass again, deterministically
    let w = plot(&["--set", &set.to_string_lossy()]);
    assert!(w.status.success(), "{}", show(&w));
    let again = plot(&["--set", &set.to_string_lossy(), "--check"]);
    assert!(again.status.success(), "{}", show(&again));
}
