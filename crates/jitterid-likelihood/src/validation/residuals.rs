//! Standardised time-domain residuals `e_k = (y_k − m_k)/√λ_k`.

use crate::second_moments;
use jitterid_estimate::{EstimateError, ModelStructure, NoiseModel};
use jitterid_jitter::JitterModel;
use jitterid_signal::{SampleGrid, Signal};

/// The residuals of a record under a model, raw and standardised.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Residuals {
    /// `m_k = E[s(t_k + τ)]`.
    pub expected: Vec<f64>,
    /// `λ_k = σ_v² + E[s(t_k + τ)²] − m_k²`, the exact variance of sample `k`.
    pub variance: Vec<f64>,
    /// `(y_k − m_k)/√λ_k`: independent with mean 0 and variance 1 at the true model.
    pub standardized: Vec<f64>,
}

/// Standardised residuals of `y` on `grid` under `structure`, with noise level `noise_std`
/// (used when the structure does not fix one). The jitter makes the samples heteroscedastic
/// (`λ_k` is largest where the signal moves fastest); dividing by `√λ_k` leaves residuals that
/// are white with unit variance when the model is right, whatever the jitter.
///
/// Errors: `y` of another length than the grid, a non-finite sample, a bad noise level, a
/// sample whose variance `λ_k` is zero (a noiseless model where the signal does not move).
pub fn standardized_residuals<S, J, N>(
    structure: &ModelStructure<S, J, N>,
    grid: &SampleGrid,
    y: &[f64],
    noise_std: f64,
) -> Result<Residuals, EstimateError>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
{
    jitterid_estimate::support::check_samples(grid, y)?;
    let moments = second_moments(structure, grid, noise_std, false)?;
    if let Some((index, &variance)) = moments
        .variance
        .iter()
        .enumerate()
        .find(|(_, v)| !(v.is_finite() && **v > 0.0))
    {
        return Err(crate::MlError::VanishingVariance { index, variance }.into());
    }
    let standardized = y
        .iter()
        .zip(&moments.mean)
        .zip(&moments.variance)
        .map(|((y, m), l)| (y - m) / l.sqrt())
        .collect();
    Ok(Residuals {
        expected: moments.mean,
        variance: moments.variance,
        standardized,
    })
}
