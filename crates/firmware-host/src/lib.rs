//! The library on Cortex-M, driven from the host: build the firmware examples of
//! `examples/` for the three reference cores, run them under `qemu-system-arm` with
//! semihosting, and read what they print (golden-vector bits, instruction counts, stack),
//! plus the flash/RAM report from binutils on the ELF files.
//!
//! Used by `needle firmware ...` and by the tests `firmware_golden.rs` and
//! `firmware_no_panic.rs`. Nothing here skips: a missing QEMU, rustup target or binutils
//! is an error that says what to install.
//!
//! The firmware is built by a nested `cargo build` in its own target folder
//! (`<target dir>/firmware`, so it never waits for the lock of an outer `cargo test`),
//! in the release profile, with `NEEDLE_COEFFS` set to the absolute path of the set.
#![forbid(unsafe_code)]

pub mod bench;
pub mod board;
pub mod build;
pub mod comparison;
pub mod float_check;
pub mod golden;
pub mod golden_fixed;
pub mod golden_stiffness;
pub mod qemu;
pub mod size;

use std::path::{Path, PathBuf};

/// One reference core: its Rust target and the QEMU board that emulates it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Core {
    /// Short name used in reports and on the command line (`m4f`, `m3`, `m0`).
    pub name: &'static str,
    /// Human name of the core.
    pub core: &'static str,
    /// Rust target triple.
    pub target: &'static str,
    /// `qemu-system-arm -machine`.
    pub machine: &'static str,
    /// `qemu-system-arm -cpu`.
    pub cpu: &'static str,
}

/// The three reference cores, in report order.
pub const CORES: [Core; 3] = [
    Core { name: "m4f", core: "Cortex-M4F", target: "thumbv7em-none-eabihf", machine: "mps2-an386", cpu: "cortex-m4" },
    Core { name: "m3", core: "Cortex-M3", target: "thumbv7m-none-eabi", machine: "mps2-an385", cpu: "cortex-m3" },
    Core { name: "m0", core: "Cortex-M0", target: "thumbv6m-none-eabi", machine: "microbit", cpu: "cortex-m0" },
];

/// The core named `name` (`m4f`, `m3`, `m0`, or its target triple).
///
/// # Errors
/// No such core.
pub fn core(name: &str) -> anyhow::Result<Core> {
    CORES.iter().copied().find(|c| c.name == name || c.target == name).ok_or_else(|| {
        anyhow::anyhow!(
            "unknown core {name:?}: one of {}",
            CORES.iter().map(|c| format!("{} ({})", c.name, c.target)).collect::<Vec<_>>().join(", ")
        )
    })
}

/// The cores named in `names`, or all three when it is empty.
///
/// # Errors
/// An unknown name.
pub fn cores(names: &[String]) -> anyhow::Result<Vec<Core>> {
    if names.is_empty() {
        return Ok(CORES.to_vec());
    }
    names.iter().map(|n| core(n)).collect()
}

/// The set compiled into this build of the host tools (absolute path), the default set
/// of every firmware command.
#[must_use]
pub fn compiled_set() -> PathBuf {
    PathBuf::from(needle_haptics::model_info::SET_DIR)
}

/// Checks that `set` is a fitted set with golden vectors, and returns its absolute path.
///
/// # Errors
/// The folder, its `model.toml`, `golden-f32.csv` or `golden-fixed.csv` is missing: the firmware would
/// hold the unfitted placeholder model, whose figures mean nothing.
pub fn fitted_set(set: &Path) -> anyhow::Result<PathBuf> {
    let dir = std::fs::canonicalize(set).map_err(|e| anyhow::anyhow!("{}: not a coefficient set folder ({e})", set.display()))?;
    use needle_fit::{GOLDEN_FILE, GOLDEN_FIXED_FILE, GOLDEN_STIFFNESS_FILE, GOLDEN_STIFFNESS_FIXED_FILE};
    for file in [needle_codegen::MODEL_FILE, GOLDEN_FILE, GOLDEN_FIXED_FILE, GOLDEN_STIFFNESS_FILE, GOLDEN_STIFFNESS_FIXED_FILE] {
        if !dir.join(file).is_file() {
            anyhow::bail!(
                "{}: no {file}: the set is not fitted yet, so the firmware would hold the unfitted \
                 placeholder (every evaluation returns NO_MODEL | ERROR). Run `needle fit --set {}` \
                 (it writes model.toml and the golden files) and retry",
                dir.display(),
                dir.display()
            );
        }
    }
    Ok(dir)
}
