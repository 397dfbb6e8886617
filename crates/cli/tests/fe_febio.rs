//! `needle fe run --solver febio` and `needle fe verify --punch --solver febio` end to end
//! on FEBio 4 (input -> febio4 -> logs -> CSV and manifest): a smoke campaign of the
//! shipped default set on the smoke mesh, the flat punch with the campaign's element on
//! a coarse mesh, a bad `FEBIO` path, and a run that fails inside a campaign that goes
//! on. They need `febio4` (`.ci/install-febio`, which `.ci/test` runs first); without it
//! they fail, they are not skipped.

mod common;
use common::{campaign_copy, needle_env, show};

use needle_fe::febio;
use needle_fe::verify::{self, VerifyOptions};
use needle_set::manifest::{read_manifest, MANIFEST};
use needle_set::results;
use needle_set::spec::Engine;
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Output;

/// The FEBio these tests run, and its version.
fn require_febio() -> (PathBuf, String) {
    let p = febio::find_febio().unwrap_or_else(|e| panic!("{e:#}: these tests run FEBio (.ci/install-febio)"));
    let v = febio::febio_version(&p).unwrap_or_else(|e| panic!("{e:#}"));
    assert!(v.starts_with("4."), "febio version {v}");
    (p, v)
}

/// [`campaign_copy`] with its fe/ folder.
fn febio_set() -> (tempfile::TempDir, PathBuf) {
    let (d, set) = campaign_copy();
    std::fs::create_dir_all(set.join("fe")).expect("mkdir");
    (d, set)
}

/// `needle fe run --set <set> <args>` with extra environment variables.
fn fe_run(args: &[&str], set: &Path, env: &[(&str, &str)]) -> Output {
    let mut all: Vec<&OsStr> = ["fe", "run", "--set"].into_iter().map(OsStr::new).collect();
    all.push(set.as_os_str());
    all.extend(args.iter().map(OsStr::new));
    needle_env(&all, env)
}

/// Smoke campaign: three poses (quarter and two half models) on the smoke mesh, 10 load
/// steps. Contact must be found (Fy grows with depth, a few hundredths of a newton at
/// 6 mm: the committed mesh gives 0.065 N), mirror-odd components exactly zero, and the
/// manifest says which engine, version and element made each CSV.
#[test]
fn smoke_campaign_on_febio() {
    let (_, version) = require_febio();
    let (_d, set) = febio_set();
    let o = fe_run(
        &["--solver", "febio", "--mesh", "smoke", "--steps", "10", "--only", "centre,z+02,tx+04", "--jobs", "2", "--threads", "1"],
        &set,
        &[],
    );
    assert!(o.status.success(), "{}", show(&o));
    let m = read_manifest(&set.join("fe").join(MANIFEST)).expect("manifest");
    assert_eq!(m.pose.keys().cloned().collect::<Vec<_>>(), ["centre", "tx+04", "z+02"]);
    for (name, e) in &m.pose {
        assert_eq!((e.engine.as_str(), e.engine_version.as_str()), ("febio", version.as_str()), "{name}");
        assert!(e.element.contains("three-field"), "{name}: {}", e.element);
        assert!(e.solver_settings.contains("sliding-elastic"), "{name}: {}", e.solver_settings);
        let rows = results::read_csv(&set.join("fe").join(format!("{name}.csv"))).expect("csv");
        assert_eq!(rows.len(), 11, "{name}: 10 steps + depth 0");
        let fy: Vec<f64> = rows.iter().map(needle_set::results::Row::fy_n).collect();
        assert!(fy.windows(2).skip(1).all(|w| w[1] > w[0]), "{name}: Fy grows with depth: {fy:?}");
        let last = rows.last().expect("rows").wrench;
        assert!(last[1] > 0.03 && last[1] < 0.15, "{name}: Fy at 6 mm {} N", last[1]);
        // z+02 and tx+04 keep the mirror plane x = 0 (Fx, My, Mz vanish); centre both
        assert_eq!((last[0], last[4], last[5]), (0.0, 0.0, 0.0), "{name}: {last:?}");
    }
    // tilted about x: a lateral force along z and a moment about x about the hub
    let tx = results::read_csv(&set.join("fe").join("tx+04.csv")).expect("csv");
    let w = tx.last().expect("rows").wrench;
    assert!(w[2].abs() > 1e-4 && w[3].abs() > 1e-3, "tx+04: Fz {} N, Mx {} N*mm", w[2], w[3]);
}

/// A `FEBIO` that is not an executable is an error that names it, before any solve.
#[test]
fn a_bad_febio_path_is_a_clear_error() {
    let (_d, set) = febio_set();
    let o =
        fe_run(&["--solver", "febio", "--mesh", "smoke", "--steps", "2", "--only", "centre"], &set, &[("FEBIO", "/nonexistent/febio4")]);
    assert_eq!(o.status.code(), Some(2), "{}", show(&o));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("FEBIO=/nonexistent/febio4: not an executable"), "{err}");
    assert!(!set.join("fe").join("centre.csv").exists());
}

/// A solve that fails (here: a wrapper around the real febio4 that reports an error
/// termination for one pose, as a crash or a diverged run does) is reported with
/// FEBio's words and each attempt's log and input kept, is retried four times (the
/// ladder of `FebioBackend::attempts`: the other projection rule, quarter first
/// increments, both, a softer contact penalty; on the full block the projection rules
/// swap), and the campaign finishes the other poses.
#[test]
fn a_failing_run_keeps_its_log_and_the_campaign_goes_on() {
    let (real, _) = require_febio();
    let (d, set) = febio_set();
    let wrapper = d.path().join("febio4-failing-on-z02");
    std::fs::write(
        &wrapper,
        format!(
            "#!/bin/sh\nif grep -q -e 'pose \"z+02\"' -e 'pose \"t2-a\"' pose.feb 2>/dev/null; then\n  echo ' *                                ERROR                                  *' > pose.log\n  echo ' * Fake divergence for the test.                                         *' >> pose.log\n  echo ' *************************************************************************' >> pose.log\n  echo ' E R R O R   T E R M I N A T I O N' >> pose.log\n  exit 1\nfi\nexec {} \"$@\"\n",
            real.display()
        ),
    )
    .expect("write wrapper");
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&wrapper, std::fs::Permissions::from_mode(0o755)).expect("chmod");
    let w = wrapper.to_string_lossy().into_owned();
    let o = fe_run(
        &["--solver", "febio", "--mesh", "smoke", "--steps", "10", "--only", "centre,z+02,t2-a", "--threads", "1"],
        &set,
        &[("FEBIO", &w)],
    );
    assert_eq!(o.status.code(), Some(1), "{}", show(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("FAILED z+02") && out.contains("Fake divergence for the test."), "{}", show(&o));
    for (n, first) in [(1, "1"), (2, "0.25"), (3, "0.25"), (4, "0.25")] {
        assert!(out.contains(&format!("retry {n} (first increment {first})")), "retry {n}: {out}");
    }
    assert!(set.join("fe").join("centre.csv").exists(), "the other pose is solved");
    assert!(!set.join("fe").join("z+02.csv").exists());
    assert!(out.contains("FAILED t2-a"), "{}", show(&o));
    assert!(!set.join("fe").join("t2-a.csv").exists());
    let kept = set.join("fe").join(".work").join("z+02");
    for attempt in 1..=5 {
        for ext in ["log", "feb"] {
            let f = kept.join(format!("failed-attempt-{attempt}.{ext}"));
            assert!(f.exists(), "{} kept", f.display());
        }
    }
    let feb = |n: u32| std::fs::read_to_string(kept.join(format!("failed-attempt-{n}.feb"))).unwrap_or_default();
    let value = |t: &str, tag: &str| {
        let l = t.lines().find(|l| l.contains(&format!("<{tag}>")))?;
        l.trim().trim_start_matches(&format!("<{tag}>")).trim_end_matches(&format!("</{tag}>")).parse::<f64>().ok()
    };
    let (p1, p5) = (value(&feb(1), "penalty"), value(&feb(5), "penalty"));
    assert!(
        matches!((p1, p5), (Some(a), Some(b)) if (b / a - 0.1).abs() < 1e-12),
        "the last attempt's contact is 10x softer: {p1:?} -> {p5:?}"
    );
    let seg_up: Vec<Option<f64>> = (1..=5).map(|n| value(&feb(n), "seg_up")).collect();
    assert_eq!(
        seg_up,
        [Some(5.0), Some(0.0), Some(5.0), Some(0.0), Some(5.0)],
        "seg_up of campaign.toml, then retry_seg_up on attempts 2 and 4"
    );
    // the full block (t2-a: no mirror plane) takes the projection rules the other way round
    let full = set.join("fe").join(".work").join("t2-a");
    let seg_up_full: Vec<Option<f64>> = (1..=5)
        .map(|n| value(&std::fs::read_to_string(full.join(format!("failed-attempt-{n}.feb"))).unwrap_or_default(), "seg_up"))
        .collect();
    assert_eq!(
        seg_up_full,
        [Some(0.0), Some(5.0), Some(0.0), Some(5.0), Some(5.0)],
        "full block: retry_seg_up on attempts 1 and 3, seg_up of campaign.toml on 2, 4 and 5"
    );
    // attempt 1: whole steps (10 of 0.6 mm); it failed before its first must point, at
    // first contact, so attempt 2 (whole steps, the other rule) takes the first-contact
    // steps (`first_contact_depth_mm` 0.6, `first_contact_step_fraction` 0.25: 40 time
    // steps of 0.15 mm to 6 mm, the first load step's capped at 0.15 mm, whole after);
    // from attempt 3 on a quarter first increment with the retry tolerances and no cap
    // (ladder.rs; no attempt reached a must point, so none is continued)
    let steps: Vec<Option<f64>> = (1..=5).map(|n| value(&feb(n), "time_steps")).collect();
    assert_eq!(steps, [Some(10.0), Some(40.0), Some(40.0), Some(40.0), Some(40.0)], "{steps:?}");
    let capped: Vec<bool> = (1..=5).map(|n| feb(n).contains("<pt>0.6,0.15</pt>") && feb(n).contains("<pt>1.2,0.6</pt>")).collect();
    assert_eq!(capped, [false, true, false, false, false], "first-contact steps after a failure there, on whole-step attempts");
    let dtol: Vec<Option<f64>> = (1..=5).map(|n| value(&feb(n), "dtol")).collect();
    assert_eq!(dtol, [Some(1e-3), Some(1e-3), Some(0.0), Some(0.0), Some(0.0)], "the retry tolerances from attempt 3 on");
}

/// Tolerance of the coarse FEBio punch, %. `punch_mesh_scale = 2` (8 hex8 elements across
/// the punch, h = a/4) measured +4.90 % (FEBio 4.11; the verification mesh, 16 across:
/// +2.55 %). The rim's stress singularity makes the error first order in h; 8 % leaves
/// 3 points for solver and platform differences, while a wrong modulus, boundary
/// condition, symmetry factor, reaction sign or sum moves it by far more (the locking
/// C3D8 of ccx is +19 %).
const COARSE_TOLERANCE_PERCENT: f64 = 8.0;

#[test]
fn coarse_flat_punch_with_the_febio_element_matches_sneddon() {
    require_febio();
    let (_d, set) = febio_set();
    let opts = VerifyOptions {
        set_dir: set.clone(),
        punch: true,
        mesh: None,
        edge: None,
        mirror: false,
        smooth: false,
        scaling: None,
        work_dir: None,
        punch_mesh_scale: 2.0,
        punch_campaign_element: false,
        threads: 1,
        engine: Some(Engine::Febio),
    };
    let folder = needle_set::set_folder::SetFolder::open(&opts.set_dir).unwrap_or_else(|e| panic!("{e:#}"));
    let (r, _) = verify::run(&folder, &opts).unwrap_or_else(|e| panic!("{e:#}"));
    let p = r.punch.expect("a punch report");
    assert!(p.check.element.contains("FEBio hex8"), "{}", p.check.element);
    assert!(p.solver.starts_with("febio 4."), "{}", p.solver);
    assert!(
        p.check.force_block_n > p.check.force_block_2x_n && p.check.force_block_2x_n > p.check.force_half_space_n,
        "F(1x) {} > F(2x) {} > F(inf) {} expected",
        p.check.force_block_n,
        p.check.force_block_2x_n,
        p.check.force_half_space_n
    );
    assert!(
        p.check.error_percent.abs() <= COARSE_TOLERANCE_PERCENT,
        "coarse FEBio flat punch: F(half-space) = {} N against Sneddon {} N: {:+.2}%, tolerance {COARSE_TOLERANCE_PERCENT}%",
        p.check.force_half_space_n,
        p.force_sneddon_n,
        p.check.error_percent
    );
    println!("coarse FEBio punch: {:+.2}%", p.check.error_percent);
}
