//! The data side of the frequency-domain criteria ([`FrequencyData`]) and the evaluation of
//! any [`Criterion`] on it: residuals, cost and Jacobian.

use crate::criterion::{Criterion, WeightContext};
use crate::data::Record;
use crate::noise::NoiseModel;
use crate::structure::ModelStructure;
use crate::EstimateError;
use faer::Mat;
use jitterid_jitter::{JitterModel, NoJitter};
use jitterid_optim::finite_diff::{central_difference_vec, MOMENT_FD_STEP};
use jitterid_signal::Signal;
use jitterid_window::{transform, FrequencySet, Window};
use num_complex::Complex64;
use std::sync::OnceLock;

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

    /// `μ_Y(f)` for the model's first moment `m_k`, or NaN where `m` is not finite. A vector
    /// passed by value is freed before the FFT runs.
    pub fn transform_moment(&self, m: impl AsRef<[f64]>) -> Vec<Complex64> {
        transform(self.record.grid(), &self.window, m, &self.freqs)
            .unwrap_or_else(|_| vec![Complex64::new(f64::NAN, f64::NAN); self.freqs.len()])
    }

    /// The model's `m_k` for a criterion: with the structure's jitter, or none for a criterion
    /// that ignores it.
    pub fn first_moment<S: Signal, J: JitterModel, N: NoiseModel, C: Criterion + ?Sized>(
        &self,
        criterion: &C,
        model: &ModelStructure<S, J, N>,
    ) -> Vec<f64> {
        let grid = self.record().grid();
        if criterion.models_jitter() {
            model.signal.expected_values(grid, &model.jitter)
        } else {
            model.signal.expected_values(grid, &NoJitter)
        }
    }

    /// The criterion's residual vector `r(θ)` at `model` (length `2F`): `√w_f Re(Y − μ)`,
    /// `√w_f Im(Y − μ)` per frequency.
    pub fn residuals<S: Signal, J: JitterModel, N: NoiseModel, C: Criterion + ?Sized>(
        &self,
        criterion: &C,
        model: &ModelStructure<S, J, N>,
    ) -> Vec<f64> {
        self.residuals_of_moment(criterion, model, self.first_moment(criterion, model))
    }

    /// [`residuals`](Self::residuals) from the model's first moment `m_k`, already computed.
    pub(crate) fn residuals_of_moment<
        S: Signal,
        J: JitterModel,
        N: NoiseModel,
        C: Criterion + ?Sized,
    >(
        &self,
        criterion: &C,
        model: &ModelStructure<S, J, N>,
        m: Vec<f64>,
    ) -> Vec<f64> {
        let mu = self.transform_moment(m);
        let w = self.weights(criterion, model, Some(&mu));
        stack(self.dtft(), &mu, &w)
    }

    /// The criterion's weights at `model`, whose first moment `μ_Y` is `mu` (computed here,
    /// only if the weights ask for it, when `None`).
    pub fn weights<S: Signal, J: JitterModel, N: NoiseModel, C: Criterion + ?Sized>(
        &self,
        criterion: &C,
        model: &ModelStructure<S, J, N>,
        mu: Option<&[Complex64]>,
    ) -> Vec<f64> {
        criterion.weights(&WeightContext {
            freqs: &self.freqs,
            grid: self.record.grid(),
            dtft: &self.y,
            model_dtft: mu,
            lazy_model_dtft: OnceLock::new(),
            first_moment: &|| self.transform_moment(self.first_moment(criterion, model)),
            transform: &|m| self.transform_moment(m),
            model,
        })
    }

    /// The criterion's `V = ½ Σ r²` at `model`.
    pub fn cost<S: Signal, J: JitterModel, N: NoiseModel, C: Criterion + ?Sized>(
        &self,
        criterion: &C,
        model: &ModelStructure<S, J, N>,
    ) -> f64 {
        0.5 * self
            .residuals(criterion, model)
            .iter()
            .map(|r| r * r)
            .sum::<f64>()
    }

    /// `∂r/∂θ` of the criterion at `model` (rows residuals, columns the structure's free
    /// parameters): analytic in the signal's parameters (the transform of `∂m_k/∂θ`),
    /// central differences in the jitter's and the noise shape's, plus the weights' own
    /// derivative for [`Criterion::model_dependent_weights`].
    pub fn jacobian<S, J, N, C>(&self, criterion: &C, model: &ModelStructure<S, J, N>) -> Mat<f64>
    where
        S: Signal + Clone,
        J: JitterModel + Clone,
        N: NoiseModel,
        C: Criterion + ?Sized,
    {
        let data = self;
        let (ns, nj, nn) = model.blocks();
        let rows = data.num_residuals();
        let mut jac = Mat::<f64>::zeros(rows, ns + nj + nn);
        let w = data.weights(criterion, model, None);
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
            let cols = if criterion.models_jitter() {
                model.signal.expected_values_gradient(grid, &model.jitter)
            } else {
                model.signal.expected_values_gradient(grid, &NoJitter)
            };
            for (j, c) in cols.iter().enumerate() {
                put(j, &data.transform_moment(c));
            }
        }
        if nj > 0 && criterion.models_jitter() {
            let theta = model.jitter.params();
            for j in 0..nj {
                let dm = central_difference_vec(&theta, j, MOMENT_FD_STEP, |p| {
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
        if criterion.model_dependent_weights() {
            // r = √w (Y − μ): add (Y − μ) ∂√w/∂θ, the weights' own dependence on every free
            // parameter, by differences of the residuals at fixed μ.
            let mu = data.transform_moment(data.first_moment(criterion, model));
            let theta = model.params();
            for j in 0..theta.len() {
                let dr = central_difference_vec(&theta, j, MOMENT_FD_STEP, |p| {
                    let m = model.with_params(p).ok()?;
                    let mu_m = data.transform_moment(data.first_moment(criterion, &m));
                    Some(stack(
                        data.dtft(),
                        &mu,
                        &data.weights(criterion, &m, Some(&mu_m)),
                    ))
                });
                for i in 0..rows {
                    jac[(i, j)] += dr.as_ref().map_or(f64::NAN, |d| d[i]);
                }
            }
        } else if nn > 0 && criterion.uses_noise_model() {
            let mu = data.transform_moment(data.first_moment(criterion, model));
            let theta = model.noise.params();
            for j in 0..nn {
                let dr = central_difference_vec(&theta, j, MOMENT_FD_STEP, |p| {
                    let mut m = model.clone();
                    m.noise = model.noise.with_params(p).ok()?;
                    Some(stack(
                        data.dtft(),
                        &mu,
                        &data.weights(criterion, &m, Some(&mu)),
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
