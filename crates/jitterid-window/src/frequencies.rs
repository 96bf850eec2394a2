//! Validated sets of frequencies at which transforms and first moments are evaluated.

use crate::WindowError;
use jitterid_signal::SampleGrid;

/// A validated, non-empty set of frequencies (Hz) in one DTFT period `[0, 1/T)` of a record.
///
/// Built for one [`SampleGrid`]; it remembers that grid's `N` and `T` and, when every
/// frequency lies on the DFT grid `j/(NT)`, their indices `j`, so that transforms of that
/// record can use the FFT ([`dft_indices`](Self::dft_indices)).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FrequencySet {
    frequencies: Vec<f64>,
    indices: Option<Vec<usize>>,
    record_len: usize,
    interval: f64,
}

/// `j/(NT)`, the `j`-th point of the DFT grid, computed the same way everywhere.
#[inline]
fn grid_point(j: usize, n: usize, interval: f64) -> f64 {
    j as f64 / (n as f64 * interval)
}

impl FrequencySet {
    /// The paper's default: the DFT grid `f_j = j/(NT)` for `0 ≤ j ≤ N/2` (`⌊N/2⌋ + 1`
    /// frequencies).
    pub fn dft(grid: &SampleGrid) -> Self {
        Self::dft_range(grid, 0, grid.len() / 2)
    }

    /// The full DFT grid `f_j = j/(NT)`, `0 ≤ j ≤ N−1` (one whole period; the grid on which
    /// Parseval's relation holds).
    pub fn full_dft(grid: &SampleGrid) -> Self {
        Self::dft_range(grid, 0, grid.len() - 1)
    }

    fn dft_range(grid: &SampleGrid, first: usize, last: usize) -> Self {
        let n = grid.len();
        let t = grid.interval();
        let indices: Vec<usize> = (first..=last).collect();
        Self {
            frequencies: indices.iter().map(|&j| grid_point(j, n, t)).collect(),
            indices: Some(indices),
            record_len: n,
            interval: t,
        }
    }

    /// The DFT-grid points `j/(NT)`, `0 ≤ j ≤ N−1`, that lie in `[min, max]` (Hz).
    ///
    /// Errors: a non-finite limit, `min > max`, or no grid point in the band.
    pub fn band(grid: &SampleGrid, min: f64, max: f64) -> Result<Self, WindowError> {
        if !min.is_finite() {
            return Err(WindowError::BandLimitNotFinite {
                name: "min",
                value: min,
            });
        }
        if !max.is_finite() {
            return Err(WindowError::BandLimitNotFinite {
                name: "max",
                value: max,
            });
        }
        if min > max {
            return Err(WindowError::InvalidBand { min, max });
        }
        let n = grid.len();
        let t = grid.interval();
        let indices: Vec<usize> = (0..n)
            .filter(|&j| {
                let f = grid_point(j, n, t);
                f >= min && f <= max
            })
            .collect();
        if indices.is_empty() {
            return Err(WindowError::EmptyFrequencySet);
        }
        Ok(Self {
            frequencies: indices.iter().map(|&j| grid_point(j, n, t)).collect(),
            indices: Some(indices),
            record_len: n,
            interval: t,
        })
    }

    /// An arbitrary list of frequencies (Hz), kept in the order given. Each must be finite and
    /// in `[0, 1/T)`; the list must not be empty. If every frequency equals a DFT-grid point
    /// `j/(NT)` exactly, the indices are remembered.
    pub fn list(grid: &SampleGrid, frequencies: Vec<f64>) -> Result<Self, WindowError> {
        if frequencies.is_empty() {
            return Err(WindowError::EmptyFrequencySet);
        }
        let n = grid.len();
        let t = grid.interval();
        let limit = 1.0 / t;
        let mut indices = Some(Vec::with_capacity(frequencies.len()));
        for (index, &value) in frequencies.iter().enumerate() {
            if !value.is_finite() {
                return Err(WindowError::FrequencyNotFinite { index, value });
            }
            if !(value >= 0.0 && value < limit) {
                return Err(WindowError::FrequencyOutOfRange {
                    index,
                    value,
                    limit,
                });
            }
            if let Some(list) = indices.as_mut() {
                let j = (value * n as f64 * t).round();
                let on_grid = j >= 0.0 && j < n as f64 && grid_point(j as usize, n, t) == value;
                if on_grid {
                    list.push(j as usize);
                } else {
                    indices = None;
                }
            }
        }
        Ok(Self {
            frequencies,
            indices,
            record_len: n,
            interval: t,
        })
    }

    /// The frequencies (Hz).
    pub fn frequencies(&self) -> &[f64] {
        &self.frequencies
    }

    /// Number of frequencies (at least one).
    pub fn len(&self) -> usize {
        self.frequencies.len()
    }

    /// Always false: a set holds at least one frequency.
    pub fn is_empty(&self) -> bool {
        self.frequencies.is_empty()
    }

    /// The DFT-grid indices `j` (`f = j/(NT)`) of the frequencies, when every one of them lies
    /// on the grid of the record the set was built for.
    pub fn dft_indices(&self) -> Option<&[usize]> {
        self.indices.as_deref()
    }

    /// `N` of the record the set was built for.
    pub fn record_len(&self) -> usize {
        self.record_len
    }

    /// `T` of the record the set was built for (s).
    pub fn interval(&self) -> f64 {
        self.interval
    }

    /// Whether the set was built for a record with the same `N` and `T` as `grid` (so that its
    /// DFT indices refer to that record's DFT).
    pub fn fits(&self, grid: &SampleGrid) -> bool {
        self.record_len == grid.len() && self.interval == grid.interval()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: usize, t: f64) -> SampleGrid {
        SampleGrid::new(0.0, t, n).unwrap()
    }

    #[test]
    fn dft_default_has_half_the_grid() {
        let g = grid(200, 1.0);
        let s = FrequencySet::dft(&g);
        assert_eq!(s.len(), 101);
        assert_eq!(s.frequencies()[100], 0.5);
        assert_eq!(s.dft_indices().unwrap()[37], 37);
        let g = grid(7, 0.5);
        let s = FrequencySet::dft(&g);
        assert_eq!(s.len(), 4);
        assert_eq!(FrequencySet::full_dft(&g).len(), 7);
    }

    #[test]
    fn band_selects_grid_points() {
        let g = grid(100, 0.1); // grid spacing 0.1 Hz, period 10 Hz
        let s = FrequencySet::band(&g, 0.25, 0.55).unwrap();
        assert_eq!(s.dft_indices().unwrap(), &[3, 4, 5]);
        assert!(matches!(
            FrequencySet::band(&g, 0.31, 0.39),
            Err(WindowError::EmptyFrequencySet)
        ));
        assert!(matches!(
            FrequencySet::band(&g, 1.0, 0.5),
            Err(WindowError::InvalidBand { .. })
        ));
        assert!(matches!(
            FrequencySet::band(&g, f64::NAN, 0.5),
            Err(WindowError::BandLimitNotFinite { name: "min", .. })
        ));
    }

    #[test]
    fn list_validates_and_detects_the_grid() {
        let g = grid(10, 1.0);
        let on = FrequencySet::list(&g, vec![0.3, 0.0, 0.9]).unwrap();
        assert_eq!(on.dft_indices(), Some(&[3, 0, 9][..]));
        let off = FrequencySet::list(&g, vec![0.3, 0.35]).unwrap();
        assert!(off.dft_indices().is_none());
        assert_eq!(
            FrequencySet::list(&g, vec![0.1, 1.0]),
            Err(WindowError::FrequencyOutOfRange {
                index: 1,
                value: 1.0,
                limit: 1.0
            })
        );
        assert_eq!(
            FrequencySet::list(&g, vec![-0.0, -0.1]),
            Err(WindowError::FrequencyOutOfRange {
                index: 1,
                value: -0.1,
                limit: 1.0
            })
        );
        assert!(matches!(
            FrequencySet::list(&g, vec![f64::INFINITY]),
            Err(WindowError::FrequencyNotFinite { index: 0, .. })
        ));
        assert_eq!(
            FrequencySet::list(&g, vec![]),
            Err(WindowError::EmptyFrequencySet)
        );
    }
}
