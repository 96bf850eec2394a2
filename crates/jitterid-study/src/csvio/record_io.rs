//! [`MeasuredRecord`]s from and to the CSV files of the command line.
//!
//! The data file has a column `y` and optionally `k` (the sample index, `0, 1, …` in order), `t`
//! (the requested instants `t0 + kT`) and `u` (the input at each instant, held to the next one
//! when no input file is given). The input file (`<data stem>.input.csv` beside the data) holds a
//! piecewise-constant input as switch times and levels in columns `t` and `u`: `u = u_j` from
//! `t_j` to the next time; a last row with level 0 ends the input at its time, otherwise the last
//! level holds until `t0 + 2NT` (well after the record).

use super::error::CsvError;
use super::table::{self, Column, Table};
use jitterid::estimate::{MeasuredRecord, Record};
use jitterid::signal::{Input, PiecewiseConstant, SampleGrid};
use std::path::{Path, PathBuf};

/// Relative tolerance (in units of `T`) of a `t` column against the grid.
const TIME_TOLERANCE: f64 = 1e-6;

/// The input file beside a data file: `<stem>.input.csv`.
pub fn input_side_file(data: &Path) -> PathBuf {
    let stem = data
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "data".into());
    data.with_file_name(format!("{stem}.input.csv"))
}

/// The grid of a data table: `grid` when given (the `t` column, if any, checked against it),
/// otherwise from the `t` column (`t0 = t_0`, `T` its mean step, every instant checked).
fn grid_of(table: &Table, n: usize, grid: Option<&SampleGrid>) -> Result<SampleGrid, CsvError> {
    let t = table.optional("t");
    let grid = match (grid, t) {
        (Some(g), _) => *g,
        (None, Some(t)) if n >= 2 => {
            let step = (t[n - 1] - t[0]) / (n - 1) as f64;
            SampleGrid::new(t[0], step, n).map_err(|e| {
                table.cell_error(n - 1, "t", format!("the instants do not make a grid: {e}"))
            })?
        }
        (None, Some(_)) => {
            return Err(table.error(
                Some(table.header_line),
                "one row cannot set the sampling interval: give the grid",
            ))
        }
        (None, None) => {
            return Err(table.error(
                Some(table.header_line),
                "no column `t` and no grid given: the requested instants are unknown",
            ))
        }
    };
    if grid.len() != n {
        return Err(table.error(
            Some(table.header_line),
            format!(
                "has {n} data rows, expected {} (the grid's samples)",
                grid.len()
            ),
        ));
    }
    if let Some(k) = table.optional("k") {
        if let Some(i) = (0..n).find(|&i| k[i] != i as f64) {
            return Err(table.cell_error(
                i,
                "k",
                format!("expected {i} (rows in order from 0), found {}", k[i]),
            ));
        }
    }
    if let Some(t) = t {
        let tol = TIME_TOLERANCE * grid.interval();
        if let Some(i) = (0..n).find(|&i| (t[i] - grid.time(i)).abs() > tol + 1e-12 * t[i].abs()) {
            return Err(table.cell_error(
                i,
                "t",
                format!("expected {} (t0 + kT), found {}", grid.time(i), t[i]),
            ));
        }
    }
    Ok(grid)
}

/// A measured record from a parsed data table (columns above); `grid` when the instants are
/// known beforehand (an experiment's), else read from the `t` column.
///
/// # Errors
///
/// [`CsvError::At`] naming the line and column of what is wrong.
pub fn record_from_table(
    table: &Table,
    grid: Option<&SampleGrid>,
) -> Result<MeasuredRecord, CsvError> {
    let y = table.column("y")?;
    let grid = grid_of(table, y.len(), grid)?;
    let record = Record::new(grid, y.to_vec())
        .map_err(|e| table.error(Some(table.header_line), e.to_string()))?;
    let measured = MeasuredRecord::new(table.name.clone(), record);
    match table.optional("u") {
        Some(u) => measured
            .with_held_input(u)
            .map_err(|e| table.cell_error(0, "u", e.to_string())),
        None => Ok(measured),
    }
}

/// A piecewise-constant input from the switch times and levels of a table (columns
/// `time_column`, `value_column`); `grid` sets how long a last level holds.
///
/// # Errors
///
/// [`CsvError::At`] when the times do not increase strictly or the columns are missing.
pub fn input_from_table(
    table: &Table,
    time_column: &str,
    value_column: &str,
    grid: &SampleGrid,
) -> Result<PiecewiseConstant, CsvError> {
    let t = table.column(time_column)?;
    let u = table.column(value_column)?;
    for i in 1..t.len() {
        if t[i] <= t[i - 1] {
            return Err(table.cell_error(
                i,
                time_column,
                format!(
                    "times must increase strictly; {} is not above {}",
                    t[i],
                    t[i - 1]
                ),
            ));
        }
    }
    let (times, values) = if t.len() >= 2 && u[u.len() - 1] == 0.0 {
        (t.to_vec(), u[..u.len() - 1].to_vec())
    } else {
        (t.to_vec(), u.to_vec())
    };
    piecewise(&times, &values, grid).map_err(|m| table.error(Some(table.header_line), m))
}

/// A piecewise-constant input from switch times and levels: `u = values[j]` from `times[j]` to
/// the next time; with one more time than values the last time ends the input (zero after it),
/// otherwise the last level holds until `t0 + 2NT` (well after the record).
///
/// # Errors
///
/// A message naming what is wrong with the lists.
pub fn piecewise(
    times: &[f64],
    values: &[f64],
    grid: &SampleGrid,
) -> Result<PiecewiseConstant, String> {
    if values.is_empty() {
        return Err("expected at least one switch time and level".into());
    }
    let mut edges = times.to_vec();
    if times.len() == values.len() {
        let last = times[times.len() - 1];
        let hold =
            (grid.start() + 2.0 * grid.duration() + grid.interval()).max(last + grid.interval());
        edges.push(hold);
    } else if times.len() != values.len() + 1 {
        return Err(format!(
            "expected as many times as values ({}), or one more to end the input; found {} times",
            values.len(),
            times.len()
        ));
    }
    for (i, w) in edges.windows(2).enumerate() {
        if w[1] <= w[0] {
            return Err(format!(
                "times must increase strictly: element {} ({}) is not above the one before ({})",
                i + 2,
                w[1],
                w[0]
            ));
        }
    }
    PiecewiseConstant::new(edges, values.to_vec()).map_err(|e| e.to_string())
}

/// Reads a measured record: the data file, and the input file `input` (or, if absent, the side
/// file [`input_side_file`] when it exists; otherwise the data file's `u` column held, if any).
///
/// # Errors
///
/// [`CsvError`] naming the file, line and column of what is wrong.
pub fn load_record(
    data: &Path,
    input: Option<&Path>,
    grid: Option<&SampleGrid>,
) -> Result<MeasuredRecord, CsvError> {
    let table = table::read(data)?;
    let measured = record_from_table(&table, grid)?;
    let side = input.map_or_else(|| input_side_file(data), Path::to_path_buf);
    if input.is_none() && !side.exists() {
        return Ok(measured);
    }
    let t = table::read(&side)?;
    let p = input_from_table(&t, "t", "u", measured.grid())?;
    Ok(measured.with_input(Input::Piecewise(p)))
}

/// The data file's text: `k,t,y`, and `u` (the input at each instant) when there is an input.
pub fn record_to_csv(record: &MeasuredRecord) -> String {
    let n = record.grid().len();
    let k: Vec<usize> = (0..n).collect();
    let t: Vec<f64> = record.grid().times().collect();
    let u: Option<Vec<f64>> = record
        .input()
        .map(|i| t.iter().map(|&t| i.value(t)).collect());
    let mut cols = vec![
        Column::Index("k", &k),
        Column::Real("t", &t),
        Column::Real("y", record.y()),
    ];
    if let Some(u) = &u {
        cols.push(Column::Real("u", u));
    }
    table::format(&cols)
}

/// The input file's text of a piecewise-constant input: switch times and levels, with a last
/// row of level 0 that ends the input.
pub fn input_to_csv(input: &PiecewiseConstant) -> String {
    let mut levels = input.levels().to_vec();
    levels.push(0.0);
    table::format(&[Column::Real("t", input.edges()), Column::Real("u", &levels)])
}

/// The input file's text of several piecewise-constant inputs, one column per input named by
/// `names`: every input's switch times in one column `t`, and each input's level from that time
/// on (held where the input does not switch), with a last row of levels 0 that ends them.
pub fn inputs_to_csv(names: &[&str], inputs: &[&PiecewiseConstant]) -> String {
    let mut t: Vec<f64> = inputs.iter().flat_map(|p| p.edges().to_vec()).collect();
    t.sort_by(f64::total_cmp);
    t.dedup();
    let levels: Vec<Vec<f64>> = inputs
        .iter()
        .map(|p| t.iter().map(|&t| p.value(t)).collect())
        .collect();
    let mut cols = vec![Column::Real("t", &t)];
    cols.extend(names.iter().zip(&levels).map(|(n, l)| Column::Real(n, l)));
    table::format(&cols)
}

/// Writes a measured record to `data` and, for a piecewise-constant input, its switch times and
/// levels to the side file [`input_side_file`] (read back exactly by [`load_record`]).
///
/// # Errors
///
/// [`CsvError::Io`] naming the file that could not be written.
pub fn save_record(record: &MeasuredRecord, data: &Path) -> Result<(), CsvError> {
    let write = |path: &Path, text: String| {
        std::fs::write(path, text).map_err(|e| CsvError::Io {
            name: path.display().to_string(),
            reason: format!("cannot write: {}", super::error::io_reason(&e)),
        })
    };
    write(data, record_to_csv(record))?;
    if let Some(Input::Piecewise(p)) = record.input() {
        write(&input_side_file(data), input_to_csv(p))?;
    }
    Ok(())
}
