//! The helpers of the `needle` binary's tests, each defined once: the binary, running it,
//! the shipped default set and a scratch copy of its spec. Every test file has
//! `mod common;` (Cargo builds `tests/common/mod.rs` as a module, not as a test).
#![allow(dead_code)]
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

/// The `needle` binary under test.
pub const NEEDLE: &str = env!("CARGO_BIN_EXE_needle");

/// Run `needle` with `args`, stdin closed.
pub fn needle<S: AsRef<OsStr>>(args: &[S]) -> Output {
    needle_env(args, &[])
}

/// Run `needle` with `args` and extra environment variables, stdin closed.
pub fn needle_env<S: AsRef<OsStr>>(args: &[S], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(NEEDLE);
    c.args(args).stdin(Stdio::null());
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("run needle")
}

/// `needle <args> --set <set>`, stdin closed.
pub fn needle_on(args: &[&str], set: &Path) -> Output {
    let mut all: Vec<&OsStr> = args.iter().map(OsStr::new).collect();
    all.extend([OsStr::new("--set"), set.as_os_str()]);
    needle(&all)
}

/// Status, stdout and stderr of a run, for assertion messages.
pub fn show(o: &Output) -> String {
    format!("status {:?}\n--- stdout\n{}\n--- stderr\n{}", o.status, String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr))
}

/// The shipped default set, coeffs/default, the one compiled into the library (read
/// only: a test that writes into a set works on a copy).
pub fn shipped_set() -> PathBuf {
    needle_stdx::workspace_root().join("coeffs/default")
}

/// [`shipped_set`] as a command-line argument.
pub fn shipped_set_arg() -> String {
    shipped_set().to_string_lossy().into_owned()
}

/// A copy of the shipped set's campaign.toml (only the spec: no FE runs, no model) in a
/// fresh temporary folder, for the FE campaign tests: (tempdir, set dir).
pub fn campaign_copy() -> (tempfile::TempDir, PathBuf) {
    let d = tempfile::tempdir().expect("tempdir");
    let set = d.path().join("set");
    std::fs::create_dir_all(&set).expect("mkdir");
    std::fs::copy(shipped_set().join("campaign.toml"), set.join("campaign.toml")).expect("copy the default spec");
    (d, set)
}

/// The help text `needle <args>` prints (it must succeed).
pub fn help(args: &[&str]) -> String {
    let out = needle(args);
    assert!(out.status.success(), "needle {args:?} failed: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).expect("help is UTF-8")
}

/// The subcommands a help text lists under "Commands:", without `help`.
pub fn listed_commands(text: &str) -> Vec<String> {
    text.lines()
        .skip_while(|l| *l != "Commands:")
        .skip(1)
        .take_while(|l| !l.is_empty())
        .filter_map(|l| l.split_whitespace().next())
        .filter(|name| *name != "help")
        .map(String::from)
        .collect()
}

/// Every command and subcommand of `needle`, depth first, in the order the help lists them.
pub fn all_commands() -> Vec<Vec<String>> {
    fn walk(prefix: &[String], out: &mut Vec<Vec<String>>) {
        let mut args: Vec<&str> = prefix.iter().map(String::as_str).collect();
        args.push("--help");
        for name in listed_commands(&help(&args)) {
            let mut cmd = prefix.to_vec();
            cmd.push(name);
            out.push(cmd.clone());
            walk(&cmd, out);
        }
    }
    let mut out = Vec::new();
    walk(&[], &mut out);
    assert!(out.len() >= 10, "found only {out:?}");
    out
}

/// A copy of the shipped set (every file: model, tissue, figures, measured curves, FE
/// records) in a fresh temporary folder, for tests that write into a set or break one of
/// its files: (tempdir, set dir).
pub fn set_copy() -> (tempfile::TempDir, PathBuf) {
    fn copy(from: &Path, to: &Path) {
        std::fs::create_dir_all(to).expect("mkdir");
        for e in std::fs::read_dir(from).expect("read the set").flatten() {
            let (src, dst) = (e.path(), to.join(e.file_name()));
            if src.is_dir() {
                copy(&src, &dst);
            } else {
                std::fs::copy(&src, &dst).expect("copy");
            }
        }
    }
    let d = tempfile::tempdir().expect("tempdir");
    let set = d.path().join("set");
    copy(&shipped_set(), &set);
    (d, set)
}

/// Every file under `dir` with its bytes, sorted by path: a snapshot to show that a
/// refused command changed no file.
pub fn snapshot(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    fn walk(dir: &Path, out: &mut Vec<(PathBuf, Vec<u8>)>) {
        for e in std::fs::read_dir(dir).expect("read").flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(&p, out);
            } else {
                out.push((p.clone(), std::fs::read(&p).unwrap_or_default()));
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, &mut out);
    out.sort();
    out
}
