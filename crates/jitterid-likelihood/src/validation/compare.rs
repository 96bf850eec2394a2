//! `compare`: the model's expected samples against a record, as a normalised fit percent.

use super::fit_percent;
use jitterid_estimate::{EstimateError, ModelStructure, NoiseModel};
use jitterid_jitter::JitterModel;
use jitterid_signal::{SampleGrid, Signal};

/// The model's expected samples on a record and how well they explain it.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Comparison {
    /// `m_k = E[s(t_k + τ)]`, exact under the structure's jitter.
    pub expected: Vec<f64>,
    /// [`fit_percent`] of `expected` against the data.
    pub fit_percent: f64,
}

/// Compares the structure's expected samples `m_k = E[s(t_k + τ)]` on `grid` (the signal's own
/// exact first moment, jitter included) with the samples `y`. Use it on the estimation record
/// and, with the fitted signal moved to another record's input
/// ([`AnySignal::with_input`](jitterid_signal::AnySignal::with_input)), on a validation record.
///
/// Errors: `y` of another length than the grid, non-finite samples, constant data.
pub fn compare<S, J, N>(
    structure: &ModelStructure<S, J, N>,
    grid: &SampleGrid,
    y: &[f64],
) -> Result<Comparison, EstimateError>
where
    S: Signal,
    J: JitterModel,
    N: NoiseModel,
{
    if y.len() != grid.len() {
        return Err(EstimateError::DataLength {
            expected: grid.len(),
            got: y.len(),
        });
    }
    let expected = structure.signal.expected_values(grid, &structure.jitter);
    let fit_percent = fit_percent(y, &expected)?;
    Ok(Comparison {
        expected,
        fit_percent,
    })
}
