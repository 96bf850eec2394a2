//! The jitter's white floor in a Box–Jenkins noise model: the default way a coloured noise model
//! meets jittered samples.
//!
//! Jittered samples carry their own noise `E[s(t_k+τ)²] − m_k²`, independent from sample to
//! sample, so the residual spectrum of a Box–Jenkins fit is `σ_e²|H(f)|² + λ̄` (`λ̄` the mean
//! of that jitter variance over the record). An ARMA shape alone absorbs the floor and its
//! coefficients are biased towards white noise; [`WithFloor`] models `σ_e² (|H|² + ρ)` with
//! `ρ = λ̄ / σ_e²` estimated with the shape.

use crate::any_noise::AnyNoise;
use crate::noise::{NoiseModel, WithFloor};
use crate::structure::ModelStructure;
use crate::EstimateError;
use jitterid_jitter::JitterModel;
use jitterid_signal::{SampleGrid, Signal};

/// The start of the floor `ρ` when the measurement-noise level is not known.
const FLOOR_START_WITHOUT_LEVEL: f64 = 1.0;

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
    /// The start of the floor `ρ = λ̄ / σ_e²` for this structure's signal and jitter on `grid`,
    /// with `σ_e` = `noise_std` (`ρ = 1` when the level is unknown or zero). `None` when there
    /// is nothing to add: white noise (its level already absorbs a flat floor), a shape that
    /// has a floor already, or a jitter that adds no variance.
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

    /// The structure whose noise shape is `|H|² + ρ` ([`WithFloor`]), `ρ` started at
    /// [`jitter_floor_start`](Self::jitter_floor_start) and estimated with the shape (the
    /// parameter `log_floor` follows the shape's). The structure is returned with its shape
    /// unchanged when there is no floor to add. This is the noise model Box–Jenkins and JBJ
    /// fits of jittered data should use.
    ///
    /// # Errors
    ///
    /// [`EstimateError::Noise`] if the floor's start is not a valid floor (cannot happen for a
    /// finite positive start).
    pub fn with_jitter_floor(
        self,
        grid: &SampleGrid,
        noise_std: Option<f64>,
    ) -> Result<ModelStructure<S, J, AnyNoise>, EstimateError> {
        let start = self.jitter_floor_start(grid, noise_std);
        let ModelStructure {
            signal,
            jitter,
            noise,
            estimate_signal,
            estimate_jitter,
            estimate_noise,
            noise_std: known_std,
        } = self;
        let noise = match start {
            Some(rho) => AnyNoise::new(WithFloor::new(noise, rho)?),
            None => AnyNoise::new(noise),
        };
        Ok(ModelStructure {
            signal,
            jitter,
            noise,
            estimate_signal,
            estimate_jitter,
            estimate_noise,
            noise_std: known_std,
        })
    }
}
