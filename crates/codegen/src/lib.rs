//! Build-time code generation for `needle-haptics`.
//!
//! Reads and validates a set's `model.toml` (format and evaluation contract:
//! `coeffs/README.md`) and writes two files into an output folder (the library's
//! `OUT_DIR` when called from `build.rs`):
//!
//! - [`RUST_TABLES_FILE`] (`tables_f32.rs`): `pub const` f32 tables, every coefficient an
//!   exact decimal literal with its bits in a comment, and per polynomial its domain and
//!   the fit's residual against FE (the model's error bound, libm style);
//! - [`C_HEADER_FILE`] (`needle_coeffs.h`): the same tables for C users;
//! - [`RUST_CROSS_FILE`] (`cross_f32.rs`): the coupled form's cross terms as straight-line
//!   f32 code (empty for the paper form), see `render_cross`, and [`RUST_CROSS_FIXED_FILE`]
//!   (`cross_fixed.rs`) the same in fixed point;
//! - [`RUST_FIXED_TABLES_FILE`] (`tables_fixed.rs`): the fixed-point tables ([`fixed`]):
//!   Q formats chosen from the coefficients so that no integer intermediate can overflow,
//!   the integer coefficients, and the derived error bound against f64;
//! - [`unsolved::RUST_FILE`] (`unsolved.rs`): the set's unsolved region (`unsolved.toml`
//!   beside `model.toml`, optional), see [`unsolved`].
//!
//! Every refusal is a [`CodegenError`] naming the file and the line (`path:line: what is
//! wrong`). It is a library, so the checks are testable without running cargo.
#![forbid(unsafe_code)]
#![deny(missing_docs)]

pub mod contract;
pub mod depth_extension;
mod error;
pub mod family;
pub mod fixed;
mod fixed_bound;
mod literal;
mod model;
mod render;
mod render_cross;
mod render_fixed;
pub mod tissue;
pub mod unsolved;

pub use error::{line_of, CodegenError};
pub use fixed::FixedTables;
pub use fixed_bound::fixed_tables;
pub use literal::f32_literal;
pub use model::{parse_bits, parse_model, parse_model_str, Baseline, Coupled, Cross, Matrix, Model};
pub use render::{render_c_header, render_rust};
pub use render_cross::{render_c_cross, render_rust_cross, render_rust_cross_fixed};
pub use render_fixed::render_rust_fixed;

use std::path::{Path, PathBuf};

/// File name of the generated Rust tables in the output folder.
pub const RUST_TABLES_FILE: &str = "tables_f32.rs";
/// File name of the generated cross terms of the coupled form (f32) in the output folder.
pub const RUST_CROSS_FILE: &str = "cross_f32.rs";
/// File name of the generated cross terms of the coupled form (fixed point).
pub const RUST_CROSS_FIXED_FILE: &str = "cross_fixed.rs";
/// File name of the generated fixed-point tables in the output folder.
pub const RUST_FIXED_TABLES_FILE: &str = "tables_fixed.rs";
/// File name of the generated C header in the output folder.
pub const C_HEADER_FILE: &str = "needle_coeffs.h";
/// File name of the model inside a set folder.
pub const MODEL_FILE: &str = "model.toml";

/// What [`generate`] produced.
#[derive(Debug, Clone, PartialEq)]
pub struct Generated {
    /// The validated model (the all-zero placeholder for [`generate_unfitted`]).
    pub model: Model,
    /// Text of `tables_f32.rs`.
    pub rust: String,
    /// Text of `needle_coeffs.h`.
    pub c_header: String,
    /// The fixed-point tables.
    pub fixed: FixedTables,
    /// Text of `tables_fixed.rs`.
    pub rust_fixed: String,
    /// Text of `cross_f32.rs`.
    pub rust_cross: String,
    /// Text of `cross_fixed.rs`.
    pub rust_cross_fixed: String,
    /// The unsolved region (empty without `unsolved.toml`).
    pub unsolved: unsolved::Region,
    /// Text of `unsolved.rs`.
    pub rust_unsolved: String,
    /// Where `tables_f32.rs` was written.
    pub rust_path: PathBuf,
    /// Where `needle_coeffs.h` was written.
    pub c_header_path: PathBuf,
}

/// Validates the model at `model_path` and the unsolved region beside it
/// ([`unsolved::FILE`], when present) and writes [`RUST_TABLES_FILE`], [`C_HEADER_FILE`],
/// [`RUST_FIXED_TABLES_FILE`], the cross terms and [`unsolved::RUST_FILE`] into `out_dir`
/// (which must exist). A file whose contents would not change is not rewritten.
///
/// # Errors
/// The model file is unreadable, is not valid TOML or departs from the contract (the
/// error has its line), a matrix or component does not fit the fixed-point evaluator
/// ([`fixed_tables`]), the unsolved region is refused ([`unsolved::parse`]), or an output
/// file cannot be written.
pub fn generate(model_path: &Path, out_dir: &Path) -> Result<Generated, CodegenError> {
    let model = parse_model(model_path)?;
    let region_path = model_path.with_file_name(unsolved::FILE);
    let region = if region_path.is_file() { unsolved::parse(&region_path)? } else { unsolved::Region::default() };
    write_all(model, region, model_path, out_dir)
}

/// Writes the placeholder tables of a set that has no `model.toml` yet: every table is
/// zero and `FITTED` is `false`, so the library's evaluator answers `NO_MODEL | ERROR`.
/// `set` is the set's name (its folder's name).
///
/// # Errors
/// An output file cannot be written.
pub fn generate_unfitted(set: &str, out_dir: &Path) -> Result<Generated, CodegenError> {
    write_all(Model::unfitted(set), unsolved::Region::default(), Path::new(MODEL_FILE), out_dir)
}

fn write_all(model: Model, region: unsolved::Region, model_path: &Path, out_dir: &Path) -> Result<Generated, CodegenError> {
    let fixed = fixed_tables(&model, model_path)?;
    let rust = render_rust(&model);
    let c_header = render::render_c_header_with(&model, &unsolved::render_c(&region));
    let rust_unsolved = unsolved::render(&region);
    let rust_fixed = render_rust_fixed(&model, &fixed);
    let rust_cross = render_rust_cross(&model);
    let rust_cross_fixed = render_rust_cross_fixed(&model, &fixed);
    let rust_path = out_dir.join(RUST_TABLES_FILE);
    let c_header_path = out_dir.join(C_HEADER_FILE);
    write_if_changed(&rust_path, &rust)?;
    write_if_changed(&c_header_path, &c_header)?;
    write_if_changed(&out_dir.join(RUST_FIXED_TABLES_FILE), &rust_fixed)?;
    write_if_changed(&out_dir.join(RUST_CROSS_FILE), &rust_cross)?;
    write_if_changed(&out_dir.join(RUST_CROSS_FIXED_FILE), &rust_cross_fixed)?;
    write_if_changed(&out_dir.join(unsolved::RUST_FILE), &rust_unsolved)?;
    Ok(Generated {
        model,
        rust,
        c_header,
        fixed,
        rust_fixed,
        rust_cross,
        rust_cross_fixed,
        unsolved: region,
        rust_unsolved,
        rust_path,
        c_header_path,
    })
}

/// Checks the set's depth extension (`<set>/depth-extension.toml`, optional) and tissue
/// stacks (`<set>/tissue/*.toml`) and writes [`depth_extension::RUST_FILE`],
/// [`family::RUST_FILE`] (from `<set>/family.toml`, optional) and
/// [`tissue::RUST_TISSUE_FILE`] into `out_dir`; returns the files to watch (for
/// `rerun-if-changed`). A set without a `tissue/` folder gets an empty `ALL`.
///
/// # Errors
/// A tissue file is refused ([`tissue::parse_stack`], with its line) or the output
/// cannot be written.
pub fn generate_tissue(set_dir: &Path, out_dir: &Path) -> Result<Vec<PathBuf>, CodegenError> {
    let extension_path = set_dir.join(depth_extension::FILE);
    let extension = if extension_path.is_file() { Some(depth_extension::parse(&extension_path)?) } else { None };
    write_if_changed(&out_dir.join(depth_extension::RUST_FILE), &depth_extension::render(extension.as_ref()))?;
    let family_path = set_dir.join(family::FILE);
    let law = if family_path.is_file() { Some(family::parse(&family_path)?) } else { None };
    write_if_changed(&out_dir.join(family::RUST_FILE), &family::render(law.as_ref()))?;
    let stacks = tissue::read_stacks(set_dir)?;
    let needle = tissue::read_fe_needle(set_dir)?;
    write_if_changed(&out_dir.join(tissue::RUST_TISSUE_FILE), &tissue::render_rust_stacks(&stacks, needle))?;
    let mut read: Vec<PathBuf> = stacks.into_iter().map(|(p, _)| p).collect();
    read.push(extension_path);
    read.push(family_path);
    Ok(read)
}

fn write_if_changed(path: &Path, text: &str) -> Result<(), CodegenError> {
    if std::fs::read_to_string(path).is_ok_and(|old| old == text) {
        return Ok(());
    }
    std::fs::write(path, text).map_err(|e| CodegenError::file(path, format!("cannot write: {e}")))
}
