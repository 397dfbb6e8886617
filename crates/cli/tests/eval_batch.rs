//! `needle eval --poses FILE.csv`: every golden vector of the default set, evaluated
//! through the batch command, gives the golden wrench and status bit for bit (the golden
//! file comes from the fitter's own f32 implementation, not from the library); bad rows
//! are named by file and line and nothing is written.

use std::path::PathBuf;
use std::process::Command;

fn default_set() -> PathBuf {
    needle_firmware_host::workspace_root().join("coeffs/default")
}

fn needle(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_needle")).args(args).output().expect("run needle")
}

fn hex_f32(t: &str) -> f32 {
    f32::from_bits(u32::from_str_radix(t.trim_start_matches("0x"), 16).expect("hex bits"))
}

#[test]
fn batch_eval_reproduces_every_golden_vector() {
    let set = default_set();
    let golden = std::fs::read_to_string(set.join("golden-f32.csv")).expect("golden-f32.csv");
    let rows: Vec<Vec<&str>> = golden.lines().skip(1).map(|l| l.split(',').collect()).collect();
    assert!(rows.len() > 1000, "golden file has {} rows", rows.len());
    let mut input = String::from("depth_mm,theta_z_deg,theta_x_deg,z_mm,x_mm,comment\n"); // another column order
    for r in &rows {
        let v: Vec<f32> = r[..5].iter().map(|t| hex_f32(t)).collect();
        input.push_str(&format!("{:?},{:?},{:?},{:?},{:?},ignored\n", v[4], v[3], v[2], v[1], v[0]));
    }
    let d = tempfile::tempdir().expect("tempdir");
    let file = d.path().join("poses.csv");
    std::fs::write(&file, input).expect("write poses");
    let out = d.path().join("wrenches.csv");
    let o = needle(&["eval", "--set", &set.to_string_lossy(), "--poses", &file.to_string_lossy(), "--out", &out.to_string_lossy()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&out).expect("output");
    let got: Vec<Vec<&str>> = text.lines().skip(1).map(|l| l.split(',').collect()).collect();
    assert_eq!(got.len(), rows.len(), "one output row per input row");
    for (i, (g, r)) in got.iter().zip(&rows).enumerate() {
        // a NaN's payload does not survive the decimal text ("NaN"): any NaN is the same input
        let key = |v: f32| if v.is_nan() { u32::MAX } else { v.to_bits() };
        let pose_in: Vec<u32> = r[..5].iter().map(|t| key(hex_f32(t))).collect();
        let pose_out: Vec<u32> = g[..5].iter().map(|t| key(t.parse::<f32>().expect("pose"))).collect();
        assert_eq!(pose_in, pose_out, "row {}: pose echoed", i + 2);
        for c in 0..6 {
            let want = hex_f32(r[6 + c]).to_bits();
            let have = g[5 + c].parse::<f32>().expect("component").to_bits();
            assert_eq!(have, want, "row {}: component {c}: {:#010x} vs golden {want:#010x}", i + 2, have);
        }
        assert_eq!(g[11], r[5], "row {}: status", i + 2);
    }
}

#[test]
fn bad_rows_are_named_by_line_and_nothing_is_written() {
    let d = tempfile::tempdir().expect("tempdir");
    let file = d.path().join("poses.csv");
    std::fs::write(&file, "x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm\n1,2,3,4,5\n1,two,3,4,5\n1,2,3,4,5\n1,2,3\n").expect("write");
    let out = d.path().join("w.csv");
    let set = default_set();
    let o = needle(&["eval", "--set", &set.to_string_lossy(), "--poses", &file.to_string_lossy(), "--out", &out.to_string_lossy()]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    let name = file.display().to_string();
    assert!(err.contains(&format!("{name}:3: column z_mm: \"two\" is not a number")), "{err}");
    assert!(err.contains(&format!("{name}:5: column theta_z_deg: missing")), "{err}");
    assert!(!out.exists(), "nothing written");
    std::fs::write(&file, "x_mm,z_mm,theta_x_deg,depth_mm\n1,2,3,4\n").expect("write");
    let o = needle(&["eval", "--set", &set.to_string_lossy(), "--poses", &file.to_string_lossy()]);
    assert!(
        String::from_utf8_lossy(&o.stderr).contains(&format!("{name}:1: no column \"theta_z_deg\"")),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}
