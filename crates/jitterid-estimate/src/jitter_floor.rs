//! The jitter's white floor in a Box–Jenkins noise model: the default way a coloured noise model
//! meets jittered samples.
//!
//! Jittered samples carry their own noise `E[s(t_k+τ)²] − m_k²`, independent from sample to
//! sample, so the residual spectrum of a Box–Jenkins fit is `σ_e²|H(f)|² + λ̄` (`λ̄` the mean
//! of that jitter variance over the record). An ARMA shape alone absorbs the floor and its
//! coefficients are biased towards white noise; [`WithFloor`] models `σ_e² (|H|² + ρ)` with
//! `ρ = λ̄ / σ_e²`.
//!
//! `λ̄` follows from the signal and jitter models and `σ_e` from the residual spectrum, so the
//! floor is not searched for: a free `ρ` is poorly determined by one record (on Table 2 with
//! AR(1) noise its logarithm spreads over ±7 and the AR coefficient stays 6 standard errors
//! off). [`ModelStructure::fit_with_jitter_floor`] fits with the floor known, sets
//! `ρ = λ̄(θ̂) / σ̂_e²` from the estimate, and refits from there, a few rounds; the noise
//! parameters it reports then come from the exact restricted likelihood in time
//! ([`restricted_noise_fit`]), which sees the jitter's variance sample by sample.

use crate::any_noise::AnyNoise;
use crate::data::Record;
use crate::noise::{NoiseModel, WithFloor};
use crate::restricted_noise::{restricted_noise_fit, NoiseEstimate, RESTRICTED_NOISE_MAX_SAMPLES};
use crate::result::Fit;
use crate::solver::Termination;
use crate::structure::ModelStructure;
use crate::EstimateError;
use jitterid_jitter::JitterModel;
use jitterid_signal::{SampleGrid, Signal};

/// The start of the floor `ρ` when the measurement-noise level is not known.
const FLOOR_START_WITHOUT_LEVEL: f64 = 1.0;

/// Fits of [`ModelStructure::fit_with_jitter_floor`]: the first with the floor's start, then
/// refits with `ρ` from the estimate. `ρ` depends on the estimate only through `λ̄(θ̂)` and
/// `σ̂_e`, which the first refit already puts within their sampling error.
pub const JITTER_FLOOR_ROUNDS: usize = 3;

/// `λ̄ = mean_k (E[s(t_k+τ)²] − m_k²)`: the jitter's mean contribution to a sample's variance.
pub fn mean_jitter_variance<S: Signal, J: JitterModel>(
    signal: &S,
    jitter: &J,
    grid: &SampleGrid,
) -> f64 {
    let m = signal.expected_values(grid, jitter);
    let squares = signal.expected_squares(grid, jitter);
    let total: f64 = squares
        .iter()
        .zip(&m)
        .map(|(s, m)| (s - m * m).max(0.0))
        .sum();
    total / grid.len() as f64
}

impl<S, J, N> ModelStructure<S, J, N>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel + 'static,
{
    /// The floor `ρ = λ̄ / σ_e²` for this structure's signal and jitter on `grid`, with
    /// `σ_e` = `noise_std` (`ρ = 1` when the level is unknown, zero or not finite). `None` when
    /// there is nothing to add: white noise (its level already absorbs a flat floor), a shape
    /// that has a floor already, or a jitter that adds no variance.
    pub fn jitter_floor_start(&self, grid: &SampleGrid, noise_std: Option<f64>) -> Option<f64> {
        if self.noise.is_white() || self.noise.floor() > 0.0 {
            return None;
        }
        let lambda = mean_jitter_variance(&self.signal, &self.jitter, grid);
        if !(lambda.is_finite() && lambda > 0.0) {
            return None;
        }
        let rho = match noise_std {
            Some(s) if s.is_finite() && s > 0.0 => lambda / (s * s),
            _ => FLOOR_START_WITHOUT_LEVEL,
        };
        (rho.is_finite() && rho > 0.0).then_some(rho)
    }

    /// The structure whose noise shape is `|H|² + ρ` with the known floor `ρ` ([`WithFloor::known`],
    /// no new parameter), or the shape unchanged for `None`.
    ///
    /// # Errors
    ///
    /// [`EstimateError::Noise`] unless `ρ` is finite and `> 0`.
    pub fn with_floor(
        self,
        floor: Option<f64>,
    ) -> Result<ModelStructure<S, J, AnyNoise>, EstimateError> {
        let ModelStructure {
            signal,
            jitter,
            noise,
            estimate_signal,
            estimate_jitter,
            estimate_noise,
            noise_std,
        } = self;
        let noise = match floor {
            Some(rho) => AnyNoise::new(WithFloor::known(noise, rho)?),
            None => AnyNoise::new(noise),
        };
        Ok(ModelStructure {
            signal,
            jitter,
            noise,
            estimate_signal,
            estimate_jitter,
            estimate_noise,
            noise_std,
        })
    }

    /// The structure with the jitter's floor at [`jitter_floor_start`](Self::jitter_floor_start)
    /// (known, not estimated; unchanged when there is no floor to add).
    ///
    /// # Errors
    ///
    /// Those of [`with_floor`](Self::with_floor).
    pub fn with_jitter_floor(
        self,
        grid: &SampleGrid,
        noise_std: Option<f64>,
    ) -> Result<ModelStructure<S, J, AnyNoise>, EstimateError> {
        let start = self.jitter_floor_start(grid, noise_std);
        self.with_floor(start)
    }

    /// A Box–Jenkins or JBJ fit whose noise spectrum is the shape plus the jitter's floor, the
    /// default way to fit a coloured noise model to jittered data: `fit` (any estimator, called
    /// with a structure whose parameters are this one's) runs first with the floor's start
    /// (`noise_std` as the level guess, or the known level), then [`JITTER_FLOOR_ROUNDS`]` − 1`
    /// times more with `ρ = λ̄(θ̂) / σ̂_e²` from the previous estimate and its noise level, each
    /// started at that estimate. Without a floor to add, one fit.
    ///
    /// When the noise shape is estimated and the record has at most
    /// [`RESTRICTED_NOISE_MAX_SAMPLES`] samples, the noise shape and level of the last fit are
    /// then replaced by those of [`restricted_noise_fit`] (the exact restricted likelihood in
    /// time, with the jitter's variances `λ_k` sample by sample), which removes the
    /// frequency-domain criterion's `O(1/N)` bias of the noise parameters; their rows of the
    /// covariance become that likelihood's (uncorrelated with the others, as the Box–Jenkins
    /// information is asymptotically), and the fit counts as converged only if that minimiser
    /// converged too (its error, if any, is the termination). Returns the fit and the fitted
    /// structure (with its floor `ρ = λ̄(θ̂) / σ̂_e²`).
    ///
    /// # Errors
    ///
    /// Those of `fit` and of the structures' parameters.
    pub fn fit_with_jitter_floor<F>(
        &self,
        record: &Record,
        noise_std: Option<f64>,
        mut fit: F,
    ) -> Result<(Fit, ModelStructure<S, J, AnyNoise>), EstimateError>
    where
        F: FnMut(&ModelStructure<S, J, AnyNoise>) -> Result<Fit, EstimateError>,
    {
        let grid = record.grid();
        let guess = self.noise_std.or(noise_std);
        let mut structure = self.clone().with_jitter_floor(grid, guess)?;
        let mut estimate = fit(&structure)?;
        if structure.noise.floor() > 0.0 {
            for _ in 1..JITTER_FLOOR_ROUNDS {
                let fitted = self.with_params(&estimate.params)?;
                let level = self.noise_std.unwrap_or(estimate.noise_std);
                if !(level.is_finite() && level > 0.0) {
                    break;
                }
                let Some(rho) = fitted.jitter_floor_start(grid, Some(level)) else {
                    break;
                };
                structure = fitted.with_floor(Some(rho))?;
                estimate = fit(&structure)?;
            }
        }
        let mut fitted = structure.with_params(&estimate.params)?;
        let (ns, nj, nn) = fitted.blocks();
        if nn > 0 && grid.len() <= RESTRICTED_NOISE_MAX_SAMPLES {
            match restricted_noise_fit(&fitted, grid, record.y(), estimate.noise_std) {
                Ok(noise) => {
                    replace_noise_block(&mut estimate, ns + nj, &noise);
                    fitted = structure.with_params(&estimate.params)?;
                    let plain = self.with_params(&estimate.params)?;
                    if fitted.noise.floor() > 0.0 {
                        if let Some(rho) = plain.jitter_floor_start(grid, Some(noise.noise_std)) {
                            fitted = plain.with_floor(Some(rho))?;
                        }
                    }
                }
                Err(e) => {
                    estimate.converged = false;
                    estimate.termination =
                        Termination::Other(format!("restricted noise likelihood: {e}")).into();
                }
            }
        }
        Ok((estimate, fitted))
    }
}

/// Puts the noise shape and level of `noise` into `estimate`, whose noise block starts at
/// `first`: the parameters, the level, and the block's covariance (zero against the others).
fn replace_noise_block(estimate: &mut Fit, first: usize, noise: &NoiseEstimate) {
    let nn = noise.params.len();
    estimate.params[first..first + nn].copy_from_slice(&noise.params);
    estimate.noise_std = noise.noise_std;
    estimate.converged &= noise.converged;
    if !noise.converged {
        estimate.termination = crate::FitTermination::Solver(Termination::Other(
            "the restricted likelihood of the noise parameters did not converge".into(),
        ));
    }
    let Some(cov) = estimate.covariance.as_mut() else {
        return;
    };
    for (i, row) in cov.iter_mut().enumerate() {
        for (j, c) in row.iter_mut().enumerate() {
            let (a, b) = (i.wrapping_sub(first), j.wrapping_sub(first));
            let (in_a, in_b) = (a < nn, b < nn);
            if in_a || in_b {
                *c = match (&noise.covariance, in_a && in_b) {
                    (Some(block), true) => block[a][b],
                    (None, true) => f64::NAN,
                    _ => 0.0,
                };
            }
        }
    }
    if let Some(se) = estimate.std_errors.as_mut() {
        for (i, s) in se.iter_mut().enumerate().skip(first).take(nn) {
            *s = cov[i][i].sqrt();
        }
    }
}
