//! The closed-form Fourier transform of a signal, for the frequency-integral route.

use crate::Signal;
use num_complex::Complex64;

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

/// The Fourier transform `S_c(f) = ∫ s(t) e^{-i2πft} dt` of a [`Signal`] in closed form: a
/// density part [`density`](Self::density) plus spectral [`lines`](Self::lines). A
/// finite-duration response has a density only, a sinusoid lines only.
///
/// Optional: estimation and simulation never use it. It serves the literal frequency-domain
/// first moment (`jitterid_window::first_moment_integral`), the independent reference against
/// which the time-domain route is checked.
pub trait Spectrum: Signal {
    /// The density part of `S_c(f)`.
    fn density(&self, f: f64) -> Complex64;

    /// `∂S_c(f)/∂θ_j` of the density part, into `grad` (one entry per parameter).
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
}
