//! Inputs on a record's grid: piecewise-constant inputs from switch times and levels or from a
//! CSV table (read by the library), and the span on which a random binary input is drawn.

use crate::csvio;
use crate::error::CliResult;
use jitterid::estimate::csv;
use jitterid::signal::{PiecewiseConstant, SampleGrid};

/// The span `[t0, t0 + (N+1)T)` on which a random binary input is drawn.
pub fn input_span(grid: &SampleGrid) -> (f64, f64) {
    let t0 = grid.start();
    (t0, t0 + (grid.len() as f64 + 1.0) * grid.interval())
}

/// A piecewise-constant input from switch times and levels (see [`csv::piecewise`]).
pub fn piecewise(
    times: &[f64],
    values: &[f64],
    grid: &SampleGrid,
) -> Result<PiecewiseConstant, String> {
    csv::piecewise(times, values, grid)
}

/// A piecewise-constant input from two columns of a CSV table (see [`csv::input_from_table`]);
/// a last row with level 0 ends the input at its time.
pub fn piecewise_from_table(
    table: &csvio::Table,
    time_column: &str,
    value_column: &str,
    grid: &SampleGrid,
) -> CliResult<PiecewiseConstant> {
    Ok(csv::input_from_table(
        table,
        time_column,
        value_column,
        grid,
    )?)
}
