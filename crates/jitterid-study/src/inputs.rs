//! Inputs on a record's grid: piecewise-constant inputs from switch times and levels or from a
//! CSV table (read by the library), and the span on which a random binary input is drawn.

use crate::csvio;
use crate::error::StudyResult;
use jitterid::signal::{PiecewiseConstant, SampleGrid, SignalError};

/// The span `[t0, t0 + (N+1)T)` on which a random binary input is drawn.
pub fn input_span(grid: &SampleGrid) -> (f64, f64) {
    let t0 = grid.start();
    (t0, t0 + (grid.len() as f64 + 1.0) * grid.interval())
}

/// A piecewise-constant input from switch times and levels (see [`csvio::piecewise`]).
pub fn piecewise(
    times: &[f64],
    values: &[f64],
    grid: &SampleGrid,
) -> Result<PiecewiseConstant, String> {
    csvio::piecewise(times, values, grid)
}

/// A piecewise-constant input from two columns of a CSV table (see [`csvio::input_from_table`]);
/// a last row with level 0 ends the input at its time.
pub fn piecewise_from_table(
    table: &csvio::Table,
    time_column: &str,
    value_column: &str,
    grid: &SampleGrid,
) -> StudyResult<PiecewiseConstant> {
    Ok(csvio::input_from_table(
        table,
        time_column,
        value_column,
        grid,
    )?)
}

/// The part of `u` from `t0` on, as a measurement that starts at `t0` records it: the level
/// held at `t0`, then `u`'s own switches; zero where `u` has ended. Unchanged when `u` starts
/// at or after `t0`.
pub fn from_start(u: &PiecewiseConstant, t0: f64) -> Result<PiecewiseConstant, SignalError> {
    let edges = u.edges();
    // Index of the first edge after t0: the interval before it holds t0.
    let i = edges.partition_point(|&e| e <= t0);
    if i == 0 {
        return Ok(u.clone());
    }
    if i == edges.len() {
        // The input ended before t0: the record sees none of it.
        return PiecewiseConstant::new(vec![t0, t0 + 1.0], vec![0.0]);
    }
    let mut e = vec![t0];
    e.extend_from_slice(&edges[i..]);
    PiecewiseConstant::new(e, u.levels()[i - 1..].to_vec())
}
