//! [`ModelFileError`]: why `model.toml` could not be read, a variant per kind of refusal
//! so that a caller or a test tells them apart; every message starts with the file (and
//! its line where one applies).

use std::path::PathBuf;

/// Why a model file was refused by [`model_file::read`](crate::model_file::read) or
/// [`model_file::parse`](crate::model_file::parse).
#[derive(Debug, thiserror::Error)]
pub enum ModelFileError {
    /// The file cannot be read (there is no fitted model yet, most often).
    #[error("{}: cannot read the model ({error}); run `needle fit` first", path.display())]
    Read {
        /// The model file.
        path: PathBuf,
        /// Why (not a `source`: the message already says it).
        error: std::io::Error,
    },
    /// Refused by the generator's reader, which the library's build uses too: the file,
    /// the line and what is wrong ([`needle_codegen::CodegenError`]).
    #[error(transparent)]
    Invalid(#[from] needle_codegen::CodegenError),
    /// A coupled form that is not one of the forms the fitter chooses from.
    #[error("{path}: [coupled] max_degree = {max_degree}, depth_degree = {depth_degree}: not one of the forms the fitter chooses from")]
    UnknownForm {
        /// The model file, as shown.
        path: String,
        /// `[coupled] max_degree`.
        max_degree: u8,
        /// `[coupled] depth_degree`.
        depth_degree: u8,
    },
    /// `[[cross]]` entries that are not the form's monomials in the fitter's order (one
    /// out of order, one missing, one too many).
    #[error("{at}: {message}")]
    CrossTerms {
        /// The model file, with the entry's line when there is one.
        at: String,
        /// Which entry, and what was expected.
        message: String,
    },
}
