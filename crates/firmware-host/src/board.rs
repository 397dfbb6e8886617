//! The board crates in `examples/<board>/`: firmware with its own workspace,
//! `.cargo/config.toml` (target, runner) and memory map, depending on the library by
//! path. Built by a nested release `cargo build` run in the crate's folder (so its
//! config applies) into `<target dir>/firmware/<board>`; a build with a warning is an
//! error.
use super::build::{check_target, nested_cargo, run_cargo_in, target_dir};
use super::{size, Core};
use anyhow::bail;
use needle_stdx::workspace_root;
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

/// The real-board example: NUCLEO-F401RE with stm32f4xx-hal, defmt over RTT, flashed
/// by probe-rs (examples/nucleo-f401re). Built, never run, here.
pub const NUCLEO_F401RE: Board = Board { dir: "nucleo-f401re", bin: "needle-nucleo-f401re", target: "thumbv7em-none-eabihf" };

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
        let stderr = run_cargo_in(cmd, &self.path(), &format!("examples/{} for {}", self.dir, self.target))?;
        let warnings: Vec<&str> = stderr.lines().filter(|l| l.starts_with("warning")).collect();
        if !warnings.is_empty() {
            bail!("examples/{} builds with warnings:\n{stderr}", self.dir);
        }
        let elf = out.join(self.target).join("release").join(self.bin);
        if !elf.is_file() {
            bail!("{}: cargo built no such file", elf.display());
        }
        Ok(elf)
    }
}

/// Flash and static RAM of a firmware image, bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImageSize {
    /// `.text` + `.rodata` + vector table (`size`'s text) plus `.data`'s initial values.
    pub flash: u64,
    /// `.data` + `.bss` (the stack comes on top).
    pub ram: u64,
}

/// The flash and RAM of `elf` (binutils `size`).
///
/// # Errors
/// binutils missing or their output unexpected.
pub fn image_size(elf: &Path) -> anyhow::Result<ImageSize> {
    let (text, data, bss) = size::berkeley(elf)?;
    Ok(ImageSize { flash: text + data, ram: data + bss })
}
