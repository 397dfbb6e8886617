//! Build script of `needle-haptics`: code generation from `coeffs/` only.
//!
//! - Selects the coefficient set: the folder named by `NEEDLE_COEFFS` (relative paths
//!   are relative to this crate's root), default `coeffs/default`.
//! - Validates `<set>/model.toml` (and `<set>/unsolved.toml`, the region where the FE
//!   could not solve, when present) with `needle-codegen` and writes
//!   `$OUT_DIR/tables_f32.rs` (included by `src/tables.rs`), `$OUT_DIR/unsolved.rs`
//!   (`src/unsolved.rs`) and `$OUT_DIR/needle_coeffs.h` (`model_info::C_HEADER`).
//! - A bad model fails the build with `cargo::error=<path>:<line>: <what is wrong>` and a
//!   non-zero exit, never a panic.
//! - A set without `model.toml` (a new set before `needle fit` has run) builds an
//!   *unfitted* library with a `cargo::warning`: every evaluation then returns the zero
//!   wrench with status `NO_MODEL | ERROR`. (The `needle` tool, `needle-cli`, depends on
//!   this library, so it must build before the first fit.)
//! - Never emits `rustc-link-search` (it would override the user's memory map); link
//!   arguments go to this package's examples only, for bare-metal targets.
use std::path::{Path, PathBuf};
use std::process::ExitCode;

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            println!("cargo::error={message}");
            ExitCode::FAILURE
        }
    }
}

fn run() -> Result<(), String> {
    println!("cargo::rerun-if-env-changed=NEEDLE_COEFFS");
    let manifest_dir = PathBuf::from(env("CARGO_MANIFEST_DIR")?);
    example_link_args(&manifest_dir);
    let out_dir = PathBuf::from(env("OUT_DIR")?);
    let (set_dir, named_by) = match std::env::var("NEEDLE_COEFFS") {
        Ok(v) if !v.is_empty() => (manifest_dir.join(&v), format!("NEEDLE_COEFFS={v}")),
        _ => (manifest_dir.join("coeffs").join("default"), "the default set".to_string()),
    };
    let model_path = set_dir.join(needle_codegen::MODEL_FILE);
    // A missing file always reruns the script (cargo treats it as changed), so a fit
    // into a new set is picked up; an existing one reruns when it changes. The set folder
    // itself is watched only while it has no model: its fe/ data changes during an FE
    // campaign, and the generated code depends on model.toml alone.
    println!("cargo::rerun-if-changed={}", model_path.display());
    // The unsolved region beside it (read by `generate` when present).
    println!("cargo::rerun-if-changed={}", set_dir.join(needle_codegen::unsolved::FILE).display());

    if !set_dir.is_dir() {
        println!("cargo::rerun-if-changed={}", set_dir.display());
        return Err(format!(
            "{}: no such set folder ({named_by}); a set is a folder like coeffs/default holding model.toml",
            set_dir.display()
        ));
    }
    let set_dir = std::fs::canonicalize(&set_dir).map_err(|e| format!("{}: cannot resolve the set folder: {e}", set_dir.display()))?;
    println!("cargo::rustc-env=NEEDLE_SET_DIR={}", set_dir.display());

    if model_path.is_file() {
        needle_codegen::generate(&model_path, &out_dir).map_err(|e| e.to_string())?;
    } else {
        println!("cargo::rerun-if-changed={}", set_dir.display());
        let set = set_name(&set_dir);
        println!(
            "cargo::warning={}: no model.toml yet: needle-haptics is built WITHOUT a fitted model (every evaluation returns status NO_MODEL | ERROR and a zero wrench); run `needle fit --set {}` and rebuild",
            set_dir.display(),
            set_dir.display()
        );
        needle_codegen::generate_unfitted(&set, &out_dir).map_err(|e| e.to_string())?;
    }
    // The tissue stacks: the folder (a file added or removed) and each file.
    println!("cargo::rerun-if-changed={}", set_dir.join(needle_codegen::tissue::TISSUE_DIR).display());
    for path in needle_codegen::generate_tissue(&set_dir, &out_dir).map_err(|e| e.to_string())? {
        println!("cargo::rerun-if-changed={}", path.display());
    }
    Ok(())
}

/// Link arguments for this package's firmware examples, only when building for a
/// bare-metal target (`target_os = "none"`): the cortex-m-rt linker script (which
/// includes `memory.x` from the package root). Never for the library itself, never a
/// search path. Cargo refuses `rustc-link-arg-examples` from a package without
/// examples, so they are emitted only when `examples/` holds one (`*.rs` or `*/main.rs`,
/// cargo's auto-discovery); `examples/` is watched so a new example reruns this script.
fn example_link_args(manifest_dir: &Path) {
    if std::env::var("CARGO_CFG_TARGET_OS").map_or(true, |os| os != "none") {
        return;
    }
    let examples = manifest_dir.join("examples");
    println!("cargo::rerun-if-changed={}", examples.display());
    if !has_examples(&examples) {
        return;
    }
    // ---- example-only link arguments (bare metal): add new ones here ----
    println!("cargo::rustc-link-arg-examples=-Tlink.x");
    // The Cortex-M0 examples run on QEMU's microbit (16 KiB RAM at 0x2000_0000), the
    // others on MPS2 (memory.x, 4 MiB RAM): the M0's initial stack pointer goes to the
    // end of the micro:bit's RAM. `_stack_start` is a PROVIDE in cortex-m-rt's link.x.
    if std::env::var("TARGET").is_ok_and(|t| t.starts_with("thumbv6m")) {
        println!("cargo::rustc-link-arg-examples=--defsym=_stack_start=0x20004000");
    }
    // defmt's linker script (its .defmt section), for examples built with the `defmt`
    // feature (the defmt_log example); defmt's build script puts defmt.x on the search path.
    if std::env::var_os("CARGO_FEATURE_DEFMT").is_some() {
        println!("cargo::rustc-link-arg-examples=-Tdefmt.x");
    }
    // ---- end of example-only link arguments ----
}

/// Whether cargo auto-discovers at least one example in `dir`.
fn has_examples(dir: &Path) -> bool {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return false;
    };
    entries.flatten().any(|e| {
        let path = e.path();
        (path.is_file() && path.extension().is_some_and(|x| x == "rs")) || path.join("main.rs").is_file()
    })
}

fn env(name: &str) -> Result<String, String> {
    std::env::var(name).map_err(|_| format!("{name} is not set: build.rs runs under cargo"))
}

/// The set's name for the unfitted placeholder: its folder's name, reduced to the
/// characters a set name may have (so it is safe in Rust and C string literals).
fn set_name(set_dir: &Path) -> String {
    let name: String = set_dir
        .file_name()
        .map(|n| n.to_string_lossy())
        .unwrap_or_default()
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.') { c } else { '_' })
        .collect();
    if name.is_empty() {
        "unnamed".to_string()
    } else {
        name
    }
}
