//! [`SpecError`]: why a campaign spec was refused, a variant per kind of refusal so that
//! a caller or a test tells them apart without reading the text. Every message starts
//! with the spec's file, and its line where the TOML reader or the `[deep]` check
//! knows it (`campaign.toml:12: ...`).

use std::fmt::Display;
use std::path::PathBuf;

/// Why a campaign spec was refused. `at` is where: the spec's path, or `path:line`;
/// `field` the key the refusal is about, dotted as in the file (`loading.steps`,
/// `mesh.needle8.growth`, `pose.x_mm`); `message` the rest of the line.
#[derive(Debug, thiserror::Error)]
pub enum SpecError {
    /// The file cannot be read.
    #[error("{}: cannot read the campaign spec", path.display())]
    Read {
        /// The spec's path.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// Not TOML, or not the spec's tables and keys (a missing key, a value of the wrong
    /// type, an unknown key).
    #[error("{}:{line}: {message}", path.display())]
    Syntax {
        /// The spec's path.
        path: PathBuf,
        /// 1-based line of the error (0: unknown).
        line: usize,
        /// The TOML reader's words.
        message: String,
    },
    /// A value outside its range or its set of choices.
    #[error("{at}: {message}")]
    OutOfRange {
        /// Where.
        at: String,
        /// Which key.
        field: String,
        /// The value and its range.
        message: String,
    },
    /// Values that contradict each other, in one section or across sections.
    #[error("{at}: {message}")]
    Inconsistent {
        /// Where.
        at: String,
        /// The key refused (the others are named in the message).
        field: String,
        /// What contradicts what.
        message: String,
    },
    /// A name the spec does not define: a mesh level, a pose.
    #[error("{at}: {message}")]
    Unknown {
        /// Where.
        at: String,
        /// The key that names it.
        field: String,
        /// The name.
        name: String,
        /// The message.
        message: String,
    },
    /// A name listed twice.
    #[error("{at}: {message}")]
    Duplicate {
        /// Where.
        at: String,
        /// The list.
        field: String,
        /// The name.
        name: String,
        /// The message.
        message: String,
    },
    /// A refusal of the `[viscoelastic]` section (`spec::visco`, not yet split by kind:
    /// its message has the file, the line and the field).
    #[error(transparent)]
    Viscoelastic(anyhow::Error),
    /// A pose whose needle leaves the block (at entry or at full depth).
    #[error("{at}: {message}")]
    OutsideBlock {
        /// Where.
        at: String,
        /// The pose.
        pose: String,
        /// How far the needle reaches, and where the block's side is.
        message: String,
    },
}

impl SpecError {
    /// [`SpecError::OutOfRange`].
    pub fn range(at: impl Display, field: impl Into<String>, message: impl Into<String>) -> Self {
        SpecError::OutOfRange { at: at.to_string(), field: field.into(), message: message.into() }
    }

    /// [`SpecError::Inconsistent`].
    pub fn inconsistent(at: impl Display, field: impl Into<String>, message: impl Into<String>) -> Self {
        SpecError::Inconsistent { at: at.to_string(), field: field.into(), message: message.into() }
    }

    /// [`SpecError::Unknown`].
    pub fn unknown(at: impl Display, field: impl Into<String>, name: impl Into<String>, message: impl Into<String>) -> Self {
        SpecError::Unknown { at: at.to_string(), field: field.into(), name: name.into(), message: message.into() }
    }

    /// [`SpecError::Duplicate`].
    pub fn duplicate(at: impl Display, field: impl Into<String>, name: impl Into<String>, message: impl Into<String>) -> Self {
        SpecError::Duplicate { at: at.to_string(), field: field.into(), name: name.into(), message: message.into() }
    }

    /// The error with the line of its key in `text` (the spec's text) added to `at` when
    /// `at` has none and the key is found: `field` `"section.key"` or `"mesh.<level>.key"`
    /// (array tables such as `[[pose]]` have no single line and stay as they are).
    #[must_use]
    pub fn located(self, text: &str) -> Self {
        let with_line = |at: String, field: &str| -> String {
            let Some((section, key)) = field.rsplit_once('.') else { return at };
            if at.contains(':') || section == "pose" {
                return at;
            }
            match crate::spec::key_line(text, section, key) {
                0 => at,
                line => format!("{at}:{line}"),
            }
        };
        match self {
            SpecError::OutOfRange { at, field, message } => SpecError::OutOfRange { at: with_line(at, &field), field, message },
            SpecError::Inconsistent { at, field, message } => SpecError::Inconsistent { at: with_line(at, &field), field, message },
            SpecError::Unknown { at, field, name, message } => SpecError::Unknown { at: with_line(at, &field), field, name, message },
            SpecError::Duplicate { at, field, name, message } => SpecError::Duplicate { at: with_line(at, &field), field, name, message },
            other => other,
        }
    }

    /// Where: the spec's path, or `path:line`.
    pub fn at(&self) -> String {
        match self {
            SpecError::Read { path, .. } => path.display().to_string(),
            SpecError::Viscoelastic(e) => e.to_string().split(": ").next().unwrap_or_default().to_string(),
            SpecError::Syntax { path, line, .. } => format!("{}:{line}", path.display()),
            SpecError::OutOfRange { at, .. }
            | SpecError::Inconsistent { at, .. }
            | SpecError::Unknown { at, .. }
            | SpecError::Duplicate { at, .. }
            | SpecError::OutsideBlock { at, .. } => at.clone(),
        }
    }

    /// The key the refusal is about (`""` for [`SpecError::Read`]; `""` for
    /// [`SpecError::Syntax`], whose key is in the TOML reader's words).
    pub fn field(&self) -> &str {
        match self {
            SpecError::Read { .. } | SpecError::Syntax { .. } => "",
            SpecError::Viscoelastic(_) => "viscoelastic",
            SpecError::OutsideBlock { .. } => "pose",
            SpecError::OutOfRange { field, .. }
            | SpecError::Inconsistent { field, .. }
            | SpecError::Unknown { field, .. }
            | SpecError::Duplicate { field, .. } => field,
        }
    }
}

/// The result of reading or checking a spec.
pub type SpecResult<T> = std::result::Result<T, SpecError>;
