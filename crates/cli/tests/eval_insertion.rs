//! `needle eval --poses FILE --insertion STACK`: a scripted insertion, one row per tick,
//! equal to the library's insertion model run on the same rows; bad scripts refused
//! with their line.
use needle_haptics::insertion::{stacks, Insertion, InsertionConfig};
use needle_haptics::Pose;

mod common;
use common::{needle, shipped_set_arg};

/// The script file of `poses`, one tick of 1 ms each, and the poses.
fn script_of(poses: Vec<Pose>) -> (String, Vec<Pose>) {
    let mut text = String::from("time_s,x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm\n");
    for (k, p) in (0u32..).zip(&poses) {
        let t = f64::from(k) * 0.001;
        text.push_str(&format!("{t},{:?},{:?},{:?},{:?},{:?}\n", p.x_mm, p.z_mm, p.theta_x_deg, p.theta_z_deg, p.depth_mm));
    }
    (text, poses)
}

/// `needle eval --poses <dir>/<name> --insertion liver` plus `extra`, the script written first.
fn eval_liver(dir: &std::path::Path, name: &str, text: &str, extra: &[&str]) -> std::process::Output {
    let file = dir.join(name);
    std::fs::write(&file, text).expect("script");
    let set = shipped_set_arg();
    let mut args = vec!["eval", "--set", &set, "--poses", file.to_str().expect("path"), "--insertion", "liver"];
    args.extend_from_slice(extra);
    needle(&args)
}

/// The fy_n column of an insertion's output rows.
fn fy_column(out: &std::process::Output) -> Vec<f32> {
    String::from_utf8_lossy(&out.stdout).lines().skip(1).map(|r| r.split(',').nth(7).expect("fy").parse().expect("fy")).collect()
}

/// A script in and out of the stack at 10 mm/s, 1 kHz.
fn script() -> (String, Vec<Pose>) {
    script_of(
        (0..8000u32)
            .map(|k| {
                let d = if k < 4000 { -1.0 + 0.01 * f64::from(k) } else { 39.0 - 0.01 * f64::from(k - 4000) };
                Pose { x_mm: 1.0, z_mm: -0.5, theta_x_deg: 2.0, theta_z_deg: -1.0, depth_mm: d as f32 }
            })
            .collect(),
    )
}

#[test]
fn a_scripted_insertion_gives_the_librarys_ticks() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (text, poses) = script();
    let out = eval_liver(dir.path(), "script.csv", &text, &[]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout);
    let rows: Vec<&str> = stdout.lines().skip(1).collect();
    assert_eq!(rows.len(), poses.len(), "one row per tick");
    let stack = stacks::ALL.iter().find(|s| s.name == "liver").expect("liver");
    let mut ins = Insertion::new(stack, InsertionConfig { period_s: 0.001, ..InsertionConfig::DEFAULT_1KHZ }).expect("stack");
    let mut punctures = 0;
    for (row, p) in rows.iter().zip(&poses) {
        let e = ins.step(p);
        let cells: Vec<&str> = row.split(',').collect();
        let fy: f32 = cells[7].parse().expect("fy");
        assert_eq!(fy.to_bits(), e.wrench.fy_n.to_bits(), "row {row}");
        punctures += u32::from(e.punctures);
        assert_eq!(cells[14].parse::<u8>().expect("punctures"), e.punctures, "row {row}");
    }
    assert!(punctures > 0, "the script punctures");
}

/// Issue 66: a script whose depth jumps to 1e6 mm for one tick and whose x jumps 30 mm in
/// one tick: the rows are not integrated (the wrench of the row before, 0 punctures), the
/// `flags` column says why and stderr names the flags with their first row.
#[test]
fn a_glitch_in_a_script_is_flagged_and_named() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (_, mut poses) = script();
    poses[3000].depth_mm = 1.0e6;
    poses[3500].x_mm += 30.0;
    let (text, poses) = script_of(poses);
    let out = eval_liver(dir.path(), "glitch.csv", &text, &[]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.lines().next().expect("header").ends_with(",punctures,flags"), "{stdout:.200}");
    let rows: Vec<Vec<&str>> = stdout.lines().skip(1).map(|r| r.split(',').collect()).collect();
    assert_eq!(rows.len(), poses.len());
    for (k, want) in [(3000, "0x02"), (3500, "0x01")] {
        assert_eq!(rows[k][15], want, "row {k}: the flags");
        assert_eq!(rows[k][14], "0", "row {k}: no puncture");
        assert_eq!(rows[k][6..12], rows[k - 1][6..12], "row {k}: the wrench of the row before");
    }
    assert!(rows.iter().enumerate().all(|(k, r)| k == 3000 || k == 3500 || r[15] == "0x00"), "only the glitch rows are flagged");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("FAST_MOTION in 1 ticks (first at row 3501)") && stderr.contains("OUT_OF_DOMAIN in 1 ticks (first at row 3001)"),
        "{stderr}"
    );
}

#[test]
fn bad_scripts_are_refused_with_their_line() {
    let dir = tempfile::tempdir().expect("temp dir");
    let cases = [
        ("x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm\n0,0,0,0,1\n0,0,0,0,2\n", "no column \"time_s\""),
        (
            "time_s,x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm\n0,0,0,0,0,1\n0.001,0,0,0,0,2\n0.003,0,0,0,0,3\n",
            "script.csv:4: column time_s: step",
        ),
        ("time_s,x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm\n0,0,0,0,0,1\nabc,0,0,0,0,2\n", "script.csv:3: column time_s"),
        ("time_s,x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm\n0,0,0,0,0,1\n", "at least two"),
    ];
    for (text, want) in cases {
        let file = dir.path().join("script.csv");
        std::fs::write(&file, text).expect("script");
        let out = needle(&["eval", "--set", &shipped_set_arg(), "--poses", file.to_str().expect("path"), "--insertion", "liver"]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{want}: accepted");
        assert!(stderr.contains(want), "{want}: {stderr}");
    }
    let file = dir.path().join("script.csv");
    std::fs::write(&file, "time_s,x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm\n0,0,0,0,0,1\n0.001,0,0,0,0,2\n").expect("script");
    let out = needle(&["eval", "--set", &shipped_set_arg(), "--poses", file.to_str().expect("path"), "--insertion", "no_such"]);
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("no such tissue file, nor a stack of the compiled-in set"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// In at 5 mm/s to 3 mm (the liver's first boundary deflected, not punctured), held 2 s.
fn stop_script() -> (String, Vec<Pose>) {
    script_of((0..3000u32).map(|k| Pose { depth_mm: (-1.0 + 0.005 * f64::from(k)).min(3.0) as f32, ..Pose::default() }).collect())
}

#[test]
fn prony_terms_make_the_scripted_insertion_relax_as_the_library_does() {
    use needle_haptics::insertion::{Layer, Stack};
    use needle_haptics::viscoelastic::{PronyTerm, PronyTerms};
    let dir = tempfile::tempdir().expect("temp dir");
    let (text, poses) = stop_script();
    let out = eval_liver(dir.path(), "stop.csv", &text, &["--prony", "0.6:0.5, 0.4:5"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let fy = fy_column(&out);
    let terms = PronyTerms::new(&[PronyTerm { g: 0.6, tau_s: 0.5 }, PronyTerm { g: 0.4, tau_s: 5.0 }]).expect("terms");
    let liver = stacks::ALL.iter().find(|s| s.name == "liver").expect("liver");
    let layers: Vec<Layer> = liver.layers.iter().map(|l| Layer { prony: terms, ..*l }).collect();
    let mut ins = Insertion::new(&Stack { layers: &layers, ..*liver }, InsertionConfig::DEFAULT_1KHZ).expect("stack");
    let want: Vec<f32> = poses.iter().map(|p| ins.step(p).wrench.fy_n).collect();
    assert_eq!(fy.iter().map(|v| v.to_bits()).collect::<Vec<_>>(), want.iter().map(|v| v.to_bits()).collect::<Vec<_>>());
    // the needle stops at tick 800 (3 mm): the force relaxes over the 2.2 s that follow
    let (stopped, end) = (fy[800], fy[2999]);
    assert!(end < 0.8 * stopped, "Fy {stopped} N at the stop, {end} N 2.2 s later: the filter relaxes");
    // without terms the same script holds its force
    let elastic = fy_column(&eval_liver(dir.path(), "stop.csv", &text, &[]));
    assert_eq!(elastic[801].to_bits(), elastic[2999].to_bits(), "elastic: no relaxation");
}

#[test]
fn bad_prony_terms_are_refused() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (text, _) = stop_script();
    for (terms, want) in [
        ("0.6", "is not g:tau_s"),
        ("-0.1:1", "must be finite and >= 0"),
        ("0.5:0", "must be finite and > 0 s"),
        ("5:1, 5:2", "must be <= 9"),
        ("0.1:1, 0.1:1, 0.1:1, 0.1:1", "at most 3"),
    ] {
        let out = eval_liver(dir.path(), "stop.csv", &text, &["--prony", terms]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains(want), "--prony {terms:?}: {err}");
    }
}
