//! The CLI's own help: every command's summary is one line of at most 100 characters
//! (issue 38), the summaries of `fit` and `header` say what they do, and
//! `docs/commands.md`, the command reference, is the help of every command as the binary
//! prints it (regenerate it with `NEEDLE_BLESS=1 cargo test --release -p needle-cli --test
//! cli_help`). The commands are found by walking `needle --help`'s command lists, so a new
//! command is held to the same rules.

use std::path::PathBuf;

mod common;
use common::{all_commands, help};

const WIDTH: usize = 100;

#[test]
fn every_summary_is_one_short_line() {
    for cmd in all_commands() {
        let mut args: Vec<&str> = cmd.iter().map(String::as_str).collect();
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

/// `docs/commands.md` as the binary's help gives it.
fn command_reference() -> String {
    let mut s = String::from(
        "# Command reference\n\n\
         Generated from the `needle` binary's own help by `crates/cli/tests/cli_help.rs`, which\n\
         fails when this file is stale (`NEEDLE_BLESS=1 cargo test --release -p needle-cli --test\n\
         cli_help` rewrites it). What each command is for, with examples: [`usage.md`](usage.md).\n",
    );
    let mut cmds = vec![Vec::new()];
    cmds.extend(all_commands());
    for cmd in cmds {
        let mut args: Vec<&str> = cmd.iter().map(String::as_str).collect();
        args.push("--help");
        let title = if cmd.is_empty() { "needle".to_string() } else { format!("needle {}", cmd.join(" ")) };
        s.push_str(&format!("\n## `{title}`\n\n```text\n{}```\n", help(&args)));
    }
    s
}

#[test]
fn docs_commands_md_is_the_help() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..").join("..").join("docs").join("commands.md");
    let now = command_reference();
    if std::env::var_os("NEEDLE_BLESS").is_some() {
        std::fs::write(&path, &now).expect("write docs/commands.md");
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(committed == now, "{} is stale: rerun with NEEDLE_BLESS=1 cargo test --release -p needle-cli --test cli_help", path.display());
}
