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
use std::collections::HashSet;
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
            None => Err(self.error(
                Some(self.header_line),
                format!(
                    "header: expected a column named `{name}`, found {}",
                    some_names(&self.columns)
                ),
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
fn reader(text: &str) -> csv::Reader<&[u8]> {
    csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .quoting(false)
        .terminator(csv::Terminator::CRLF)
        .from_reader(text.as_bytes())
}

/// The 1-based line of each record, counted here because the `csv` reader counts LF only: a
/// lone CR ends a line too, and CR LF is one line end.
struct LineCounter<'a> {
    bytes: &'a [u8],
    /// Bytes counted so far (up to the end of the last record).
    at: usize,
    /// Line ends among them.
    ends: usize,
}

impl<'a> LineCounter<'a> {
    fn new(text: &'a str) -> Self {
        Self {
            bytes: text.as_bytes(),
            at: 0,
            ends: 0,
        }
    }

    /// The line of a record of `len` bytes that the reader read from byte `from` on: past the
    /// byte-order mark and the line ends (of empty lines) that the reader skipped before it.
    /// A record holds no line end, so only the gaps between records are scanned.
    fn line_of(&mut self, from: u64, len: usize) -> usize {
        let b = self.bytes;
        let mut start = usize::try_from(from).unwrap_or(b.len()).max(self.at);
        if start == 0 && b.starts_with("\u{feff}".as_bytes()) {
            start = 3;
        }
        while start < b.len() && matches!(b[start], b'\r' | b'\n') {
            start += 1;
        }
        let gap = &b[self.at..start];
        self.ends += gap
            .iter()
            .enumerate()
            .filter(|&(i, &c)| c == b'\n' || (c == b'\r' && gap.get(i + 1) != Some(&b'\n')))
            .count();
        self.at = start + len;
        self.ends + 1
    }
}

/// The cells of a record, each with its 1-based column (in characters) where it starts.
fn cells_of(record: &csv::StringRecord) -> Vec<(usize, &str)> {
    let mut col = 1;
    record
        .iter()
        .map(|cell| {
            let start = col + cell.chars().take_while(|c| c.is_whitespace()).count();
            col += cell.chars().count() + 1;
            (start, cell)
        })
        .collect()
}

/// The length of a record's line in characters.
fn line_chars(record: &csv::StringRecord) -> usize {
    record.iter().map(|c| c.chars().count()).sum::<usize>() + record.len().saturating_sub(1)
}

/// Whether a record is a line to skip: blank, or a comment (`#` after optional white space).
fn skipped(record: &csv::StringRecord) -> bool {
    let first = record.get(0).unwrap_or("").trim_start();
    (record.len() == 1 && first.is_empty()) || first.starts_with('#')
}

/// Reads the next record to check into `record`; its line, `None` at the end of the text.
fn next_record(
    name: &str,
    rdr: &mut csv::Reader<&[u8]>,
    lines: &mut LineCounter<'_>,
    record: &mut csv::StringRecord,
) -> Result<Option<usize>, CsvError> {
    loop {
        let from = rdr.position().byte();
        // Reading `&str` text without quoting cannot fail (no I/O, fields split at ASCII
        // bytes stay UTF-8); a failure would still be reported, not lost.
        let more = rdr
            .read_record(record)
            .map_err(|e| CsvError::at(name, None, None, e.to_string()))?;
        if !more {
            return Ok(None);
        }
        let len = record.as_slice().len() + record.len().saturating_sub(1);
        let line = lines.line_of(from, len);
        if !skipped(record) {
            return Ok(Some(line));
        }
    }
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
fn header_names(
    name: &str,
    line: usize,
    header: &csv::StringRecord,
) -> Result<Vec<String>, CsvError> {
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
    let mut rdr = reader(text);
    let mut lines = LineCounter::new(text);
    let mut record = csv::StringRecord::new();
    let Some(header_line) = next_record(name, &mut rdr, &mut lines, &mut record)? else {
        return Err(CsvError::at(
            name,
            None,
            None,
            "empty file; expected a header line of column names (for example k,t,y)",
        ));
    };
    let columns = header_names(name, header_line, &record)?;
    let mut values = vec![Vec::new(); columns.len()];
    let mut rows = Vec::new();
    while let Some(line) = next_record(name, &mut rdr, &mut lines, &mut record)? {
        let err = |col: usize, m: String| CsvError::at(name, Some(line), Some(col), m);
        let cells = cells_of(&record);
        if cells.len() != columns.len() {
            // The column where the row goes wrong: its first extra cell, or its end.
            let col = cells
                .get(columns.len())
                .map_or(line_chars(&record) + 1, |(c, _)| *c);
            return Err(err(
                col,
                format!(
                    "expected {} cells ({}), found {}",
                    columns.len(),
                    some_names(&columns),
                    cells.len()
                ),
            ));
        }
        for (j, (col, cell)) in cells.into_iter().enumerate() {
            let cell = cell.trim();
            let column = shorten(&columns[j]);
            if cell.is_empty() {
                return Err(err(
                    col,
                    format!("column `{column}`: expected a number, found an empty cell"),
                ));
            }
            let v: f64 = cell.parse().map_err(|_| {
                err(
                    col,
                    format!(
                        "column `{column}`: expected a number, found `{}`",
                        shorten(cell)
                    ),
                )
            })?;
            if !v.is_finite() {
                return Err(err(
                    col,
                    format!(
                        "column `{column}`: expected a finite number, found `{}`",
                        shorten(cell)
                    ),
                ));
            }
            values[j].push(v);
        }
        rows.push(line);
    }
    if rows.is_empty() {
        return Err(CsvError::at(
            name,
            Some(header_line),
            None,
            "no data rows after the header",
        ));
    }
    Ok(Table {
        name: name.to_string(),
        header_line,
        columns,
        values,
        lines: rows,
    })
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
    let text = read_text(path, name, "a CSV file")?;
    parse(name, &text)
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

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]

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
