//! The error of parsing, validating or generating: a file, a line and what is wrong.
use std::fmt;
use std::path::{Path, PathBuf};

/// Why a model file was refused (or could not be read or written).
///
/// `Display` gives `path:line: message` (or `path: message` when no line applies, as
/// for an unreadable file): the form compilers and editors understand.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CodegenError {
    /// The file the error is about (the model file, or an output file).
    pub path: PathBuf,
    /// 1-based line in `path`, when the error is about a place in the file.
    pub line: Option<usize>,
    /// What is wrong, on one line.
    pub message: String,
}

impl CodegenError {
    /// An error about the whole file (no line).
    pub fn file(path: &Path, message: impl Into<String>) -> Self {
        Self { path: path.to_path_buf(), line: None, message: one_line(&message.into()) }
    }

    /// An error at byte `offset` of `text`, the contents of `path`.
    pub fn at(path: &Path, text: &str, offset: usize, message: impl Into<String>) -> Self {
        Self { path: path.to_path_buf(), line: Some(line_of(text, offset)), message: one_line(&message.into()) }
    }
}

impl fmt::Display for CodegenError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}:{}: {}", self.path.display(), line, self.message),
            None => write!(f, "{}: {}", self.path.display(), self.message),
        }
    }
}

impl std::error::Error for CodegenError {}

/// 1-based line number of byte `offset` in `text` (offsets past the end give the last line).
pub fn line_of(text: &str, offset: usize) -> usize {
    let end = offset.min(text.len());
    1 + text.as_bytes().iter().take(end).filter(|&&b| b == b'\n').count()
}

/// Joins a multi-line message (as `toml` writes them) into one line.
fn one_line(message: &str) -> String {
    message.lines().map(str::trim).filter(|l| !l.is_empty()).collect::<Vec<_>>().join("; ")
}
