//! Build of the explorer's WebAssembly evaluator (`crates/wasm`) for one set.

use anyhow::{bail, Result};
use needle_stdx::cargo::{check_target, nested_cargo, run_cargo_in};
use needle_stdx::workspace_root;
use std::path::{Path, PathBuf};

/// The target folder of the module's build: the firmware builds' (`firmware/` in the
/// workspace's target folder), whose dependencies it shares.
fn target_dir() -> PathBuf {
    needle_stdx::cargo::target_dir().join("firmware")
}

/// The Rust target of the explorer's module.
pub const TARGET: &str = "wasm32-unknown-unknown";

/// Builds `needle-wasm` (release, without debug info) with the coefficient set `set`
/// (an absolute path or one relative to the workspace root) and returns the `.wasm`
/// file's path, under `target_dir`.
///
/// # Errors
/// The wasm32 target is not installed (the message has the `rustup` command), or the build
/// fails (the message holds cargo's output).
pub fn build(set: &Path) -> Result<PathBuf> {
    check_target(TARGET)?;
    let mut cmd = nested_cargo();
    cmd.args(["build", "--release", "-p", "needle-wasm", "--lib", "--target", TARGET, "--target-dir"])
        .arg(target_dir())
        .env("NEEDLE_COEFFS", set)
        // the module is served to a browser: no DWARF (1 MB -> tens of kB)
        .env("CARGO_PROFILE_RELEASE_DEBUG", "false")
        .env("CARGO_PROFILE_RELEASE_STRIP", "true");
    let what = format!("the wasm evaluator for {TARGET} with set {}", set.display());
    run_cargo_in(cmd, &workspace_root(), "explore", &what, &|_| String::new())?;
    let wasm = target_dir().join(TARGET).join("release").join("needle_wasm.wasm");
    if !wasm.is_file() {
        bail!("{}: cargo built no such file", wasm.display());
    }
    Ok(wasm)
}
