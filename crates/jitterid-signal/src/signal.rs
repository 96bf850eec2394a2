use crate::{SampleGrid, SignalError};
use jitterid_jitter::JitterModel;
use num_complex::Complex64;
use std::fmt;

/// A spectral line of a signal: the term `coefficient · e^{i2π·frequency·t}` of `s(t)`.
///
/// A real sinusoid `A sin(2πf0 t + φ)` is the pair of lines at `±f0` with coefficients
/// `A e^{±iφ} / (±2i)`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SpectralLine {
    /// Frequency `f_l` in Hz.
    pub frequency: f64,
    /// Complex amplitude `c_l`.
    pub coefficient: Complex64,
}

/// Derivatives of a vector quantity with respect to the parameters: `columns[j][k] = ∂x_k/∂θ_j`.
pub type Jacobian = Vec<Vec<f64>>;

/// A continuous-time signal model `s(t; θ)`.
///
/// Its Fourier transform `S_c(f) = ∫ s(t) e^{-i2πft} dt` is a density part
/// [`density`](Self::density) plus spectral [`lines`](Self::lines): a finite-duration response
/// has a density only, a sinusoid lines only.
///
/// Required: the parameters, `s(t)` and its gradient, and `S_c`. Provided: the jitter
/// expectations `m_k = E[s(t_k + τ)]` and `E[s(t_k + τ)²]` by quadrature over the jitter,
/// which a model overrides with a faster exact route where it has one (the LTI response does).
pub trait Signal: fmt::Debug + Send + Sync {
    /// Names of the parameters `θ`, in order.
    fn param_names(&self) -> Vec<String>;

    /// The current parameters `θ`.
    fn params(&self) -> Vec<f64>;

    /// The same model with parameters `θ`, validated like the constructor.
    fn with_params(&self, params: &[f64]) -> Result<Self, SignalError>
    where
        Self: Sized;

    /// `s(t)`.
    fn value(&self, t: f64) -> f64;

    /// `∂s(t)/∂θ_j` for every parameter, into `grad`.
    fn value_gradient(&self, t: f64, grad: &mut [f64]);

    /// The density part of `S_c(f)`.
    fn density(&self, f: f64) -> Complex64;

    /// `∂S_c(f)/∂θ_j` of the density part, into `grad`.
    fn density_gradient(&self, f: f64, grad: &mut [Complex64]);

    /// Spectral lines of `s` (none by default).
    fn lines(&self) -> Vec<SpectralLine> {
        Vec::new()
    }

    /// Gradient of the spectral lines' coefficients and frequencies:
    /// `(∂c_l/∂θ_j, ∂f_l/∂θ_j)` as `[l][j]`. Empty by default, like [`lines`](Self::lines).
    fn lines_gradient(&self) -> Vec<Vec<(Complex64, f64)>> {
        Vec::new()
    }

    /// Times where `s` is not analytic (input switches, start and end of the response), in
    /// increasing order.
    fn breakpoints(&self) -> Vec<f64> {
        Vec::new()
    }

    /// Fastest local rate of `s` in 1/s (largest pole modulus, `2πf` of the fastest tone):
    /// sets the resolution of quadrature over the jitter.
    fn rate(&self) -> f64;

    /// Number of parameters.
    fn num_params(&self) -> usize {
        self.params().len()
    }

    /// `m_k = E[s(t_k + τ)]` for every requested instant.
    fn expected_values(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Vec<f64> {
        let breaks = self.breakpoints();
        let (lo, hi) = jitter.reach();
        grid.times()
            .map(|t| {
                let rule = jitter.rule(&local_breaks(&breaks, t, lo, hi), self.rate());
                rule.expect(|tau| self.value(t + tau))
            })
            .collect()
    }

    /// `∂m_k/∂θ_j` as columns, one per parameter.
    fn expected_values_gradient(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Jacobian {
        let p = self.num_params();
        let mut cols = vec![vec![0.0; grid.len()]; p];
        let breaks = self.breakpoints();
        let (lo, hi) = jitter.reach();
        let mut g = vec![0.0; p];
        for (k, t) in grid.times().enumerate() {
            let rule = jitter.rule(&local_breaks(&breaks, t, lo, hi), self.rate());
            for (&tau, &w) in rule.nodes.iter().zip(&rule.weights) {
                self.value_gradient(t + tau, &mut g);
                for (col, gj) in cols.iter_mut().zip(&g) {
                    col[k] += w * gj;
                }
            }
        }
        cols
    }

    /// `E[s(t_k + τ)²]` for every requested instant (for the second moment
    /// `Var y_k = σ_v² + E[s(t_k+τ)²] − m_k²`).
    fn expected_squares(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Vec<f64> {
        let breaks = self.breakpoints();
        let (lo, hi) = jitter.reach();
        grid.times()
            .map(|t| {
                let rule = jitter.rule(&local_breaks(&breaks, t, lo, hi), 2.0 * self.rate());
                rule.expect(|tau| self.value(t + tau).powi(2))
            })
            .collect()
    }
}

/// The breakpoints of `s` (sorted) seen from instant `t` within the jitter's reach `[lo, hi]`,
/// in jitter time `τ = b - t`. Cost `O(log B)` plus the number returned.
pub fn local_breaks(breaks: &[f64], t: f64, lo: f64, hi: f64) -> Vec<f64> {
    let first = breaks.partition_point(|&b| b - t <= lo);
    breaks[first..]
        .iter()
        .map(|b| b - t)
        .take_while(|&tau| tau < hi)
        .collect()
}
