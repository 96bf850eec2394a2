//! The plain numeric CSV files of the study layer and its front ends: numeric tables
//! ([`Table`], [`parse`], [`format()`]) and measured records ([`load_record`],
//! [`save_record`]), with errors ([`CsvError`]) that name the file, the line and the column
//! (a [`StudyError`](crate::StudyError) through `?`).

mod error;
mod record_io;
mod table;

pub use error::{io_reason, CsvError};
pub use record_io::{
    input_from_table, input_side_file, input_to_csv, inputs_to_csv, load_record, piecewise,
    record_from_table, record_to_csv, save_record,
};
pub use table::{
    check_regular_file, excerpt, format, open_rows, parse, read, read_as, read_text, Column, Rows,
    Table, MAX_EXCERPT_CHARS, MAX_FILE_BYTES,
};

impl From<CsvError> for crate::error::StudyError {
    fn from(e: CsvError) -> Self {
        crate::error::StudyError::new(e.to_string())
    }
}
