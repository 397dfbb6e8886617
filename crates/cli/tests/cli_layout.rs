//! The CLI's source is laid out by command (no solver needed): every command `needle
//! --help` lists, and every subcommand of a command group (`needle fe`, `needle
//! firmware`), has its module under `src/commands/`, named as the command with `-` as
//! `_`, a file `<name>.rs` or a folder `<name>/mod.rs` inside its group's folder.
//!
//! The convention (`src/commands/mod.rs`): a command's module has one entry,
//! `pub fn run(args) -> anyhow::Result<ExitCode>`. So each command module defines
//! `pub fn run(` exactly once, and a file under `src/commands/` that defines it is the
//! module of a command `needle` knows (a hidden one such as `fe run-one` included): no
//! file holds two commands' entries, no helper holds one.

use std::path::{Path, PathBuf};

mod common;
use common::{all_commands, needle};

/// `src/commands/` of this crate.
fn commands_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("src").join("commands")
}

/// The module file of command `cmd` (e.g. `["fe", "run-one"]`): `fe/run_one.rs` or
/// `fe/run_one/mod.rs` under `src/commands/`, whichever exists.
fn module_file(cmd: &[String]) -> Option<PathBuf> {
    let mut dir = commands_dir();
    let (last, groups) = cmd.split_last()?;
    for g in groups {
        dir.push(g.replace('-', "_"));
    }
    let name = last.replace('-', "_");
    [dir.join(format!("{name}.rs")), dir.join(&name).join("mod.rs")].into_iter().find(|p| p.is_file())
}

/// Every `.rs` file under `dir`, sorted.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())).flatten() {
        let p = e.path();
        if p.is_dir() {
            out.extend(rust_files(&p));
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
    out.sort();
    out
}

/// How many command entries (`pub fn run(`) `file` defines.
fn entries(file: &Path) -> usize {
    let text = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    text.lines().filter(|l| l.trim_start().starts_with("pub fn run(")).count()
}

/// The command whose module `file` would be: its path under `src/commands/` without
/// `.rs` or `/mod.rs`, `_` as `-` (`fe/run_one.rs` is `["fe", "run-one"]`).
fn command_of(file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(commands_dir()).expect("under src/commands");
    let mut parts: Vec<String> = rel.iter().map(|p| p.to_string_lossy().replace('_', "-")).collect();
    if parts.last().is_some_and(|l| l == "mod.rs") {
        parts.pop();
    } else if let Some(l) = parts.last_mut() {
        *l = l.trim_end_matches(".rs").to_string();
    }
    parts
}

#[test]
fn every_command_has_its_module_named_as_the_command() {
    let mut missing = Vec::new();
    for cmd in all_commands() {
        match module_file(&cmd) {
            None => missing.push(format!("needle {}: no src/commands/{}(.rs|/mod.rs)", cmd.join(" "), cmd.join("/").replace('-', "_"))),
            Some(file) if entries(&file) != 1 => missing.push(format!(
                "needle {}: {} defines `pub fn run(` {} times, not once",
                cmd.join(" "),
                file.display(),
                entries(&file)
            )),
            Some(_) => {}
        }
    }
    assert!(missing.is_empty(), "the commands' modules (src/commands/mod.rs states the layout):\n{}", missing.join("\n"));
}

#[test]
fn every_entry_is_one_command_of_needle() {
    let mut wrong = Vec::new();
    let files = rust_files(&commands_dir());
    assert!(files.len() >= 12, "found only {files:?}");
    for file in files {
        let n = entries(&file);
        if n == 0 {
            continue;
        }
        if n > 1 {
            wrong.push(format!("{}: {n} entries (`pub fn run(`): one command per file", file.display()));
            continue;
        }
        // a hidden command is not listed but answers --help with its own usage line
        let cmd = command_of(&file);
        let mut args: Vec<&str> = cmd.iter().map(String::as_str).collect();
        args.push("--help");
        let out = needle(&args);
        let usage = format!("Usage: needle {}", cmd.join(" "));
        if !(out.status.success() && String::from_utf8_lossy(&out.stdout).contains(&usage)) {
            wrong.push(format!("{}: defines an entry (`pub fn run(`) but `needle {}` is no command", file.display(), cmd.join(" ")));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}
