//! Why a CSV file could not be read: the file's name, the line and column (1-based) where it
//! goes wrong, and what was expected.

use thiserror::Error;

/// A CSV problem. Displayed as `file:line:column: message` (the parts that are known).
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum CsvError {
    /// A problem at a place in the file.
    #[error("{}: {message}", place(name, *line, *column))]
    At {
        /// The file's name.
        name: String,
        /// The line (1-based), if the problem has one.
        line: Option<usize>,
        /// The column in characters (1-based) where the offending cell starts, if any.
        column: Option<usize>,
        /// What is wrong.
        message: String,
    },
    /// The file could not be read.
    #[error("{name}: {reason}")]
    Io {
        /// The file's name.
        name: String,
        /// Why (`cannot read: file does not exist`, `not a regular file`, …).
        reason: String,
    },
}

fn place(name: &str, line: Option<usize>, column: Option<usize>) -> String {
    match (line, column) {
        (Some(l), Some(c)) => format!("{name}:{l}:{c}"),
        (Some(l), None) => format!("{name}:{l}"),
        _ => name.to_string(),
    }
}

impl CsvError {
    /// A problem at `line`, `column` of `name`.
    pub fn at(
        name: &str,
        line: Option<usize>,
        column: Option<usize>,
        message: impl Into<String>,
    ) -> Self {
        CsvError::At {
            name: name.to_string(),
            line,
            column,
            message: message.into(),
        }
    }

    /// The line of the problem, if it has one.
    pub fn line(&self) -> Option<usize> {
        match self {
            CsvError::At { line, .. } => *line,
            CsvError::Io { .. } => None,
        }
    }

    /// The column of the problem, if it has one.
    pub fn column(&self) -> Option<usize> {
        match self {
            CsvError::At { column, .. } => *column,
            CsvError::Io { .. } => None,
        }
    }
}

/// A short reason for an I/O error (`file does not exist`, …).
pub fn io_reason(e: &std::io::Error) -> String {
    match e.kind() {
        std::io::ErrorKind::NotFound => "file does not exist".into(),
        std::io::ErrorKind::PermissionDenied => "permission denied".into(),
        _ => e.to_string(),
    }
}
