//! Every command's summary is one line of at most 100 characters (issue 38): the first
//! line of `needle <command> -h`, which `needle --help` lists; the details are in
//! `--help` only. The summaries of `fit` and `header` say what they do.

use std::process::Command;

const COMMANDS: &[&[&str]] = &[
    &["fe"],
    &["fe", "run"],
    &["fe", "verify"],
    &["fe", "status"],
    &["fit"],
    &["eval"],
    &["calibrate"],
    &["validate"],
    &["explore"],
    &["plot"],
    &["fixed-error"],
    &["header"],
    &["firmware"],
    &["firmware", "size"],
    &["firmware", "bench"],
    &["firmware", "golden"],
    &["firmware", "check"],
];

const WIDTH: usize = 100;

fn help(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_needle")).args(args).output().expect("run needle");
    assert!(out.status.success(), "needle {args:?} failed: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).expect("help is UTF-8")
}

#[test]
fn every_summary_is_one_short_line() {
    for cmd in COMMANDS {
        let mut args = cmd.to_vec();
        args.push("-h");
        let text = help(&args);
        let first = text.lines().next().unwrap_or_default();
        assert!(first.len() <= WIDTH, "needle {} -h: summary of {} characters (at most {WIDTH}): {first}", cmd.join(" "), first.len());
        assert_eq!(text.lines().nth(1), Some(""), "needle {} -h: the summary is not one line:\n{text}", cmd.join(" "));
    }
}

#[test]
fn the_command_list_names_what_fit_and_header_do() {
    let text = help(&["--help"]);
    let line = |name: &str| {
        text.lines()
            .find(|l| l.trim_start().starts_with(&format!("{name} ")))
            .unwrap_or_else(|| panic!("no {name} in:\n{text}"))
            .to_string()
    };
    assert!(line("fit").contains("paper or coupled"), "{}", line("fit"));
    assert!(line("header").contains("needle.h") && line("header").contains("needle_coeffs.h"), "{}", line("header"));
}
