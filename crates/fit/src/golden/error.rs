//! [`GoldenCsvError`]: why a golden file was refused, a variant per kind of refusal;
//! every message starts with `file:line`.

/// Why a golden CSV file was refused by one of the `parse_csv` readers.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum GoldenCsvError {
    /// The first line is not the file's header.
    #[error("{path}:1: expected the header {expected:?}")]
    Header {
        /// The file, as shown.
        path: String,
        /// The header the file must start with.
        expected: String,
    },
    /// A row with another number of fields than the header.
    #[error("{at}: {found} fields, expected {expected}")]
    FieldCount {
        /// `file:line`.
        at: String,
        /// Fields in the row.
        found: usize,
        /// Fields in the header.
        expected: usize,
    },
    /// A status that is not `0x` and two hex digits.
    #[error("{at}: status {value:?} is not 0x + 2 hex digits")]
    Status {
        /// `file:line`.
        at: String,
        /// The field as written.
        value: String,
    },
    /// A pose or output value that is not the column's form (`0x` and 8 hex digits for
    /// f32 bits, an `i32` for the fixed-point files).
    #[error("{at}: {message}")]
    Value {
        /// `file:line`.
        at: String,
        /// The field as written.
        value: String,
        /// What it should be.
        message: String,
    },
}

impl GoldenCsvError {
    /// A field that is not `0x` and 8 hex digits (the bits of an f32).
    pub fn hex32(at: &str, value: &str) -> Self {
        GoldenCsvError::Value { at: at.to_string(), value: value.to_string(), message: format!("field {value:?} is not 0x + 8 hex digits") }
    }

    /// A field that is not an `i32`.
    pub fn int(at: &str, value: &str) -> Self {
        GoldenCsvError::Value { at: at.to_string(), value: value.to_string(), message: format!("{value:?} is not an i32") }
    }
}
