//! Frequency-domain criteria: naive LS (the paper's eq. 9), BCLS (eq. 14), weighted BCLS and
//! the Box–Jenkins criterion, all of the form
//!
//! ```text
//! V(θ) = ½ Σ_f w_f |Y(f) − μ_Y(f; θ)|²  = ½ Σ r_i(θ)²
//! ```
//!
//! over an arbitrary [`FrequencySet`]. A criterion is its weights `w_f`: they may depend on the
//! frequency set, the data `Y(f)` and the model at the current parameters (its first moment
//! `μ_Y`, the jitter's `γ(f)`, the noise shape, the variance of `Y(f)`), all offered by the
//! [`WeightContext`]. The residuals, their Jacobian and the cost are the same for every
//! criterion ([`FrequencyData::residuals`](crate::FrequencyData::residuals),
//! [`jacobian`](crate::FrequencyData::jacobian), [`cost`](crate::FrequencyData::cost)).
//! The trait is object safe: criteria can be collected in a `Vec<Box<dyn Criterion>>`.

use crate::noise::NoiseModel;
use crate::structure::ModelStructure;
use crate::EstimateError;
use jitterid_jitter::JitterModel;
use jitterid_signal::{SampleGrid, Signal};
use jitterid_window::FrequencySet;
use num_complex::Complex64;
use std::fmt;
use std::sync::OnceLock;

/// A frequency-weighted least-squares criterion on the first moment of the DTFT.
///
/// Required: a name, whether the model of the mean includes the jitter, and the weights
/// `w_f ≥ 0`. Everything else has a default. A new criterion (a different weighting) is one
/// new type; see the criterion section of `docs/extending.md`.
pub trait Criterion: fmt::Debug + Send + Sync {
    /// Short name (`"ls"`, `"bcls"`, …).
    fn name(&self) -> &'static str;

    /// Whether `μ_Y` includes the jitter's damping (false for naive LS, which uses `γ ≡ 1`).
    fn models_jitter(&self) -> bool;

    /// Whether the weights depend on the noise model (so its parameters enter the criterion
    /// through the weights).
    fn uses_noise_model(&self) -> bool {
        false
    }

    /// Whether the weights depend on the model's parameters (through `μ_Y`, `γ(f)` or the
    /// variance of `Y(f)`), so that the Jacobian must include `∂√w_f/∂θ`. False by default:
    /// weights of the frequency set and the data alone.
    fn model_dependent_weights(&self) -> bool {
        false
    }

    /// Whether the weighted residuals at the true parameters have the same variance at every
    /// frequency (white measurement noise for BCLS; the noise model's shape divided out for
    /// Box–Jenkins), so that [`fit`](crate::fit) checks a converged fit with
    /// [`residual_flatness`](crate::residual_flatness). False by default (naive LS keeps the
    /// jitter's bias in its residuals; user weights can shape them arbitrarily); a criterion of
    /// your own that declares it gets the same check.
    fn flat_residuals(&self) -> bool {
        false
    }

    /// Weights `w_f ≥ 0`, one per frequency of the set.
    fn weights(&self, context: &WeightContext<'_>) -> Vec<f64>;

    /// Checks the criterion against a frequency set before a fit (for example the number of
    /// user weights).
    fn validate(&self, freqs: &FrequencySet) -> Result<(), EstimateError> {
        let _ = freqs;
        Ok(())
    }
}

/// A criterion behind a pointer is the criterion it points to, so that `Box<dyn Criterion>`,
/// `Arc<dyn Criterion>` and `&dyn Criterion` fit like the concrete type.
macro_rules! forward_criterion {
    ($($pointer:ty),*) => {$(
        impl<C: Criterion + ?Sized> Criterion for $pointer {
            fn name(&self) -> &'static str {
                (**self).name()
            }
            fn models_jitter(&self) -> bool {
                (**self).models_jitter()
            }
            fn uses_noise_model(&self) -> bool {
                (**self).uses_noise_model()
            }
            fn model_dependent_weights(&self) -> bool {
                (**self).model_dependent_weights()
            }
            fn flat_residuals(&self) -> bool {
                (**self).flat_residuals()
            }
            fn weights(&self, context: &WeightContext<'_>) -> Vec<f64> {
                (**self).weights(context)
            }
            fn validate(&self, freqs: &FrequencySet) -> Result<(), EstimateError> {
                (**self).validate(freqs)
            }
        }
    )*};
}

forward_criterion!(Box<C>, std::sync::Arc<C>, &C);

/// The parts of a model structure that weights may look at, without its type parameters.
pub(crate) trait ModelView: Sync {
    fn jitter_cf(&self, f: f64) -> Complex64;
    fn noise_shape(&self, f: f64, interval: f64) -> f64;
    fn jitter_variances(&self, grid: &SampleGrid) -> Vec<f64>;
    fn noise_std(&self) -> Option<f64>;
    fn estimated_signal_gradient(&self, grid: &SampleGrid) -> Vec<Vec<f64>>;
}

impl<S: Signal, J: JitterModel, N: NoiseModel> ModelView for ModelStructure<S, J, N> {
    fn jitter_cf(&self, f: f64) -> Complex64 {
        self.jitter.cf(f)
    }
    fn noise_shape(&self, f: f64, interval: f64) -> f64 {
        self.noise.shape(f, interval)
    }
    fn jitter_variances(&self, grid: &SampleGrid) -> Vec<f64> {
        let m = self.signal.expected_values(grid, &self.jitter);
        let s2 = self.signal.expected_squares(grid, &self.jitter);
        s2.iter()
            .zip(&m)
            .map(|(s2, m)| (s2 - m * m).max(0.0))
            .collect()
    }
    fn noise_std(&self) -> Option<f64> {
        self.noise_std
    }
    fn estimated_signal_gradient(&self, grid: &SampleGrid) -> Vec<Vec<f64>> {
        if self.estimate_signal {
            self.signal.expected_values_gradient(grid, &self.jitter)
        } else {
            Vec::new()
        }
    }
}

/// What a criterion's weights may depend on: the frequency set, the data's DTFT `Y(f)`, and the
/// model at the current parameters.
pub struct WeightContext<'a> {
    pub(crate) freqs: &'a FrequencySet,
    pub(crate) grid: &'a SampleGrid,
    pub(crate) dtft: &'a [Complex64],
    pub(crate) model_dtft: Option<&'a [Complex64]>,
    pub(crate) lazy_model_dtft: OnceLock<Vec<Complex64>>,
    pub(crate) first_moment: &'a (dyn Fn() -> Vec<Complex64> + 'a),
    pub(crate) transform: &'a (dyn Fn(&[f64]) -> Vec<Complex64> + 'a),
    pub(crate) model: &'a dyn ModelView,
}

impl fmt::Debug for WeightContext<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("WeightContext")
            .field("frequencies", &self.freqs.len())
            .finish_non_exhaustive()
    }
}

impl WeightContext<'_> {
    /// The frequency set (Hz).
    pub fn frequencies(&self) -> &FrequencySet {
        self.freqs
    }

    /// The sampling grid of the record.
    pub fn grid(&self) -> &SampleGrid {
        self.grid
    }

    /// The data's windowed DTFT `Y(f)` at the frequency set.
    pub fn dtft(&self) -> &[Complex64] {
        self.dtft
    }

    /// The model's first moment `μ_Y(f; θ)` at the frequency set (with the jitter if the
    /// criterion models it).
    pub fn model_dtft(&self) -> &[Complex64] {
        match self.model_dtft {
            Some(mu) => mu,
            None => self.lazy_model_dtft.get_or_init(self.first_moment),
        }
    }

    /// The jitter's characteristic function `γ(f)` at the frequency set.
    pub fn jitter_cf(&self) -> Vec<Complex64> {
        let f = self.freqs.frequencies();
        f.iter().map(|&f| self.model.jitter_cf(f)).collect()
    }

    /// The noise model's shape `|H(f)|²` at the frequency set.
    pub fn noise_shape(&self) -> Vec<f64> {
        let t = self.freqs.interval();
        let f = self.freqs.frequencies();
        f.iter().map(|&f| self.model.noise_shape(f, t)).collect()
    }

    /// `∂μ_Y/∂θ` at the frequency set for each estimated parameter of the signal (with the
    /// structure's jitter; none when the signal is not estimated). Costs the signal's moment
    /// gradient.
    pub fn signal_sensitivities(&self) -> Vec<Vec<Complex64>> {
        self.model
            .estimated_signal_gradient(self.grid)
            .iter()
            .map(|c| (self.transform)(c))
            .collect()
    }

    /// The structure's known measurement-noise standard deviation, if any.
    pub fn noise_std(&self) -> Option<f64> {
        self.model.noise_std()
    }

    /// `Var Y(f)` of the unwindowed DTFT at the frequency set for measurement-noise level
    /// `noise_std`: the jitter's flat floor `Σ_k (E[s(t_k+τ)²] − m_k²)` plus the measurement
    /// noise `N σ_v² |H(f)|²` (exact for white noise, the long-record value for coloured
    /// noise). Costs two passes of the signal's moments.
    pub fn dtft_variance(&self, noise_std: f64) -> Vec<f64> {
        let floor: f64 = self.model.jitter_variances(self.grid).iter().sum();
        let n = self.grid.len() as f64;
        self.noise_shape()
            .iter()
            .map(|h| floor + n * noise_std * noise_std * h)
            .collect()
    }
}

/// Naive least squares, the paper's eq. (9): the jitter is ignored (`γ ≡ 1`), so the estimate
/// is biased where `|γ|` departs from 1.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Ls;

impl Criterion for Ls {
    fn name(&self) -> &'static str {
        "ls"
    }
    fn models_jitter(&self) -> bool {
        false
    }
    fn weights(&self, context: &WeightContext<'_>) -> Vec<f64> {
        vec![1.0; context.frequencies().len()]
    }
}

/// Bias-compensated least squares, the paper's eq. (14): `μ_Y` includes the jitter.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Bcls;

impl Criterion for Bcls {
    fn name(&self) -> &'static str {
        "bcls"
    }
    fn models_jitter(&self) -> bool {
        true
    }
    fn flat_residuals(&self) -> bool {
        true
    }
    fn weights(&self, context: &WeightContext<'_>) -> Vec<f64> {
        vec![1.0; context.frequencies().len()]
    }
}

/// BCLS with user weights `w_f ≥ 0`, one per frequency of the set.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WeightedBcls {
    weights: Vec<f64>,
}

impl WeightedBcls {
    /// Validates the weights (finite, non-negative, not all zero).
    pub fn new(weights: Vec<f64>) -> Result<Self, EstimateError> {
        if let Some((index, &value)) = weights
            .iter()
            .enumerate()
            .find(|(_, w)| !(w.is_finite() && **w >= 0.0))
        {
            return Err(EstimateError::BadWeight { index, value });
        }
        if weights.iter().all(|&w| w == 0.0) {
            return Err(EstimateError::BadWeight {
                index: 0,
                value: 0.0,
            });
        }
        Ok(Self { weights })
    }
}

impl Criterion for WeightedBcls {
    fn name(&self) -> &'static str {
        "weighted-bcls"
    }
    fn models_jitter(&self) -> bool {
        true
    }
    fn weights(&self, _: &WeightContext<'_>) -> Vec<f64> {
        self.weights.clone()
    }
    fn validate(&self, freqs: &FrequencySet) -> Result<(), EstimateError> {
        if self.weights.len() == freqs.len() {
            Ok(())
        } else {
            Err(EstimateError::BadWeight {
                index: self.weights.len().min(freqs.len()),
                value: f64::NAN,
            })
        }
    }
}

/// The Box–Jenkins frequency-domain criterion: the Gaussian log-likelihood of the residual DTFT
/// with noise spectrum `σ²|H(f)|²`, restricted to the residuals (REML), with `σ²` concentrated
/// out:
///
/// ```text
/// Σ_f [ |Y − μ|² / (σ² |H_f|²) + log(σ² |H_f|²) ] + log det(Xᵀ Φ⁻¹ X)
/// ```
///
/// `X` the sensitivities `∂μ/∂θ` of the `p` estimated signal parameters (real and imaginary
/// parts) and `Φ = σ²|H|²`. The minimiser over `σ²` is `Σ|Y − μ|²/|H|² / (M − p)` (`M` real
/// residuals), which turns the criterion into the sum of squares `Σ_f G |Y − μ|² / |H_f|²` with
/// the scalar `G = exp[(Σ log|H_f|² + log det(Xᵀ|H|⁻²X)) / (M − p)]` (both sums over the real
/// residuals): the `log|H|²` term keeps the noise shape identifiable while the problem stays a
/// least-squares one.
///
/// The determinant accounts for the residual power the signal's fit takes out: without it the
/// plain likelihood's score for the noise shape has expectation `−½ Σ h_i ∂log Φ_i` at the truth
/// (`h_i` the fit's leverages, concentrated where the input has power), which biases the shape
/// towards a flat spectrum by `O(p/N)` (on Table 2 with AR(1) noise, `N = 200`, about 6 standard
/// errors of a 128-record mean). Its derivative in the noise shape is exactly `−Σ h_i ∂log Φ_i`,
/// so the REML score has expectation zero. Without estimated signal parameters `G` is the
/// geometric mean of `|H|²` and the criterion the plain concentrated likelihood.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BoxJenkins;

impl Criterion for BoxJenkins {
    fn name(&self) -> &'static str {
        "bj"
    }
    fn models_jitter(&self) -> bool {
        true
    }
    fn flat_residuals(&self) -> bool {
        true
    }
    fn uses_noise_model(&self) -> bool {
        true
    }
    fn model_dependent_weights(&self) -> bool {
        // G depends on the signal's sensitivities.
        true
    }
    fn weights(&self, context: &WeightContext<'_>) -> Vec<f64> {
        let shape = context.noise_shape();
        let sum_log = 2.0 * shape.iter().map(|s| s.ln()).sum::<f64>();
        let residuals = 2 * shape.len();
        let sens = context.signal_sensitivities();
        let log_g = match restricted_log_det(&sens, &shape) {
            Some(log_det) if sens.len() < residuals => {
                (sum_log + log_det) / (residuals - sens.len()) as f64
            }
            _ => sum_log / residuals as f64,
        };
        let g = log_g.exp();
        shape.iter().map(|s| g / s).collect()
    }
}

/// `log det(Xᵀ|H|⁻²X)` for the sensitivities `X` (one column of `∂μ/∂θ` per parameter, real and
/// imaginary parts as rows) and the noise shape `|H|²`, by Cholesky; `None` without columns or
/// when the matrix is not numerically positive definite (the plain likelihood then).
fn restricted_log_det(sens: &[Vec<Complex64>], shape: &[f64]) -> Option<f64> {
    let p = sens.len();
    if p == 0 {
        return None;
    }
    let mut a = vec![0.0; p * p];
    for i in 0..p {
        for j in 0..=i {
            let v: f64 = sens[i]
                .iter()
                .zip(&sens[j])
                .zip(shape)
                .map(|((x, y), s)| (x.re * y.re + x.im * y.im) / s)
                .sum();
            a[i * p + j] = v;
        }
    }
    // In-place Cholesky of the lower triangle.
    let mut log_det = 0.0;
    for j in 0..p {
        let mut d = a[j * p + j];
        for k in 0..j {
            d -= a[j * p + k] * a[j * p + k];
        }
        if !(d.is_finite() && d > 0.0) {
            return None;
        }
        let l = d.sqrt();
        a[j * p + j] = l;
        log_det += 2.0 * l.ln();
        for i in j + 1..p {
            let mut v = a[i * p + j];
            for k in 0..j {
                v -= a[i * p + k] * a[j * p + k];
            }
            a[i * p + j] = v / l;
        }
    }
    Some(log_det)
}
