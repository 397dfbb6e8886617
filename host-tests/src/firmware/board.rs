//! The board crates in `examples/<board>/`: firmware with its own workspace,
//! `.cargo/config.toml` (target, runner) and memory map, depending on the library by
//! path. Built by a nested release `cargo build` run in the crate's folder (so its
//! config applies) into `<target dir>/firmware/<board>`.
use super::build::{check_target, nested_cargo, run_cargo_in, target_dir};
use super::{workspace_root, Core};
use anyhow::bail;
use std::path::{Path, PathBuf};

/// One board crate.
#[derive(Clone, Copy, Debug)]
pub struct Board {
    /// Folder under `examples/`.
    pub dir: &'static str,
    /// Its binary (the firmware ELF).
    pub bin: &'static str,
    /// Rust target triple (the crate's `[build] target`).
    pub target: &'static str,
}

/// The RTIC 2 application on QEMU's Stellaris LM3S6965 (examples/rtic-lm3s6965).
pub const RTIC_LM3S6965: Board = Board { dir: "rtic-lm3s6965", bin: "needle-rtic-lm3s6965", target: "thumbv7m-none-eabi" };

/// The QEMU board [`RTIC_LM3S6965`] runs on.
pub const LM3S6965: Core = Core {
    name: "lm3s6965",
    core: "Cortex-M3 (Stellaris LM3S6965)",
    target: "thumbv7m-none-eabi",
    machine: "lm3s6965evb",
    cpu: "cortex-m3",
};

impl Board {
    /// The crate's folder.
    #[must_use]
    pub fn path(&self) -> PathBuf {
        workspace_root().join("examples").join(self.dir)
    }

    /// Builds the board's firmware (release) with the coefficient set `set` and returns
    /// the ELF's path.
    ///
    /// # Errors
    /// The target is not installed or the build fails (the error holds cargo's output).
    pub fn build(&self, set: &Path) -> anyhow::Result<PathBuf> {
        check_target(self.target)?;
        let out = target_dir().join(self.dir);
        let mut cmd = nested_cargo();
        cmd.args(["build", "--release", "--target", self.target, "--target-dir"]).arg(&out).env("NEEDLE_COEFFS", set);
        run_cargo_in(cmd, &self.path(), &format!("examples/{} for {}", self.dir, self.target))?;
        let elf = out.join(self.target).join("release").join(self.bin);
        if !elf.is_file() {
            bail!("{}: cargo built no such file", elf.display());
        }
        Ok(elf)
    }
}
