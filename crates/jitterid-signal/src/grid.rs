use crate::error::{finite, positive, SignalError};

/// The requested sampling instants `t_k = t0 + kT`, `k = 0..N-1`.
///
/// Deserializes through [`SampleGrid::new`], so a grid read from a file is valid too.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "GridFields")]
pub struct SampleGrid {
    start: f64,
    interval: f64,
    len: usize,
}

impl SampleGrid {
    /// A grid of `len` instants `start + k·interval`. Needs `interval > 0`, `len ≥ 1`, finite
    /// values.
    pub fn new(start: f64, interval: f64, len: usize) -> Result<Self, SignalError> {
        finite("start", start)?;
        positive("interval", interval)?;
        if len == 0 {
            return Err(SignalError::TooFew {
                name: "samples",
                min: 1,
                value: len,
            });
        }
        jitterid_numeric::limits::check(jitterid_numeric::limits::Limit::Samples, len)?;
        Ok(Self {
            start,
            interval,
            len,
        })
    }

    /// The same instants moved earlier by `by` seconds (`t_k − by`): where a response delayed
    /// by `by` is sampled in its own time. `by` is finite (checked by the caller).
    pub(crate) fn earlier(&self, by: f64) -> Self {
        Self {
            start: self.start - by,
            ..*self
        }
    }

    /// `t0`, the first requested instant (s).
    pub fn start(&self) -> f64 {
        self.start
    }

    /// `T`, the sampling interval (s).
    pub fn interval(&self) -> f64 {
        self.interval
    }

    /// `N`, the number of samples.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Always false: a grid has at least one instant.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// `t_k = t0 + kT`.
    pub fn time(&self, k: usize) -> f64 {
        self.start + k as f64 * self.interval
    }

    /// All requested instants.
    pub fn times(&self) -> impl ExactSizeIterator<Item = f64> + '_ {
        (0..self.len).map(|k| self.time(k))
    }

    /// Duration `N·T` of the record.
    pub fn duration(&self) -> f64 {
        self.len as f64 * self.interval
    }
}

/// The serialized form of a [`SampleGrid`], validated on the way in.
#[derive(serde::Deserialize)]
struct GridFields {
    start: f64,
    interval: f64,
    len: usize,
}

impl TryFrom<GridFields> for SampleGrid {
    type Error = SignalError;
    fn try_from(g: GridFields) -> Result<Self, SignalError> {
        Self::new(g.start, g.interval, g.len)
    }
}
