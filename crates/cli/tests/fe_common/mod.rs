//! Shared by the FE campaign tests (`fe_resume.rs`, `fe_slurm.rs`): a copy of the shipped
//! default set and running the `needle` binary.
#![allow(dead_code)]
use std::ffi::OsStr;
use std::path::PathBuf;
use std::process::{Command, Output, Stdio};

/// The `needle` binary under test.
pub const NEEDLE: &str = env!("CARGO_BIN_EXE_needle");

/// A copy of coeffs/default/campaign.toml in a fresh temporary folder: (tempdir, set dir).
pub fn default_set() -> (tempfile::TempDir, PathBuf) {
    let d = tempfile::tempdir().expect("tempdir");
    let set = d.path().join("set");
    std::fs::create_dir_all(&set).expect("mkdir");
    let src = needle_stdx::workspace_root().join("coeffs/default/campaign.toml");
    std::fs::copy(&src, set.join("campaign.toml")).expect("copy the default spec");
    (d, set)
}

/// Run `needle` with `args` and extra environment variables, stdin closed.
pub fn needle<S: AsRef<OsStr>>(args: &[S], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(NEEDLE);
    c.args(args).stdin(Stdio::null());
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("run needle")
}

/// Status, stdout and stderr of a run, for assertion messages.
pub fn show(o: &Output) -> String {
    format!("status {:?}\n--- stdout\n{}\n--- stderr\n{}", o.status, String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr))
}
