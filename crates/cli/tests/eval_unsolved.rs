//! `needle eval` and the unsolved region (status `FE_UNSOLVED`, coeffs/README.md "The
//! unsolved region"): a pose the FE could not solve is flagged in the text and the JSON
//! with its wrench (exit 0), and `--set` must carry the compiled-in region.

use std::path::Path;
use std::process::Command;

fn needle(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_needle")).args(args).output().expect("run needle")
}

fn set() -> String {
    needle_stdx::workspace_root().join("coeffs/default").to_string_lossy().into_owned()
}

/// tx+15 failed every attempt: the pose is in the region below the depth its furthest
/// attempt reached (5.70 mm, `fe/tx+15.partial.toml`), so at 6 mm; the centre is not.
fn pose(theta_x: &str) -> Vec<String> {
    ["--x-mm", "0", "--z-mm", "0", "--theta-x-deg", theta_x, "--theta-z-deg", "0", "--depth-mm", "6"].map(String::from).to_vec()
}

#[test]
fn eval_names_the_flag_and_keeps_the_wrench() {
    let s = set();
    let run = |theta_x: &str, json: bool| {
        let mut args: Vec<String> = vec!["eval".into(), "--set".into(), s.clone()];
        args.extend(pose(theta_x));
        if json {
            args.push("--json".into());
        }
        let o = needle(&args.iter().map(String::as_str).collect::<Vec<_>>());
        assert!(o.status.success(), "a flagged pose is a wrench, exit 0: {}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    let text = run("15", false);
    assert!(
        text.contains(
            "status  = 0x20 (FE_UNSOLVED): in the domain; FE_UNSOLVED: the pose lies where the set's FE campaign could not solve"
        ),
        "{text}"
    );
    let v: serde_json::Value = serde_json::from_str(&run("15", true)).expect("json");
    assert_eq!(v["status"]["bits"], "0x20");
    assert_eq!(v["status"]["fe_unsolved"], true);
    assert_eq!(v["status"]["error"], false);
    assert_ne!(v["wrench"]["fy_n"].as_f64(), Some(0.0), "the wrench is the model's");
    let v: serde_json::Value = serde_json::from_str(&run("0", true)).expect("json");
    assert_eq!((v["status"]["bits"].as_str(), v["status"]["fe_unsolved"].as_bool()), (Some("0x00"), Some(false)));
}

#[test]
fn another_region_than_the_compiled_in_one_is_refused() {
    let dir = tempfile::tempdir().expect("tempdir");
    let from = Path::new(&set()).to_path_buf();
    for f in ["model.toml", "unsolved.toml"] {
        std::fs::copy(from.join(f), dir.path().join(f)).expect("copy");
    }
    let edited = std::fs::read_to_string(dir.path().join("unsolved.toml")).expect("read").replacen("radius_q15 = ", "radius_q15 = 1", 1);
    std::fs::write(dir.path().join("unsolved.toml"), edited).expect("write");
    let mut args = vec!["eval".to_string(), "--set".into(), dir.path().to_string_lossy().into_owned()];
    args.extend(pose("15"));
    let o = needle(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("is another unsolved region than the compiled-in one"), "{err}");
}
