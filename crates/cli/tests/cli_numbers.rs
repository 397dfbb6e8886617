//! Numbers on the command line: negative and non-finite values are accepted as values
//! (not taken for options), and out-of-range counts are refused with the range.

use std::process::Command;

fn needle(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_needle")).args(args).output().expect("run needle")
}

fn set() -> String {
    needle_stdx::workspace_root().join("coeffs/default").to_string_lossy().into_owned()
}

#[test]
fn negative_and_infinite_pose_values_are_values() {
    let s = set();
    let o = needle(&[
        "eval",
        "--set",
        &s,
        "--x-mm",
        "-3",
        "--z-mm",
        "-1e0",
        "--theta-x-deg",
        "-2.5",
        "--theta-z-deg",
        "0",
        "--depth-mm",
        "-inf",
        "--json",
    ]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "an infinite depth is an error status, exit 1: {out}{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.contains("\"x_mm\": -3.0") && out.contains("\"ERROR\""), "{out}");
    let o = needle(&["eval", "--set", &s, "--x-mm", "-3", "--z-mm", "0", "--theta-x-deg", "0", "--theta-z-deg", "-15", "--depth-mm", "6"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn out_of_range_counts_are_refused_with_their_range() {
    let s = set();
    for (args, want) in [
        (vec!["fe", "run", "--set", &s, "--jobs", "-1"], "invalid value '-1' for '--jobs <N>': -1 is not in 1..=256"),
        (vec!["fe", "run", "--set", &s, "--jobs", "0"], "invalid value '0' for '--jobs <N>': 0 is not in 1..=256"),
        (vec!["fe", "run", "--set", &s, "--steps", "0"], "0 is not in 1..=10000"),
        (vec!["fe", "run", "--set", &s, "--timeout-s", "-5"], "-5 s: must be > 0 s"),
        (vec!["fe", "run", "--set", &s, "--stall-s", "inf"], "inf s: must be > 0 s"),
        (vec!["fe", "run", "--set", &s, "--timeout-s", "ten"], "\"ten\" is not a number of seconds"),
        (vec!["fixed-error", "--set", &s, "--grid", "100"], "100 is not in 2..=41"),
        (vec!["fixed-error", "--set", &s, "--random", "1000000000"], "1000000000 is not in 0..=100000000"),
    ] {
        let o = needle(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(want), "{args:?}: {err}");
    }
}
