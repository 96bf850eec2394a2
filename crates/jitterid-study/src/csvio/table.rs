//! The plain numeric CSV files of the project: parsing with errors that name the line and the
//! column, and formatting that reads back to the same values.
//!
//! The format: a header line of column names, then one line per row of numbers, all separated by
//! commas. Blank lines and lines starting with `#` are skipped. Every cell must parse as a
//! finite number (`1`, `-0.25`, `3e-4`); every row has as many cells as the header. There is no
//! quoting (names may be wrapped in double quotes, which are removed). Lines end with LF, CR LF
//! or a lone CR (old Mac files). Problems are named as `file:line:column:` (both 1-based, the
//! column counted in characters to the start of the cell).
//!
//! Lines are split into cells by the [`csv`] crate's reader with quoting off; this module
//! skips blank and comment lines, numbers the lines (the reader counts LF only) and checks the
//! cells. Writing is a plain join: numbers and the project's column names never need quoting.

use super::error::{io_reason, CsvError};
use std::collections::{HashSet, VecDeque};
use std::io::Read;
use std::path::Path;

/// A parsed CSV file: named numeric columns of equal length.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// The file's name, for messages.
    pub name: String,
    /// Line of the header (1-based).
    pub header_line: usize,
    /// Column names, in file order.
    pub columns: Vec<String>,
    /// The values, one vector per column.
    pub values: Vec<Vec<f64>>,
    /// The line (1-based) of every row.
    pub lines: Vec<usize>,
}

impl Table {
    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.lines.len()
    }

    /// Index of a column.
    pub fn index(&self, name: &str) -> Option<usize> {
        self.columns.iter().position(|c| c == name)
    }

    /// The values of a column, or an error naming the header and what was expected.
    ///
    /// # Errors
    ///
    /// [`CsvError::At`] at the header line when there is no such column.
    pub fn column(&self, name: &str) -> Result<&[f64], CsvError> {
        match self.index(name) {
            Some(i) => Ok(&self.values[i]),
            None => Err(missing_column(
                &self.name,
                self.header_line,
                &self.columns,
                name,
            )),
        }
    }

    /// The values of a column if it is there.
    pub fn optional(&self, name: &str) -> Option<&[f64]> {
        self.index(name).map(|i| self.values[i].as_slice())
    }

    /// An error at `line` of this file (no column).
    pub fn error(&self, line: Option<usize>, message: impl Into<String>) -> CsvError {
        CsvError::at(&self.name, line, None, message)
    }

    /// An error at row `row` (0-based) of column `column`.
    pub fn cell_error(&self, row: usize, column: &str, message: impl Into<String>) -> CsvError {
        let line = self.lines.get(row).copied();
        CsvError::at(
            &self.name,
            line,
            None,
            format!("column `{}`: {}", shorten(column), message.into()),
        )
    }
}

fn clean_name(s: &str) -> &str {
    let s = s.trim();
    s.strip_prefix('"')
        .and_then(|s| s.strip_suffix('"'))
        .unwrap_or(s)
        .trim()
}

/// A reader of the format: no quoting (every field is kept as written), `,` between fields,
/// records ending at LF, CR LF or a lone CR; a UTF-8 byte-order mark at the start is dropped
/// and empty lines are skipped by the reader itself.
fn reader<R: Read>(input: R) -> csv::Reader<LineEndLog<R>> {
    csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .quoting(false)
        .terminator(csv::Terminator::CRLF)
        .from_reader(LineEndLog::new(input))
}

/// The input of the `csv` reader, logging where the line-end bytes (`\r`, `\n`) it passes on
/// are, so that a record's line can be told without keeping the text (the `csv` reader counts
/// LF only). Only the line ends the reader has read ahead of the last record are kept (a few
/// per buffer of the reader), so a file of any length is read in constant memory.
struct LineEndLog<R> {
    input: R,
    /// Bytes passed on so far.
    passed: u64,
    /// The first three bytes (a byte-order mark?).
    first: [u8; 3],
    /// Offset and byte of each `\r` and `\n` passed on and not yet counted.
    ends: VecDeque<(u64, u8)>,
    /// Most bytes passed on before the read fails: the file's size bound.
    limit: u64,
}

impl<R: Read> LineEndLog<R> {
    fn new(input: R) -> Self {
        Self {
            input,
            passed: 0,
            first: [0; 3],
            ends: VecDeque::new(),
            limit: u64::MAX,
        }
    }

    fn has_bom(&self) -> bool {
        self.passed >= 3 && self.first == *"\u{feff}".as_bytes()
    }
}

impl<R: Read> Read for LineEndLog<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.input.read(buf)?;
        for (i, &b) in buf[..n].iter().enumerate() {
            let at = self.passed + i as u64;
            if at < 3 {
                self.first[at as usize] = b;
            }
            if b == b'\r' || b == b'\n' {
                self.ends.push_back((at, b));
            }
        }
        self.passed += n as u64;
        if self.passed > self.limit {
            return Err(std::io::Error::other(format!(
                "grew beyond {} bytes while being read",
                self.limit
            )));
        }
        Ok(n)
    }
}

/// The 1-based line of each record, counted here because the `csv` reader counts LF only: a
/// lone CR ends a line too, and CR LF is one line end.
struct LineCounter {
    /// Bytes counted so far (up to the end of the last record).
    at: u64,
    /// Line ends among them.
    ends: usize,
}

impl LineCounter {
    fn new() -> Self {
        Self { at: 0, ends: 0 }
    }

    /// The line of a record of `len` bytes that the reader read from byte `from` on, and the
    /// offset of its first byte: past the byte-order mark and the line ends (of empty lines)
    /// that the reader skipped before it. A record holds no line end, so only the line-end
    /// bytes logged between records are counted: a `\n`, and a `\r` not followed by `\n`.
    fn line_of(&mut self, log: &mut LineEndLog<impl Read>, from: u64, len: usize) -> (usize, u64) {
        let mut start = from.max(self.at);
        if start == 0 && log.has_bom() {
            start = 3;
        }
        let mut pending_cr: Option<u64> = None;
        while let Some(&(at, b)) = log.ends.front() {
            if at < start {
                // A terminator of the record before, or a line end the reader skipped.
            } else if at == start {
                // The record starts after this run of line ends.
                start += 1;
            } else {
                break;
            }
            log.ends.pop_front();
            if let Some(cr) = pending_cr.take() {
                if !(b == b'\n' && at == cr + 1) {
                    self.ends += 1;
                }
            }
            if b == b'\r' {
                pending_cr = Some(at);
            } else {
                self.ends += 1;
            }
        }
        if pending_cr.is_some() {
            self.ends += 1;
        }
        self.at = start + len as u64;
        (self.ends + 1, start)
    }
}

/// The cells of a record, each with its 1-based column (in characters) where it starts.
fn cells_of<'a>(record: &[&'a str]) -> Vec<(usize, &'a str)> {
    let mut col = 1;
    record
        .iter()
        .map(|&cell| {
            let start = col + cell.chars().take_while(|c| c.is_whitespace()).count();
            col += cell.chars().count() + 1;
            (start, cell)
        })
        .collect()
}

/// The length of a record's line in characters.
fn line_chars(record: &[&str]) -> usize {
    record.iter().map(|c| c.chars().count()).sum::<usize>() + record.len().saturating_sub(1)
}

/// Whether a record is a line to skip: blank, or a comment (`#` after optional white space).
fn skipped(record: &[&str]) -> bool {
    let first = record.first().copied().unwrap_or("").trim_start();
    (record.len() == 1 && first.is_empty()) || first.starts_with('#')
}

/// The fields of a record read as bytes, checked to be UTF-8 text; the error gives the
/// offset in the file of the first byte that is not (the record starts at `start`).
fn fields_of(record: &csv::ByteRecord, start: u64) -> Result<Vec<&str>, u64> {
    let mut fields = Vec::with_capacity(record.len());
    let mut offset = start;
    for field in record.iter() {
        match std::str::from_utf8(field) {
            Ok(s) => fields.push(s),
            Err(e) => return Err(offset + e.valid_up_to() as u64),
        }
        // The field and the comma after it.
        offset += field.len() as u64 + 1;
    }
    Ok(fields)
}

/// The next record to check of `rdr` (read into `record`), with its line; `None` at the end
/// of the input. Blank and comment lines are skipped.
fn next_record<'r, R: Read>(
    name: &str,
    rdr: &mut csv::Reader<LineEndLog<R>>,
    lines: &mut LineCounter,
    record: &'r mut csv::ByteRecord,
) -> Result<Option<(usize, Vec<&'r str>)>, CsvError> {
    let (line, start) = loop {
        let from = rdr.position().byte();
        let more = rdr
            .read_byte_record(record)
            .map_err(|e| match e.into_kind() {
                csv::ErrorKind::Io(e) => CsvError::Io {
                    name: name.to_string(),
                    reason: format!("cannot read: {}", io_reason(&e)),
                },
                // Reading without quoting fails only on I/O; anything else is still reported,
                // not lost.
                other => CsvError::at(name, None, None, format!("{other:?}")),
            })?;
        if !more {
            return Ok(None);
        }
        let len = record.as_slice().len() + record.len().saturating_sub(1);
        let (line, start) = lines.line_of(rdr.get_mut(), from, len);
        let fields = fields_of(record, start).map_err(|offset| CsvError::Io {
            name: name.to_string(),
            reason: format!(
                "not UTF-8 text (invalid byte at offset {offset}); expected a CSV file"
            ),
        })?;
        if !skipped(&fields) {
            break (line, start);
        }
    };
    // Checked in the loop; split again so that the fields borrow the record for the caller.
    Ok(Some((line, fields_of(record, start).unwrap_or_default())))
}

/// The rows of a CSV text, read one at a time from any reader: a header of column names, then
/// rows of finite numbers, each checked as it is read (line and column named on error). Only
/// the current row is held, so a file of any length is read in constant memory; [`parse`] and
/// [`read`] collect the rows into a [`Table`].
pub struct Rows<R: Read> {
    name: String,
    rdr: csv::Reader<LineEndLog<R>>,
    lines: LineCounter,
    record: csv::ByteRecord,
    header_line: usize,
    columns: Vec<String>,
    values: Vec<f64>,
    rows: usize,
}

impl<R: Read> Rows<R> {
    /// Reads the header of `input` (named `name` in messages).
    ///
    /// # Errors
    ///
    /// [`CsvError::At`] for an empty file or a header that is not a list of distinct names;
    /// [`CsvError::Io`] if the input cannot be read or is not UTF-8 text.
    pub fn new(name: &str, input: R) -> Result<Self, CsvError> {
        let mut rows = Self {
            name: name.to_string(),
            rdr: reader(input),
            lines: LineCounter::new(),
            record: csv::ByteRecord::new(),
            header_line: 0,
            columns: Vec::new(),
            values: Vec::new(),
            rows: 0,
        };
        let Some((header_line, fields)) =
            next_record(name, &mut rows.rdr, &mut rows.lines, &mut rows.record)?
        else {
            return Err(CsvError::at(
                name,
                None,
                None,
                "empty file; expected a header line of column names (for example k,t,y)",
            ));
        };
        let columns = header_names(name, header_line, &fields)?;
        rows.header_line = header_line;
        rows.values = Vec::with_capacity(columns.len());
        rows.columns = columns;
        Ok(rows)
    }

    /// At most this many bytes are read: more is an error (a file that grows while it is read
    /// past the size checked before).
    fn with_limit(mut self, limit: u64) -> Self {
        self.rdr.get_mut().limit = limit;
        self
    }

    /// The file's name, as messages give it.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Line of the header (1-based).
    pub fn header_line(&self) -> usize {
        self.header_line
    }

    /// Column names, in file order.
    pub fn columns(&self) -> &[String] {
        &self.columns
    }

    /// Index of a column.
    pub fn index(&self, name: &str) -> Option<usize> {
        self.columns.iter().position(|c| c == name)
    }

    /// Rows read so far.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// The index of a column that must be there, or an error naming the header and what was
    /// expected.
    ///
    /// # Errors
    ///
    /// [`CsvError::At`] at the header line when there is no such column.
    pub fn required(&self, name: &str) -> Result<usize, CsvError> {
        self.index(name)
            .ok_or_else(|| missing_column(&self.name, self.header_line, &self.columns, name))
    }

    /// The next row's line and values (in the order of [`columns`](Self::columns)); `None`
    /// at the end of the input.
    ///
    /// # Errors
    ///
    /// [`CsvError::At`] naming the line and column of a row that does not have a finite
    /// number in every column; [`CsvError::Io`] as [`new`](Self::new).
    pub fn next_row(&mut self) -> Result<Option<(usize, &[f64])>, CsvError> {
        let Self {
            name,
            rdr,
            lines,
            record,
            columns,
            values,
            rows,
            ..
        } = self;
        let Some((line, fields)) = next_record(name, rdr, lines, record)? else {
            return Ok(None);
        };
        let err = |col: usize, m: String| CsvError::at(name, Some(line), Some(col), m);
        let cells = cells_of(&fields);
        if cells.len() != columns.len() {
            // The column where the row goes wrong: its first extra cell, or its end.
            let col = cells
                .get(columns.len())
                .map_or(line_chars(&fields) + 1, |(c, _)| *c);
            return Err(err(
                col,
                format!(
                    "expected {} cells ({}), found {}",
                    columns.len(),
                    some_names(columns),
                    cells.len()
                ),
            ));
        }
        values.clear();
        for (j, (col, cell)) in cells.into_iter().enumerate() {
            let cell = cell.trim();
            let column = || shorten(&columns[j]);
            if cell.is_empty() {
                return Err(err(
                    col,
                    format!(
                        "column `{}`: expected a number, found an empty cell",
                        column()
                    ),
                ));
            }
            let v: f64 = cell.parse().map_err(|_| {
                err(
                    col,
                    format!(
                        "column `{}`: expected a number, found `{}`",
                        column(),
                        shorten(cell)
                    ),
                )
            })?;
            if !v.is_finite() {
                return Err(err(
                    col,
                    format!(
                        "column `{}`: expected a finite number, found `{}`",
                        column(),
                        shorten(cell)
                    ),
                ));
            }
            values.push(v);
        }
        *rows += 1;
        Ok(Some((line, values)))
    }

    /// The error of a file that ended before its first row.
    pub fn no_rows_error(&self) -> CsvError {
        CsvError::at(
            &self.name,
            Some(self.header_line),
            None,
            "no data rows after the header",
        )
    }

    /// Every remaining row collected into a [`Table`].
    ///
    /// # Errors
    ///
    /// As [`next_row`](Self::next_row); [`CsvError::At`] when there is no data row.
    pub fn into_table(mut self) -> Result<Table, CsvError> {
        let mut values = vec![Vec::new(); self.columns.len()];
        let mut lines = Vec::new();
        while let Some((line, row)) = self.next_row()? {
            for (column, &v) in values.iter_mut().zip(row) {
                column.push(v);
            }
            lines.push(line);
        }
        if lines.is_empty() {
            return Err(self.no_rows_error());
        }
        Ok(Table {
            name: self.name,
            header_line: self.header_line,
            columns: self.columns,
            values,
            lines,
        })
    }
}

/// The error of a header without the column `wanted`.
fn missing_column(name: &str, header_line: usize, columns: &[String], wanted: &str) -> CsvError {
    CsvError::at(
        name,
        Some(header_line),
        None,
        format!(
            "header: expected a column named `{wanted}`, found {}",
            some_names(columns)
        ),
    )
}

/// At most a few column names, for a message.
fn some_names(columns: &[String]) -> String {
    const SHOWN: usize = 8;
    let mut s = columns
        .iter()
        .take(SHOWN)
        .map(|c| shorten(c))
        .collect::<Vec<_>>()
        .join(",");
    if columns.len() > SHOWN {
        s.push_str(&format!(",… ({} more)", columns.len() - SHOWN));
    }
    s
}

/// Most characters of a file's content that a message quotes (a cell, a column name): a file
/// can be one the user did not mean to show (named by someone else's experiment file), so a
/// message shows a short excerpt, never a line.
pub const MAX_EXCERPT_CHARS: usize = 20;

/// A short, printable excerpt of `s` for a message: at most [`MAX_EXCERPT_CHARS`] characters
/// (`…` marks a cut), control and other unprintable characters escaped (`\u{1b}`, `\t`).
pub fn excerpt(s: &str) -> String {
    let mut out: String = s.chars().take(MAX_EXCERPT_CHARS).collect();
    if s.chars().count() > MAX_EXCERPT_CHARS {
        out.push('…');
    }
    out.escape_debug().to_string()
}

fn shorten(s: &str) -> String {
    excerpt(s)
}

/// The column names of a header line, checked: named, not numbers, each once.
fn header_names(name: &str, line: usize, header: &[&str]) -> Result<Vec<String>, CsvError> {
    let err = |col: usize, m: String| CsvError::at(name, Some(line), Some(col), m);
    let mut columns: Vec<String> = Vec::new();
    // A set, so that a header of 200 000 names is checked in linear time.
    let mut seen: HashSet<&str> = HashSet::new();
    for (i, (col, cell)) in cells_of(header).into_iter().enumerate() {
        let c = clean_name(cell);
        if c.is_empty() {
            return Err(err(col, format!(
                "header: column {} has no name; expected a comma-separated list of names such as k,t,y",
                i + 1
            )));
        }
        if c.parse::<f64>().is_ok() {
            return Err(err(col, format!(
                "header: expected column names, found the number `{}` (is the header line missing?)",
                shorten(c)
            )));
        }
        if !seen.insert(c) {
            return Err(err(
                col,
                format!("header: column `{}` appears twice", shorten(c)),
            ));
        }
        columns.push(c.to_string());
    }
    Ok(columns)
}

/// Parses CSV text; `name` is used in messages.
///
/// # Errors
///
/// [`CsvError::At`] naming the line and column of the first problem.
pub fn parse(name: &str, text: &str) -> Result<Table, CsvError> {
    Rows::new(name, text.as_bytes())?.into_table()
}

/// Largest input file accepted (1 GiB): the library's limit
/// ([`jitterid::limits::MAX_FILE_BYTES`]).
pub const MAX_FILE_BYTES: u64 = jitterid::limits::MAX_FILE_BYTES;

/// Fails unless `path` is a regular file of at most [`MAX_FILE_BYTES`] (so that a device or a
/// pipe given by mistake cannot block or exhaust memory).
///
/// # Errors
///
/// [`CsvError::Io`] naming the file.
pub fn check_regular_file(path: &Path, name: &str) -> Result<(), CsvError> {
    let io = |reason: String| CsvError::Io {
        name: name.to_string(),
        reason,
    };
    let meta =
        std::fs::metadata(path).map_err(|e| io(format!("cannot read: {}", io_reason(&e))))?;
    if !meta.is_file() {
        return Err(io("not a regular file".into()));
    }
    if meta.len() > MAX_FILE_BYTES {
        return Err(io(format!("larger than {MAX_FILE_BYTES} bytes")));
    }
    Ok(())
}

/// Reads and parses a CSV file.
///
/// # Errors
///
/// [`CsvError::Io`] if the file cannot be read or is not UTF-8 text; those of [`parse`].
pub fn read(path: &Path) -> Result<Table, CsvError> {
    read_as(path, &path.display().to_string())
}

/// Reads and parses the CSV file at `path`, named `name` in messages (for a file opened by
/// its canonical path but known to the user by another).
///
/// # Errors
///
/// As [`read`].
pub fn read_as(path: &Path, name: &str) -> Result<Table, CsvError> {
    open_rows(path, name)?.into_table()
}

/// The rows of the CSV file at `path`, named `name` in messages, read as they are asked for
/// (the file's text is never held whole): opened only if it is a regular file of at most
/// [`MAX_FILE_BYTES`], and read no further than that bound.
///
/// # Errors
///
/// [`CsvError::Io`] if the file cannot be read; those of [`Rows::new`].
pub fn open_rows(path: &Path, name: &str) -> Result<Rows<std::fs::File>, CsvError> {
    check_regular_file(path, name)?;
    let file = std::fs::File::open(path).map_err(|e| CsvError::Io {
        name: name.to_string(),
        reason: format!("cannot read: {}", io_reason(&e)),
    })?;
    Ok(Rows::new(name, file)?.with_limit(MAX_FILE_BYTES))
}

/// The text of the file at `path`, named `name` in messages, read only if it is a regular
/// file of at most [`MAX_FILE_BYTES`]: the one checked reader of every file the study layer
/// reads (CSV files, experiment files, shard files, fit files). `expected` says what the file
/// should have been (`"a CSV file"`) when it is not UTF-8 text.
///
/// # Errors
///
/// [`CsvError::Io`]: not a regular file, too large, unreadable, or not UTF-8.
pub fn read_text(path: &Path, name: &str, expected: &str) -> Result<String, CsvError> {
    check_regular_file(path, name)?;
    let bytes = std::fs::read(path).map_err(|e| CsvError::Io {
        name: name.to_string(),
        reason: format!("cannot read: {}", io_reason(&e)),
    })?;
    String::from_utf8(bytes).map_err(|e| CsvError::Io {
        name: name.to_string(),
        reason: format!(
            "not UTF-8 text (invalid byte at offset {}); expected {expected}",
            e.utf8_error().valid_up_to()
        ),
    })
}

/// A column to write: a name and its values; integer columns are printed without a fraction.
#[derive(Debug, Clone, Copy)]
pub enum Column<'a> {
    /// Whole numbers.
    Index(&'a str, &'a [usize]),
    /// Real numbers, printed with the shortest text that reads back to the same value.
    Real(&'a str, &'a [f64]),
}

impl Column<'_> {
    /// The column's name.
    pub fn name(&self) -> &str {
        match self {
            Column::Index(n, _) | Column::Real(n, _) => n,
        }
    }
    fn len(&self) -> usize {
        match self {
            Column::Index(_, v) => v.len(),
            Column::Real(_, v) => v.len(),
        }
    }
    fn cell(&self, i: usize) -> String {
        match self {
            Column::Index(_, v) => v[i].to_string(),
            Column::Real(_, v) => format!("{:?}", v[i]),
        }
    }
}

/// Formats columns of equal length as CSV text.
pub fn format(columns: &[Column<'_>]) -> String {
    let rows = columns.iter().map(Column::len).min().unwrap_or(0);
    let mut out = columns
        .iter()
        .map(Column::name)
        .collect::<Vec<_>>()
        .join(",");
    out.push('\n');
    for i in 0..rows {
        let row: Vec<String> = columns.iter().map(|c| c.cell(i)).collect();
        out.push_str(&row.join(","));
        out.push('\n');
    }
    out
}

#[cfg(test)]
#[path = "table_reference.rs"]
mod reference;

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A reader that hands out its text in the smallest pieces: the first four bytes (as a
    /// file's first read would, so that a byte-order mark is seen whole), then one byte per
    /// read, so that every CR LF pair and every record is split across reads.
    struct Trickle<'a>(&'a [u8], bool);

    impl Read for Trickle<'_> {
        fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
            let n = if self.1 { 1 } else { 4 }.min(self.0.len()).min(buf.len());
            self.1 = true;
            buf[..n].copy_from_slice(&self.0[..n]);
            self.0 = &self.0[n..];
            Ok(n)
        }
    }

    /// The rows of `text` read from a [`Trickle`].
    fn trickled(text: &str) -> Result<Table, CsvError> {
        Rows::new("d.csv", Trickle(text.as_bytes(), false))?.into_table()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]

        /// Read from a file piece by piece (the text never held whole), any text gives the
        /// table or error of the whole text: lines are counted across the reads.
        #[test]
        fn reads_in_pieces_like_the_whole_text(
            text in "(\u{feff})?([0-9a-c.,# \t\r\n\"e+-]|\u{feff}|\u{85}|é|NaN|inf){0,80}"
        ) {
            prop_assert_eq!(trickled(&text), parse("d.csv", &text));
        }

        /// The `csv`-based reader gives the hand-written reader's table or error on any text
        /// made of the characters that matter (separators, line ends, comments, quotes, white
        /// space, a byte-order mark, numbers and names).
        #[test]
        fn reads_like_the_hand_written_reader(
            text in "(\u{feff})?([0-9a-c.,# \t\r\n\"e+-]|\u{feff}|\u{85}|é|NaN|inf){0,80}"
        ) {
            prop_assert_eq!(parse("d.csv", &text), reference::parse("d.csv", &text));
        }

        /// The same on well-formed tables with comments, blank lines and mixed line ends
        /// inserted.
        #[test]
        fn reads_tables_like_the_hand_written_reader(
            rows in prop::collection::vec(prop::collection::vec(-1e3f64..1e3, 3), 0..6),
            ends in prop::collection::vec(prop_oneof![
                Just("\n"), Just("\r\n"), Just("\r"), Just("\n\n"), Just("\r\n# c,1\r\n"),
                Just("\n  \n"), Just("\n \t# note\n"), Just(",\n"), Just("\r\r\n")
            ], 7),
            bom in any::<bool>(),
        ) {
            let mut text = String::from(if bom { "\u{feff}k, \"t\" ,y" } else { "k, \"t\" ,y" });
            text.push_str(ends[0]);
            for (i, r) in rows.iter().enumerate() {
                text.push_str(&format!("{:?}, {},{:e}", r[0], r[1], r[2]));
                text.push_str(ends[i + 1]);
            }
            prop_assert_eq!(parse("d.csv", &text), reference::parse("d.csv", &text));
            prop_assert_eq!(trickled(&text), parse("d.csv", &text));
        }
    }

    /// Bytes that are not UTF-8 are named by their offset in the file, wherever they are:
    /// in the header, a row or a comment, after line ends of every kind.
    #[test]
    fn a_byte_that_is_not_utf8_is_named_by_its_offset() {
        for (bytes, offset) in [
            (&b"k,\xffy\n0,1\n"[..], 2),
            (&b"k,y\r\n0,1\r\n1,\xc3\n"[..], 12),
            (&b"k,y\r\r# \xe9\n0,1\n"[..], 7),
        ] {
            let e = Rows::new("d.csv", bytes)
                .and_then(Rows::into_table)
                .unwrap_err();
            assert_eq!(
                e.to_string(),
                format!(
                    "d.csv: not UTF-8 text (invalid byte at offset {offset}); expected a CSV file"
                )
            );
        }
    }

    #[test]
    fn round_trip() {
        let y = [0.1, -2.5e-7, 3.0];
        let text = format(&[Column::Index("k", &[0, 1, 2]), Column::Real("y", &y)]);
        let t = parse("x.csv", &text).unwrap();
        assert_eq!(t.column("y").unwrap(), &y);
        assert_eq!(t.column("k").unwrap(), &[0.0, 1.0, 2.0]);
        assert_eq!(t.lines, vec![2, 3, 4]);
    }

    #[test]
    fn errors_name_line_and_column() {
        let e = parse("d.csv", "k,y\n0,1\n1,abc\n").unwrap_err();
        assert!(e.to_string().starts_with("d.csv:3:3: column `y`"), "{e}");
        let e = parse("d.csv", "k,  y\n0, 1\n1,  2,3\n").unwrap_err();
        assert!(
            e.to_string().starts_with("d.csv:3:7: expected 2 cells"),
            "{e}"
        );
        let e = parse("d.csv", "k,y\n0,NaN\n").unwrap_err();
        assert!(e.to_string().contains("finite"), "{e}");
        let e = parse("d.csv", "k,y\n0\n").unwrap_err();
        assert!(
            e.to_string().starts_with("d.csv:2:2: expected 2 cells"),
            "{e}"
        );
        let e = parse("d.csv", "").unwrap_err();
        assert!(e.to_string().contains("empty"), "{e}");
        let e = parse("d.csv", "k,,y\n").unwrap_err();
        assert!(e.to_string().starts_with("d.csv:1:3: header"), "{e}");
        let e = parse("d.csv", "k,y\n0,1\n")
            .unwrap()
            .column("t")
            .unwrap_err();
        assert!(
            e.to_string()
                .starts_with("d.csv:1: header: expected a column named `t`"),
            "{e}"
        );
    }

    #[test]
    fn every_line_ending_reads_the_same() {
        let lf = parse("d.csv", "k,y\n0,1\n# note\n1,2\n").unwrap();
        for text in ["k,y\r\n0,1\r\n# note\r\n1,2\r\n", "k,y\r0,1\r# note\r1,2\r"] {
            let t = parse("d.csv", text).unwrap();
            assert_eq!(t.values, lf.values, "{text:?}");
            assert_eq!(t.lines, lf.lines, "{text:?}");
        }
        let e = parse("d.csv", "k,y\r0,1\r1,x\r").unwrap_err();
        assert!(e.to_string().starts_with("d.csv:3:3: column `y`"), "{e}");
    }

    #[test]
    fn a_very_wide_file_gives_a_short_error() {
        let header: Vec<String> = (0..200_004).map(|i| format!("c{i}")).collect();
        let text = format!("{}\n1,2\n", header.join(","));
        let e = parse("d.csv", &text).unwrap_err();
        assert!(e.to_string().len() < 300, "{} bytes", e.to_string().len());
        assert!(
            e.to_string()
                .starts_with("d.csv:2:4: expected 200004 cells"),
            "{e}"
        );
        assert!(e.to_string().contains("199996 more"), "{e}");
    }
}
