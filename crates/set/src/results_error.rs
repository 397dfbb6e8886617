//! [`CsvError`]: why an FE result file (`fe/<pose>.csv`) was refused, a variant per kind of
//! refusal so that a caller or a test tells them apart without reading the text. Every
//! message starts with `path:line`.

use std::path::PathBuf;

/// Most characters of a bad line or field echoed in a message.
pub const MAX_ECHO_CHARS: usize = 80;

/// `text` as a message shows it: quoted, cut after `max_chars` characters with its
/// length in bytes then.
pub fn echo_cut(text: &str, max_chars: usize) -> String {
    match text.char_indices().nth(max_chars) {
        Some((cut, _)) => format!("{:?}... ({} bytes)", text.get(..cut).unwrap_or(""), text.len()),
        None => format!("{text:?}"),
    }
}

/// [`echo_cut`] after [`MAX_ECHO_CHARS`] characters.
fn echo(text: &str) -> String {
    echo_cut(text, MAX_ECHO_CHARS)
}

/// Why an FE result file was refused. `line` is 1-based; `field` the 1-based column.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum CsvError {
    /// The file holds no line at all.
    #[error("{}:1: empty file, expected the header {expected:?}", path.display())]
    Empty {
        /// The file.
        path: PathBuf,
        /// The header it should start with.
        expected: String,
    },
    /// The first line is not the contract's header.
    #[error("{}:1: header is {}, expected {expected:?}", path.display(), echo(found))]
    Header {
        /// The file.
        path: PathBuf,
        /// The first line as found.
        found: String,
        /// The contract's header.
        expected: String,
    },
    /// A row without one field per column.
    #[error("{}:{line}: {found} fields, expected {expected}: {}", path.display(), echo(text))]
    FieldCount {
        /// The file.
        path: PathBuf,
        /// The row's line.
        line: usize,
        /// Fields in the row.
        found: usize,
        /// Columns of the header.
        expected: usize,
        /// The row.
        text: String,
    },
    /// A field that does not read as a number.
    #[error("{}:{line}: field {field} = {} is not a number", path.display(), echo(text))]
    NotANumber {
        /// The file.
        path: PathBuf,
        /// The row's line.
        line: usize,
        /// The field's column, 1-based.
        field: usize,
        /// The field.
        text: String,
    },
    /// A field that reads as NaN or an infinity.
    #[error("{}:{line}: field {field} = {} is not finite", path.display(), echo(text))]
    NotFinite {
        /// The file.
        path: PathBuf,
        /// The row's line.
        line: usize,
        /// The field's column, 1-based.
        field: usize,
        /// The field.
        text: String,
    },
}
