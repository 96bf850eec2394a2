//! An operating point: a constant output offset added to another signal.

use crate::signal::{Jacobian, Signal};
use crate::spectrum::{SpectralLine, Spectrum};
use crate::{SampleGrid, SignalError};
use jitterid_jitter::JitterModel;
use num_complex::Complex64;

/// The name of the offset's parameter (when it is estimated).
pub const OFFSET_PARAM: &str = "offset";

/// `y₀ + s(t)`: a signal `s` around an operating point, the constant output offset `y₀`.
///
/// A constant does not move with the sampling instant, so under jitter it is exact and free:
/// `E[y₀ + s(t_k + τ)] = y₀ + m_k` and the variance is that of `s` alone
/// (`E[(y₀ + s)²] = y₀² + 2y₀ m_k + E[s²]`). In the frequency domain it is a spectral line at
/// `f = 0` with coefficient `y₀`; the jitter's `γ(0) = 1` leaves it alone and the Dirichlet
/// window gives it `y₀ Γ_N(f)` in the data's first moment, which is `N y₀` at the DFT bin
/// `f = 0` and zero at every other bin of the DFT grid.
///
/// Parameters: those of `s`, then `offset` when [`estimated`](Self::estimated); a known
/// offset is part of the model but not a parameter (the parameters and their names are those
/// of `s`, so a model without an estimated offset reports exactly what `s` reports).
#[derive(Debug, Clone, PartialEq)]
pub struct Offset<S> {
    inner: S,
    offset: f64,
    estimated: bool,
}

impl<S: Signal> Offset<S> {
    /// `offset + signal`, with the offset a parameter when `estimated`.
    ///
    /// # Errors
    ///
    /// [`SignalError::NotFinite`] for a NaN or infinite offset.
    pub fn new(signal: S, offset: f64, estimated: bool) -> Result<Self, SignalError> {
        crate::error::finite(OFFSET_PARAM, offset)?;
        Ok(Self {
            inner: signal,
            offset,
            estimated,
        })
    }

    /// The signal without the offset.
    pub fn signal(&self) -> &S {
        &self.inner
    }

    /// The offset `y₀`.
    pub fn offset(&self) -> f64 {
        self.offset
    }

    /// Whether `y₀` is a parameter (the last one).
    pub fn estimated(&self) -> bool {
        self.estimated
    }

    /// The inner signal's gradient columns with the offset's column (all ones) appended when
    /// it is a parameter: `∂(y₀ + m_k)/∂y₀ = 1`.
    fn with_offset_column(&self, mut cols: Jacobian, n: usize) -> Jacobian {
        if self.estimated {
            cols.push(vec![1.0; n]);
        }
        cols
    }
}

impl<S: Signal + Clone> Signal for Offset<S> {
    fn param_names(&self) -> Vec<String> {
        let mut names = self.inner.param_names();
        if self.estimated {
            names.push(OFFSET_PARAM.into());
        }
        names
    }

    fn params(&self) -> Vec<f64> {
        let mut p = self.inner.params();
        if self.estimated {
            p.push(self.offset);
        }
        p
    }

    fn with_params(&self, params: &[f64]) -> Result<Self, SignalError> {
        let (inner, own) =
            crate::error::split_trailing(params, self.inner.num_params(), self.estimated)?;
        Self::new(
            self.inner.with_params(inner)?,
            own.unwrap_or(self.offset),
            self.estimated,
        )
    }

    fn value(&self, t: f64) -> f64 {
        self.offset + self.inner.value(t)
    }

    fn value_gradient(&self, t: f64, grad: &mut [f64]) {
        let n = self.inner.num_params();
        self.inner.value_gradient(t, &mut grad[..n]);
        if self.estimated {
            grad[n] = 1.0;
        }
    }

    fn value_and_gradient(&self, t: f64, grad: &mut [f64]) -> f64 {
        let n = self.inner.num_params();
        let v = self.inner.value_and_gradient(t, &mut grad[..n]);
        if self.estimated {
            grad[n] = 1.0;
        }
        self.offset + v
    }

    fn breakpoints(&self) -> Vec<f64> {
        self.inner.breakpoints()
    }

    fn rate(&self) -> f64 {
        self.inner.rate()
    }

    fn num_params(&self) -> usize {
        self.inner.num_params() + usize::from(self.estimated)
    }

    fn expected_values(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Vec<f64> {
        let mut m = self.inner.expected_values(grid, jitter);
        m.iter_mut().for_each(|v| *v += self.offset);
        m
    }

    fn expected_values_gradient(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Jacobian {
        let cols = self.inner.expected_values_gradient(grid, jitter);
        self.with_offset_column(cols, grid.len())
    }

    fn expected_values_and_gradient(
        &self,
        grid: &SampleGrid,
        jitter: &dyn JitterModel,
    ) -> (Vec<f64>, Jacobian) {
        let (mut m, cols) = self.inner.expected_values_and_gradient(grid, jitter);
        m.iter_mut().for_each(|v| *v += self.offset);
        (m, self.with_offset_column(cols, grid.len()))
    }

    fn expected_squares(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Vec<f64> {
        let y0 = self.offset;
        let squares = self.inner.expected_squares(grid, jitter);
        if y0 == 0.0 {
            // Bit for bit the inner signal's: a zero offset changes no number.
            return squares;
        }
        let means = self.inner.expected_values(grid, jitter);
        squares
            .iter()
            .zip(&means)
            .map(|(s2, m)| s2 + y0 * (2.0 * m + y0))
            .collect()
    }
}

impl<S: Spectrum + Clone> Spectrum for Offset<S> {
    fn density(&self, f: f64) -> Complex64 {
        self.inner.density(f)
    }

    fn density_gradient(&self, f: f64, grad: &mut [Complex64]) {
        let n = self.inner.num_params();
        self.inner.density_gradient(f, &mut grad[..n]);
        if self.estimated {
            grad[n] = Complex64::new(0.0, 0.0);
        }
    }

    /// The inner signal's lines, then the offset's line at `f = 0` (coefficient `y₀`), also
    /// when `y₀ = 0` so that the lines and their gradient keep one shape along a search.
    fn lines(&self) -> Vec<SpectralLine> {
        let mut lines = self.inner.lines();
        lines.push(SpectralLine {
            frequency: 0.0,
            coefficient: Complex64::new(self.offset, 0.0),
        });
        lines
    }

    fn lines_gradient(&self) -> Vec<Vec<(Complex64, f64)>> {
        let zero = (Complex64::new(0.0, 0.0), 0.0);
        let n = self.num_params();
        let mut rows: Vec<Vec<(Complex64, f64)>> = self
            .inner
            .lines_gradient()
            .into_iter()
            .map(|mut row| {
                row.resize(n, zero);
                row
            })
            .collect();
        // An inner signal without lines has an empty gradient: one row of zeros per line.
        rows.resize(self.inner.lines().len(), vec![zero; n]);
        let mut own = vec![zero; n];
        if self.estimated {
            own[n - 1] = (Complex64::new(1.0, 0.0), 0.0);
        }
        rows.push(own);
        rows
    }
}
