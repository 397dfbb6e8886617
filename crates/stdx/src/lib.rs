//! Generic helpers of the host crates, each written once (as rust-analyzer keeps `stdx`):
//! atomic file writes (`fs`), the workspace root (`workspace_root`), nested cargo builds
//! (`cargo`), the library crates' output, which only the binary prints (`report`).
//! Nothing here knows the set, the model, an engine or the firmware.
#![forbid(unsafe_code)]

pub mod cargo;
pub mod fs;
pub mod report;

/// The workspace root (the `needle-haptics` package: Cargo.toml, coeffs/, examples/),
/// two folders above this crate (`crates/stdx`), as compiled in.
#[must_use]
pub fn workspace_root() -> std::path::PathBuf {
    let here = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    here.ancestors().nth(2).map_or_else(|| here.join("../.."), std::path::Path::to_path_buf)
}
