//! Issue 66, run-time inputs of `needle eval --poses FILE --insertion STACK`: an empty
//! `--prony` (an unset shell variable) is refused, not read as "no terms"; a repeated
//! time_s column is refused; ticks far longer than the control period are warned as a
//! unit problem and refused past the limit. Each test names the case of the issue.
use std::path::Path;
use std::process::Output;

mod common;
use common::{needle, shipped_set_arg, show};

/// A short insertion script (200 ticks into the stack) with ticks of `tick_s`, and the
/// time column written `times` times.
fn script(tick_s: f64, times: usize) -> String {
    let mut text = vec!["time_s"; times].join(",") + ",x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm\n";
    for k in 0..200u32 {
        let t = f64::from(k) * tick_s;
        let depth = -1.0 + 0.05 * f64::from(k);
        text.push_str(&(vec![format!("{t}"); times].join(",") + &format!(",0,0,0,0,{depth}\n")));
    }
    text
}

fn eval(dir: &Path, text: &str, stack: &str, extra: &[&str]) -> Output {
    let file = dir.join("script.csv");
    std::fs::write(&file, text).expect("script");
    let set = shipped_set_arg();
    let mut args = vec!["eval", "--set", &set, "--poses", file.to_str().expect("path"), "--insertion", stack];
    args.extend_from_slice(extra);
    needle(&args)
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn issue66_11_an_empty_prony_is_refused_not_read_as_no_terms() {
    let d = tempfile::tempdir().expect("tempdir");
    for empty in ["", ",", " , "] {
        let o = eval(d.path(), &script(0.001, 1), "epidural", &["--prony", empty]);
        assert_eq!(o.status.code(), Some(2), "--prony {empty:?}: {}", show(&o));
        assert!(stderr(&o).contains("no term (an unset shell variable?)"), "{}", show(&o));
    }
    let o = eval(d.path(), &script(0.001, 1), "epidural", &["--prony", "0.6:0.5"]);
    assert!(o.status.success(), "one term is taken: {}", show(&o));
}

#[test]
fn message_prony_1e40_says_beyond_f32_not_must_be_finite() {
    let d = tempfile::tempdir().expect("tempdir");
    let o = eval(d.path(), &script(0.001, 1), "epidural", &["--prony", "1e40:1"]);
    assert_eq!(o.status.code(), Some(2), "{}", show(&o));
    let e = stderr(&o);
    assert!(e.contains("g = 10000000000000000000000000000000000000000 is beyond the library's f32 numbers"), "{e}");
    assert!(!e.contains("must be finite"), "{e}");
}

#[test]
fn issue66_12_two_time_columns_are_refused() {
    let d = tempfile::tempdir().expect("tempdir");
    let o = eval(d.path(), &script(0.001, 2), "liver", &[]);
    assert_eq!(o.status.code(), Some(2), "{}", show(&o));
    assert!(stderr(&o).contains(":1: column \"time_s\" appears 2 times"), "{}", show(&o));
}

#[test]
fn issue66_13_time_in_milliseconds_is_refused_and_a_slow_tick_warned() {
    let d = tempfile::tempdir().expect("tempdir");
    // time_s written in ms: ticks of 1 s
    let o = eval(d.path(), &script(1.0, 1), "liver", &[]);
    assert_eq!(o.status.code(), Some(2), "{}", show(&o));
    let e = stderr(&o);
    assert!(e.contains("ticks of 1 s, more than 0.1") && e.contains("milliseconds"), "{e}");
    assert!(o.stdout.is_empty(), "no rows: {}", show(&o));
    // 50 Hz: taken, with a warning
    let o = eval(d.path(), &script(0.02, 1), "liver", &[]);
    assert!(o.status.success(), "{}", show(&o));
    assert!(stderr(&o).contains("warning:") && stderr(&o).contains("ticks of 0.02 s"), "{}", show(&o));
    // 1 kHz: no warning
    let o = eval(d.path(), &script(0.001, 1), "liver", &[]);
    assert!(o.status.success() && !stderr(&o).contains("warning"), "{}", show(&o));
}
