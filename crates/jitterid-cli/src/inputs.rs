//! Inputs on a record's grid: piecewise-constant inputs from switch times and levels or from a
//! CSV table, and the span on which a random binary input is drawn.

use crate::cli_err;
use crate::csvio;
use crate::error::CliResult;
use jitterid::signal::{PiecewiseConstant, SampleGrid};

/// The span `[t0, t0 + (N+1)T)` on which a random binary input is drawn.
pub fn input_span(grid: &SampleGrid) -> (f64, f64) {
    let t0 = grid.start();
    (t0, t0 + (grid.len() as f64 + 1.0) * grid.interval())
}

/// A piecewise-constant input from switch times and levels: `u = values[j]` from `times[j]` to
/// the next time; with one more time than values the last time ends the input (zero after it),
/// otherwise the last level holds until `t0 + 2NT` (well after the record).
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

/// A piecewise-constant input from two columns of a CSV table (see [`piecewise`]); a last row
/// with level 0 ends the input at its time.
pub fn piecewise_from_table(
    table: &csvio::Table,
    time_column: &str,
    value_column: &str,
    grid: &SampleGrid,
) -> CliResult<PiecewiseConstant> {
    let t = table.column(time_column)?;
    let u = table.column(value_column)?;
    for i in 1..t.len() {
        if t[i] <= t[i - 1] {
            return Err(cli_err!(
                "{}:{}: column `{time_column}`: times must increase strictly; {} is not above {}",
                table.name,
                table.lines[i],
                t[i],
                t[i - 1]
            ));
        }
    }
    let (times, values) = if t.len() >= 2 && u[u.len() - 1] == 0.0 {
        (t.to_vec(), u[..u.len() - 1].to_vec())
    } else {
        (t.to_vec(), u.to_vec())
    };
    piecewise(&times, &values, grid)
        .map_err(|m| cli_err!("{}:{}: {m}", table.name, table.header_line))
}
