use crate::EstimateError;
use jitterid_signal::SampleGrid;

/// A record of samples `y_k` requested at the instants of a [`SampleGrid`]: validated finite and
/// of the grid's length.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Record {
    grid: SampleGrid,
    y: Vec<f64>,
}

impl Record {
    /// Validates that `y` has one finite value per instant of `grid`.
    pub fn new(grid: SampleGrid, y: Vec<f64>) -> Result<Self, EstimateError> {
        if y.len() != grid.len() {
            return Err(EstimateError::DataLength {
                expected: grid.len(),
                got: y.len(),
            });
        }
        if let Some((index, &value)) = y.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(EstimateError::NonFiniteData { index, value });
        }
        Ok(Self { grid, y })
    }

    /// The sampling grid.
    pub fn grid(&self) -> &SampleGrid {
        &self.grid
    }

    /// The samples.
    pub fn y(&self) -> &[f64] {
        &self.y
    }
}
