use crate::EstimateError;
use jitterid_signal::SampleGrid;

/// A record of samples `y_k` requested at the instants of a [`SampleGrid`]: validated finite and
/// of the grid's length (also when read with serde).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "RawRecord")]
pub struct Record {
    grid: SampleGrid,
    y: Vec<f64>,
}

/// A [`Record`] as read, before validation.
#[derive(serde::Deserialize)]
struct RawRecord {
    grid: SampleGrid,
    y: Vec<f64>,
}

impl TryFrom<RawRecord> for Record {
    type Error = EstimateError;

    fn try_from(raw: RawRecord) -> Result<Self, EstimateError> {
        Record::new(raw.grid, raw.y)
    }
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
