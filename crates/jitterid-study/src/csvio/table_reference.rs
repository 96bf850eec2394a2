//! The hand-written reader that the `csv` crate replaced, kept for the tests only: the new
//! reader must give the same tables and the same errors on any text.

use super::{CsvError, Table};
use std::collections::HashSet;

fn clean_name(s: &str) -> &str {
    let s = s.trim();
    s.strip_prefix('"')
        .and_then(|s| s.strip_suffix('"'))
        .unwrap_or(s)
        .trim()
}

/// The lines of `text`, ending at LF, CR LF or a lone CR.
fn lines_of(text: &str) -> impl Iterator<Item = &str> {
    text.split("\r\n").flat_map(|l| l.split(['\n', '\r']))
}

/// The cells of a line, each with its 1-based column (in characters) where it starts.
fn cells_of(line: &str) -> Vec<(usize, &str)> {
    let mut col = 1;
    line.split(',')
        .map(|cell| {
            let start = col + cell.chars().take_while(|c| c.is_whitespace()).count();
            col += cell.chars().count() + 1;
            (start, cell)
        })
        .collect()
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

fn shorten(s: &str) -> String {
    let mut out: String = s.chars().take(20).collect();
    if s.chars().count() > 20 {
        out.push('…');
    }
    out.escape_debug().to_string()
}

/// The column names of a header line, checked: named, not numbers, each once.
fn header_names(name: &str, line: usize, header: &str) -> Result<Vec<String>, CsvError> {
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
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut lines = lines_of(text)
        .enumerate()
        .map(|(i, l)| (i + 1, l))
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let Some((header_line, header)) = lines.next() else {
        return Err(CsvError::at(
            name,
            None,
            None,
            "empty file; expected a header line of column names (for example k,t,y)",
        ));
    };
    let columns = header_names(name, header_line, header)?;
    let mut values = vec![Vec::new(); columns.len()];
    let mut rows = Vec::new();
    for (line, text) in lines {
        let err = |col: usize, m: String| CsvError::at(name, Some(line), Some(col), m);
        let cells = cells_of(text);
        if cells.len() != columns.len() {
            // The column where the row goes wrong: its first extra cell, or its end.
            let col = cells
                .get(columns.len())
                .map_or(text.chars().count() + 1, |(c, _)| *c);
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
