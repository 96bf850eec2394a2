//! The study layer's one error type: a single line of text for the user that names the file,
//! the line, the key or the option at fault. The command line prints it as `error: …` and exits
//! with status 2; Python raises it as `ValueError`.

use std::fmt;

/// Longest error line in characters: a longer message keeps its start and its end around a note
/// of how much was left out (a file with 200 000 columns must not print a megabyte-long "line").
pub const MAX_MESSAGE_CHARS: usize = 400;

/// Characters kept from the end of a message that is too long.
const KEPT_TAIL_CHARS: usize = 80;

/// `message` cut to [`MAX_MESSAGE_CHARS`] characters.
fn capped(message: String) -> String {
    let total = message.chars().count();
    if total <= MAX_MESSAGE_CHARS {
        return message;
    }
    // The note's length depends on the number it carries; 40 characters hold any count.
    let head = MAX_MESSAGE_CHARS - KEPT_TAIL_CHARS - 40;
    let left_out = total - head - KEPT_TAIL_CHARS;
    let start: String = message.chars().take(head).collect();
    let end: String = message.chars().skip(total - KEPT_TAIL_CHARS).collect();
    format!("{start} … [{left_out} characters left out] … {end}")
}

/// What kind of error a [`StudyError`] is, for a caller that treats some differently (the
/// message says the rest).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum StudyErrorKind {
    /// Anything else: a value, a file or an option that is not as expected.
    #[default]
    Invalid,
    /// A path written in an experiment file leads outside the experiment's directory and the
    /// caller did not allow that ([`crate::experiment::Paths`]).
    PathOutside,
    /// The instants of a data file's `t` column, read for an experiment's `[sampling]`, are not
    /// a uniform grid `t0 + kT` (the message names the row that breaks it).
    NotUniformGrid,
}

/// An error reported to the user as one line (`error: …` on the command line's stderr).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StudyError {
    message: String,
    kind: StudyErrorKind,
}

impl StudyError {
    /// An error with this message (newlines are folded into spaces, so the report is one line,
    /// and a message longer than [`MAX_MESSAGE_CHARS`] is shortened in the middle).
    pub fn new(message: impl Into<String>) -> Self {
        let message: String = message.into();
        let message = message
            .split(['\n', '\r'])
            .map(str::trim)
            .filter(|s| !s.is_empty())
            .collect::<Vec<_>>()
            .join(" ");
        Self {
            message: capped(message),
            kind: StudyErrorKind::Invalid,
        }
    }

    /// The same error, of `kind`.
    #[must_use]
    pub fn with_kind(mut self, kind: StudyErrorKind) -> Self {
        self.kind = kind;
        self
    }

    /// What kind of error it is.
    pub fn kind(&self) -> StudyErrorKind {
        self.kind
    }

    /// The message.
    pub fn message(&self) -> &str {
        &self.message
    }

    /// The same error with `prefix: ` in front.
    pub fn context(self, prefix: impl fmt::Display) -> Self {
        Self::new(format!("{prefix}: {}", self.message)).with_kind(self.kind)
    }
}

impl fmt::Display for StudyError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for StudyError {}

/// Result with a [`StudyError`].
pub type StudyResult<T> = Result<T, StudyError>;

/// Builds a [`StudyError`] with `format!` syntax.
#[macro_export]
macro_rules! study_err {
    ($($arg:tt)*) => {
        $crate::error::StudyError::new(format!($($arg)*))
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_messages_keep_start_and_end() {
        let long = format!("start {} end", "x".repeat(1_000_000));
        let e = StudyError::new(long);
        let m = e.message();
        assert!(m.chars().count() <= MAX_MESSAGE_CHARS, "{}", m.len());
        assert!(m.starts_with("start xxx"), "{m}");
        assert!(m.ends_with("xxx end"), "{m}");
        assert!(m.contains("characters left out"), "{m}");
        let short = StudyError::new("a\nb");
        assert_eq!(short.message(), "a b");
    }
}
