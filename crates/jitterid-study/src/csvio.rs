//! The plain numeric CSV files of the command line, read and written by the library
//! ([`jitterid::estimate::csv`], which documents the format); this module turns the library's
//! typed errors into the command line's one-line messages.

use crate::error::{StudyError, StudyResult};
pub use jitterid::estimate::csv::{format, io_reason, Column, CsvError, Table, MAX_FILE_BYTES};
use std::path::Path;

impl From<CsvError> for StudyError {
    fn from(e: CsvError) -> Self {
        StudyError::new(e.to_string())
    }
}

/// Parses CSV text; `name` is used in messages.
pub fn parse(name: &str, text: &str) -> StudyResult<Table> {
    Ok(jitterid::estimate::csv::parse(name, text)?)
}

/// Reads and parses a CSV file.
pub fn read(path: &Path) -> StudyResult<Table> {
    Ok(jitterid::estimate::csv::read(path)?)
}

/// Fails unless `path` is a regular file of at most [`MAX_FILE_BYTES`].
pub fn check_regular_file(path: &Path, name: &str) -> StudyResult<()> {
    Ok(jitterid::estimate::csv::check_regular_file(path, name)?)
}
