//! Frequency-domain criteria: naive LS (the paper's eq. 9), BCLS (eq. 14), weighted BCLS and
//! the Box–Jenkins criterion, all of the form
//!
//! ```text
//! V(θ) = ½ Σ_f w_f(θ) |Y(f) − μ_Y(f; θ)|²  = ½ Σ r_i(θ)²
//! ```
//!
//! over an arbitrary [`FrequencySet`]. The residual vector stacks
//! `√w_f Re(Y − μ)` and `√w_f Im(Y − μ)` per frequency. Jacobians are analytic in the signal's
//! parameters (the transform of `∂m_k/∂θ`) and central finite differences in the jitter's and
//! the noise shape's.

use crate::data::Record;
use crate::noise::NoiseModel;
use crate::structure::ModelStructure;
use crate::EstimateError;
use faer::Mat;
use jitterid_jitter::{JitterModel, NoJitter};
use jitterid_signal::Signal;
use jitterid_window::{transform, FrequencySet, Window};
use num_complex::Complex64;
use std::fmt;

/// The data side of a frequency-domain criterion: the record, the window, the frequency set
/// and the windowed DTFT `Y(f)` at those frequencies, computed once.
#[derive(Debug, Clone)]
pub struct FrequencyData<W> {
    record: Record,
    window: W,
    freqs: FrequencySet,
    y: Vec<Complex64>,
}

impl<W: Window> FrequencyData<W> {
    /// Transforms the record once.
    pub fn new(record: Record, window: W, freqs: FrequencySet) -> Result<Self, EstimateError> {
        let y = transform(record.grid(), &window, record.y(), &freqs)?;
        Ok(Self {
            record,
            window,
            freqs,
            y,
        })
    }

    /// The record.
    pub fn record(&self) -> &Record {
        &self.record
    }

    /// The window.
    pub fn window(&self) -> &W {
        &self.window
    }

    /// The frequency set.
    pub fn frequencies(&self) -> &FrequencySet {
        &self.freqs
    }

    /// `Y(f)` at the frequency set.
    pub fn dtft(&self) -> &[Complex64] {
        &self.y
    }

    /// Number of real residuals (two per frequency).
    pub fn num_residuals(&self) -> usize {
        2 * self.freqs.len()
    }

    /// `μ_Y(f)` for the model's first moment `m_k`, or NaN where `m` is not finite.
    pub fn transform_moment(&self, m: &[f64]) -> Vec<Complex64> {
        transform(self.record.grid(), &self.window, m, &self.freqs)
            .unwrap_or_else(|_| vec![Complex64::new(f64::NAN, f64::NAN); self.freqs.len()])
    }
}

/// A frequency-weighted least-squares criterion on the first moment of the DTFT.
///
/// Required: a name, whether the model of the mean includes the jitter, and the weights
/// `w_f`. Provided: residuals, their Jacobian with respect to the structure's free parameters,
/// and the cost. A new criterion of this family (a different weighting) is one new type.
pub trait Criterion: fmt::Debug + Send + Sync {
    /// Short name (`"ls"`, `"bcls"`, …).
    fn name(&self) -> &'static str;

    /// Whether `μ_Y` includes the jitter's damping (false for naive LS, which uses `γ ≡ 1`).
    fn models_jitter(&self) -> bool;

    /// Whether the weights depend on the noise model (so its parameters enter the criterion).
    fn uses_noise_model(&self) -> bool {
        false
    }

    /// Whether the weighted residuals at the true parameters have the same variance at every
    /// frequency (white measurement noise for BCLS; the noise model's shape divided out for
    /// Box–Jenkins), so that [`estimate`](crate::estimate) can check a converged fit with
    /// [`residual_flatness`](crate::residual_flatness). False by default (naive LS keeps the
    /// jitter's bias in its residuals; user weights can shape them arbitrarily).
    fn flat_residuals(&self) -> bool {
        false
    }

    /// Weights `w_f ≥ 0`, one per frequency of the set.
    fn weights<N: NoiseModel>(&self, freqs: &FrequencySet, noise: &N) -> Vec<f64>;

    /// Checks the criterion against a frequency set before a fit (for example the number of
    /// user weights).
    fn validate(&self, freqs: &FrequencySet) -> Result<(), EstimateError> {
        let _ = freqs;
        Ok(())
    }

    /// The model's `m_k`: with the structure's jitter, or none for a criterion that ignores it.
    fn first_moment<S: Signal, J: JitterModel, N: NoiseModel, W: Window>(
        &self,
        data: &FrequencyData<W>,
        model: &ModelStructure<S, J, N>,
    ) -> Vec<f64> {
        let grid = data.record().grid();
        if self.models_jitter() {
            model.signal.expected_values(grid, &model.jitter)
        } else {
            model.signal.expected_values(grid, &NoJitter)
        }
    }

    /// The residual vector `r(θ)` (length `2F`).
    fn residuals<S: Signal, J: JitterModel, N: NoiseModel, W: Window>(
        &self,
        data: &FrequencyData<W>,
        model: &ModelStructure<S, J, N>,
    ) -> Vec<f64> {
        let mu = data.transform_moment(&self.first_moment(data, model));
        let w = self.weights(data.frequencies(), &model.noise);
        stack(data.dtft(), &mu, &w)
    }

    /// `V = ½ Σ r²`.
    fn cost<S: Signal, J: JitterModel, N: NoiseModel, W: Window>(
        &self,
        data: &FrequencyData<W>,
        model: &ModelStructure<S, J, N>,
    ) -> f64 {
        0.5 * self
            .residuals(data, model)
            .iter()
            .map(|r| r * r)
            .sum::<f64>()
    }

    /// `∂r/∂θ` (rows residuals, columns the structure's free parameters).
    fn jacobian<S: Signal + Clone, J: JitterModel + Clone, N: NoiseModel, W: Window>(
        &self,
        data: &FrequencyData<W>,
        model: &ModelStructure<S, J, N>,
    ) -> Mat<f64> {
        let (ns, nj, nn) = model.blocks();
        let rows = data.num_residuals();
        let mut jac = Mat::<f64>::zeros(rows, ns + nj + nn);
        let w = self.weights(data.frequencies(), &model.noise);
        let sw: Vec<f64> = w.iter().map(|w| w.sqrt()).collect();
        let grid = data.record().grid();
        // Residuals are Y − μ, so ∂r = −√w ∂μ.
        let mut put = |col: usize, dmu: &[Complex64]| {
            for (f, d) in dmu.iter().enumerate() {
                jac[(2 * f, col)] = -sw[f] * d.re;
                jac[(2 * f + 1, col)] = -sw[f] * d.im;
            }
        };
        if ns > 0 {
            let cols = if self.models_jitter() {
                model.signal.expected_values_gradient(grid, &model.jitter)
            } else {
                model.signal.expected_values_gradient(grid, &NoJitter)
            };
            for (j, c) in cols.iter().enumerate() {
                put(j, &data.transform_moment(c));
            }
        }
        if nj > 0 && self.models_jitter() {
            let theta = model.jitter.params();
            for j in 0..nj {
                let dm = central_difference(&theta, j, |p| {
                    let jit = model.jitter.with_params(p).ok()?;
                    Some(model.signal.expected_values(grid, &jit))
                });
                match dm {
                    Some(dm) => put(ns + j, &data.transform_moment(&dm)),
                    None => put(
                        ns + j,
                        &vec![Complex64::new(f64::NAN, f64::NAN); data.frequencies().len()],
                    ),
                }
            }
        }
        if nn > 0 && self.uses_noise_model() {
            let theta = model.noise.params();
            let mu = data.transform_moment(&self.first_moment(data, model));
            for j in 0..nn {
                let dr = central_difference(&theta, j, |p| {
                    let noise = model.noise.with_params(p).ok()?;
                    Some(stack(
                        data.dtft(),
                        &mu,
                        &self.weights(data.frequencies(), &noise),
                    ))
                });
                for i in 0..rows {
                    jac[(i, ns + nj + j)] = dr.as_ref().map_or(f64::NAN, |d| d[i]);
                }
            }
        }
        jac
    }
}

/// `[√w_f Re(Y − μ), √w_f Im(Y − μ)]` per frequency.
fn stack(y: &[Complex64], mu: &[Complex64], w: &[f64]) -> Vec<f64> {
    let mut r = Vec::with_capacity(2 * y.len());
    for ((y, m), w) in y.iter().zip(mu).zip(w) {
        let d = (y - m) * w.sqrt();
        r.push(d.re);
        r.push(d.im);
    }
    r
}

/// Central difference of a vector function of `θ` in coordinate `j`, falling back to a one-sided
/// difference where a side leaves the model's domain (for example `a ≤ 0`).
pub(crate) fn central_difference(
    theta: &[f64],
    j: usize,
    f: impl Fn(&[f64]) -> Option<Vec<f64>>,
) -> Option<Vec<f64>> {
    let h = 1e-6 * theta[j].abs().max(1e-3);
    let mut plus = theta.to_vec();
    plus[j] += h;
    let mut minus = theta.to_vec();
    minus[j] -= h;
    match (f(&plus), f(&minus)) {
        (Some(a), Some(b)) => Some(a.iter().zip(&b).map(|(a, b)| (a - b) / (2.0 * h)).collect()),
        (Some(a), None) => {
            let c = f(theta)?;
            Some(a.iter().zip(&c).map(|(a, c)| (a - c) / h).collect())
        }
        (None, Some(b)) => {
            let c = f(theta)?;
            Some(c.iter().zip(&b).map(|(c, b)| (c - b) / h).collect())
        }
        (None, None) => None,
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
    fn weights<N: NoiseModel>(&self, freqs: &FrequencySet, _: &N) -> Vec<f64> {
        vec![1.0; freqs.len()]
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
    fn weights<N: NoiseModel>(&self, freqs: &FrequencySet, _: &N) -> Vec<f64> {
        vec![1.0; freqs.len()]
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
    fn weights<N: NoiseModel>(&self, _: &FrequencySet, _: &N) -> Vec<f64> {
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
/// with noise spectrum `σ²|H(f)|²`,
/// `Σ_f [ |Y − μ|² / (σ² |H_f|²) + log(σ² |H_f|²) ]`, with `σ²` concentrated out. The
/// minimiser over `σ²` turns it into the sum of squares `Σ_f |Y − μ|² / |H̃_f|²` with
/// `H̃ = H / exp(mean_f log|H_f|)`, which keeps the `log|H|²` term (so the noise shape is
/// identifiable) while staying a least-squares problem.
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
    fn weights<N: NoiseModel>(&self, freqs: &FrequencySet, noise: &N) -> Vec<f64> {
        let t = freqs.interval();
        let shape: Vec<f64> = freqs
            .frequencies()
            .iter()
            .map(|&f| noise.shape(f, t))
            .collect();
        let mean_log = shape.iter().map(|s| s.ln()).sum::<f64>() / shape.len() as f64;
        let g = mean_log.exp();
        shape.iter().map(|s| g / s).collect()
    }
}
