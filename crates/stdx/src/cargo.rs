//! Nested `cargo` builds from a host tool (the firmware examples, the wasm evaluator):
//! the cargo to run, the workspace's target folder, the rustup target check, running a
//! build with the end of its output in the error.

use crate::workspace_root;
use anyhow::{bail, Context};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// The workspace's target folder (`CARGO_TARGET_DIR`, relative to the workspace root, or
/// `target`).
#[must_use]
pub fn target_dir() -> PathBuf {
    let root = workspace_root();
    match std::env::var_os("CARGO_TARGET_DIR") {
        Some(d) if !d.is_empty() => root.join(d),
        _ => root.join("target"),
    }
}

/// `cargo` as the outer cargo named it (`$CARGO`), else from `PATH`.
#[must_use]
pub fn nested_cargo() -> Command {
    Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()))
}

/// Checks that the Rust standard library of `target` is installed (rustup target).
///
/// # Errors
/// `rustc` cannot be run, or the target is missing, with the command that installs it.
pub fn check_target(target: &str) -> anyhow::Result<()> {
    let rustc = std::env::var_os("RUSTC").unwrap_or_else(|| "rustc".into());
    let out = Command::new(&rustc)
        .args(["--print", "sysroot"])
        .current_dir(workspace_root())
        .output()
        .with_context(|| format!("cannot run {} --print sysroot", rustc.to_string_lossy()))?;
    let sysroot = PathBuf::from(String::from_utf8_lossy(&out.stdout).trim());
    let lib = sysroot.join("lib").join("rustlib").join(target).join("lib");
    if !out.status.success() || !lib.is_dir() {
        bail!(
            "the Rust target {target} is not installed ({} does not exist): `rustup target add {target}` \
             (.ci/test installs thumbv7em-none-eabihf, thumbv7m-none-eabi, thumbv6m-none-eabi and wasm32-unknown-unknown)",
            lib.display()
        );
    }
    Ok(())
}

/// Runs a nested cargo build in `dir` (cargo reads the `.cargo/config.toml` files from
/// there up), announced on stderr as `<who>: building <what>`; returns cargo's stderr
/// (its warnings, replayed from the cache on a rebuild). `hint` adds a sentence to the
/// error from cargo's whole stderr (empty: none).
///
/// # Errors
/// cargo cannot be started or exits with an error: the end of its output, the hint.
pub fn run_cargo_in(mut cmd: Command, dir: &Path, who: &str, what: &str, hint: &dyn Fn(&str) -> String) -> anyhow::Result<String> {
    cmd.current_dir(dir).stdin(Stdio::null());
    crate::noteln!("{who}: building {what}");
    let out = cmd.output().with_context(|| format!("cannot run cargo to build {what}"))?;
    let stderr = String::from_utf8_lossy(&out.stderr);
    if out.status.success() {
        return Ok(stderr.into_owned());
    }
    let tail: Vec<&str> = stderr.lines().rev().take(60).collect::<Vec<_>>().into_iter().rev().collect();
    let mut extra = hint(&stderr);
    if extra.is_empty() && stderr.contains("can't find crate for `core`") {
        extra = "\nThe target's standard library is missing: rustup target add it.".to_string();
    }
    bail!("cargo build of {what} failed ({}):\n{}{extra}", out.status, tail.join("\n"))
}
