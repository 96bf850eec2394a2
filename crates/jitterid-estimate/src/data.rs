use crate::EstimateError;
use jitterid_signal::SampleGrid;
use std::sync::Arc;

/// A record of samples `y_k` requested at the instants of a [`SampleGrid`]: validated finite and
/// of the grid's length (also when read with serde).
///
/// The samples are shared, not copied, between clones: a fit keeps the caller's record in its
/// data without a second copy of a long record.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "RawRecord", into = "RawRecord")]
pub struct Record {
    grid: SampleGrid,
    y: Arc<Vec<f64>>,
}

/// A [`Record`] as read or written, before validation.
#[derive(serde::Serialize, serde::Deserialize)]
struct RawRecord {
    grid: SampleGrid,
    y: Vec<f64>,
}

impl From<Record> for RawRecord {
    fn from(r: Record) -> Self {
        RawRecord {
            grid: r.grid,
            y: Arc::unwrap_or_clone(r.y),
        }
    }
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
        check_samples(&grid, &y)?;
        Ok(Self {
            grid,
            y: Arc::new(y),
        })
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

/// `y` holds one finite value per instant of `grid` (what [`Record::new`] checks, for callers
/// that borrow the samples).
pub fn check_samples(grid: &SampleGrid, y: &[f64]) -> Result<(), EstimateError> {
    if y.len() != grid.len() {
        return Err(EstimateError::DataLength {
            expected: grid.len(),
            got: y.len(),
        });
    }
    if let Some((index, &value)) = y.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(EstimateError::NonFiniteData { index, value });
    }
    Ok(())
}
