//! `needle stack sample` (issue 65 item 3): a stack calibrated on several rig trials
//! (read in place from `../shared/data/stokes-needle-rig/`) carries its values' spread
//! beside it, and a tissue drawn within that spread is a valid stack, the same for the
//! same seed, within 2 standard deviations of the stack's values, and replays; a spread
//! file that does not fit the stack is refused with its `FILE:LINE`, nothing written.

mod common;
use common::{needle, shipped_set_arg, show};
use needle_calibrate::spread;
use needle_codegen::tissue::{parse_stack_str, Stack};
use std::path::{Path, PathBuf};

fn rig(name: &str) -> PathBuf {
    let p = needle_stdx::workspace_root().join("../shared/data/stokes-needle-rig").join(name);
    assert!(p.is_file(), "{}: the measured rig trials live beside the checkout", p.display());
    p
}

fn stack(path: &Path) -> Stack {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    parse_stack_str(&text, path).unwrap_or_else(|e| panic!("{e}"))
}

fn value(s: &Stack, r: &spread::Row) -> f64 {
    let l = &s.layers[r.layer];
    match r.key {
        "stiffness_scale" => l.stiffness_scale,
        "puncture_force_n" => l.puncture_force_n,
        "cutting_force_n" => l.cutting_force_n,
        _ => l.friction_coulomb_n_per_mm,
    }
}

fn sample(stack: &Path, seed: &str, out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args =
        vec!["stack", "sample", "--stack", stack.to_str().expect("utf-8"), "--seed", seed, "--out", out.to_str().expect("utf-8")];
    args.extend_from_slice(extra);
    needle(&args)
}

#[test]
fn a_tissue_drawn_within_the_spread_of_three_skin_trials() {
    let d = tempfile::tempdir().expect("tempdir");
    let out = d.path().join("skin.toml");
    let trials: Vec<String> =
        (1..=3).map(|k| rig(&format!("skin_2mmps_0deg_needle2_trial{k}.csv")).to_string_lossy().into_owned()).collect();
    let mut args = vec!["calibrate".to_string(), "--trials".into()];
    args.extend(trials);
    for a in ["--name", "skin", "--needle-diameter-mm", "1.27", "--write-on-miss", "--set", &shipped_set_arg()] {
        args.push(a.into());
    }
    args.extend([
        "--out".into(),
        out.to_string_lossy().into_owned(),
        "--figure".into(),
        d.path().join("skin.svg").to_string_lossy().into_owned(),
    ]);
    let o = needle(&args);
    let spread_file = d.path().join("skin.spread.csv");
    assert!(out.is_file() && spread_file.is_file(), "stack and spread written: {}", show(&o));
    let rows = spread::read(&spread_file).unwrap_or_else(|e| panic!("{e:#}"));
    let base = stack(&out);
    // every layer's scale was fitted on each of the three trials, and differs between them
    for k in 0..base.layers.len() {
        let r = rows.iter().find(|r| r.layer == k && r.key == "stiffness_scale").unwrap_or_else(|| panic!("layer {k}: {rows:?}"));
        assert!(r.trials == 3 && r.sd > 0.0, "{r:?}");
    }
    // the same seed, the same bytes; another seed, another tissue
    // (the second draw of seed 11 under the same name, in a folder of its own)
    std::fs::create_dir(d.path().join("again")).expect("mkdir");
    let (a, b, c) = (d.path().join("skin_a.toml"), d.path().join("again/skin_a.toml"), d.path().join("skin_c.toml"));
    for (seed, path) in [("11", &a), ("11", &b), ("12", &c)] {
        let o = sample(&out, seed, path, &[]);
        assert!(o.status.success(), "{}", show(&o));
    }
    let bytes = |p: &Path| std::fs::read_to_string(p).expect("written");
    assert_eq!(bytes(&a), bytes(&b), "seed 11 twice");
    assert_ne!(bytes(&a), bytes(&c), "seeds 11 and 12");
    for p in [&a, &c] {
        let drawn = stack(p);
        let mut moved = 0;
        for r in &rows {
            let (old, new) = (value(&base, r), value(&drawn, r));
            assert!(
                (new - old).abs() <= 2.0 * r.sd * (1.0 + 1e-9),
                "{}: layer {} {}: {old} -> {new}, sd {}",
                p.display(),
                r.layer,
                r.key,
                r.sd
            );
            moved += usize::from(new != old);
        }
        assert!(moved > rows.len() / 2, "{}: {moved} of {} values drawn", p.display(), rows.len());
        // it drives the library's insertion like any stack file
        let rp = needle(&[
            "replay",
            "--stack",
            p.to_str().expect("utf-8"),
            "--trial",
            &rig("skin_2mmps_0deg_needle2_trial4.csv").to_string_lossy(),
        ]);
        assert!(rp.status.success() && String::from_utf8_lossy(&rp.stdout).contains("puncture 1"), "{}", show(&rp));
    }
    // a spread row naming a layer the stack does not have: its FILE:LINE, nothing written
    let bad = d.path().join("bad.spread.csv");
    let n = base.layers.len();
    std::fs::write(&bad, format!("{}\n0,stiffness_scale,3,1.0,0.1\n{n},puncture_force_n,3,1.0,0.1\n", spread::HEADER)).expect("write");
    let never = d.path().join("never.toml");
    let o = sample(&out, "1", &never, &["--spread", bad.to_str().expect("utf-8")]);
    assert_eq!(o.status.code(), Some(2), "{}", show(&o));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains(&format!("{}:3: layer {n}", bad.display())), "{err}");
    assert!(!never.exists(), "nothing written on an error");
    // a negative standard deviation: the same
    std::fs::write(&bad, format!("{}\n0,stiffness_scale,3,1.0,-0.1\n", spread::HEADER)).expect("write");
    let o = sample(&out, "1", &never, &["--spread", bad.to_str().expect("utf-8")]);
    assert!(String::from_utf8_lossy(&o.stderr).contains(&format!("{}:2: sd -0.1", bad.display())), "{}", show(&o));
    assert!(!never.exists(), "nothing written on an error");
}
