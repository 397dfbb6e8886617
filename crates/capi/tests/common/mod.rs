//! What the C program tests share: paths, the scratch folder with `needle.h`, running a
//! command, building the static library.
#![allow(dead_code)]
use std::path::{Path, PathBuf};
use std::process::Command;

pub fn manifest_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

pub use needle_stdx::workspace_root;

pub fn golden_csv() -> PathBuf {
    let p = Path::new(needle_haptics::model_info::SET_DIR).join("golden-f32.csv");
    assert!(p.is_file(), "{}: no golden vectors; run `needle fit`", p.display());
    p
}

/// A scratch folder under the target folder, holding needle.h.
pub fn scratch(name: &str) -> PathBuf {
    let dir = workspace_root().join("target").join("capi-test").join(name);
    std::fs::create_dir_all(&dir).expect("create scratch folder");
    std::fs::write(dir.join("needle.h"), needle_capi::HEADER).expect("write needle.h");
    dir
}

pub fn run(cmd: &mut Command, what: &str) -> String {
    let out = cmd.output().unwrap_or_else(|e| panic!("{what}: cannot run {cmd:?}: {e} (is it installed? .ci/test installs it)"));
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "{what} failed ({}):\n{text}", out.status);
    text
}

/// Builds `libneedle_capi.a` in release for `target` (None: the host) in the firmware
/// target folder (shared with the firmware tests, so it does not wait for this test's
/// own cargo lock) and returns its path.
pub fn staticlib(target: Option<&str>) -> PathBuf {
    let dir = workspace_root().join("target").join("firmware");
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut cmd = Command::new(cargo);
    cmd.current_dir(workspace_root()).args(["build", "--release", "-p", "needle-capi", "--lib", "--target-dir"]).arg(&dir);
    if let Some(t) = target {
        cmd.args(["--target", t]);
    }
    run(&mut cmd, "cargo build -p needle-capi");
    let lib = match target {
        Some(t) => dir.join(t).join("release").join("libneedle_capi.a"),
        None => dir.join("release").join("libneedle_capi.a"),
    };
    assert!(lib.is_file(), "{}: not built", lib.display());
    lib
}
