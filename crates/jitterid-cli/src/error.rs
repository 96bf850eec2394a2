//! The command line's one error type: a single line of text for the user, exit status 2.

use std::fmt;

/// An error reported to the user as one line on stderr (`error: …`), with exit status 2.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CliError {
    message: String,
}

impl CliError {
    /// An error with this message (newlines are folded into spaces, so the report is one line).
    pub fn new(message: impl Into<String>) -> Self {
        let message: String = message.into();
        let message = message
            .split(['\n', '\r'])
            .map(str::trim)
            .filter(|s| !s.is_empty())
            .collect::<Vec<_>>()
            .join(" ");
        Self { message }
    }

    /// The message.
    pub fn message(&self) -> &str {
        &self.message
    }

    /// The same error with `prefix: ` in front.
    pub fn context(self, prefix: impl fmt::Display) -> Self {
        Self::new(format!("{prefix}: {}", self.message))
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for CliError {}

/// Result with a [`CliError`].
pub type CliResult<T> = Result<T, CliError>;

/// Builds a [`CliError`] with `format!` syntax.
#[macro_export]
macro_rules! cli_err {
    ($($arg:tt)*) => {
        $crate::error::CliError::new(format!($($arg)*))
    };
}
