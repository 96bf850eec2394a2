//! The exact jittered sampler: `y_k = s(t_k + τ_k) + v_k`, with `s` evaluated exactly at the
//! perturbed instants (no interpolation, no time stepping).

use crate::error::{finite, SignalError};
use crate::{SampleGrid, Signal};
use jitterid_jitter::JitterModel;
use rand::RngCore;
use rand_distr::{Distribution, Normal};

/// One simulated record, with the drawn jitter and noise kept for diagnostics.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Simulation {
    /// The requested instants `t_k`.
    pub grid: SampleGrid,
    /// The samples `y_k = s(t_k + τ_k) + v_k`.
    pub y: Vec<f64>,
    /// The jitter `τ_k` of each sample (s).
    pub tau: Vec<f64>,
    /// The measurement noise `v_k` of each sample.
    pub noise: Vec<f64>,
}

/// Draws `y_k = s(t_k + τ_k) + v_k` for every instant of `grid`, with `τ_k` iid from `jitter`
/// and `v_k ~ N(0, noise_std²)` iid, independent of the jitter.
///
/// Draw order, so that a seed reproduces a record exactly: all `N` jitter values
/// `τ_0, …, τ_{N−1}` first (by [`JitterModel::sample`]), then all `N` noise values
/// `v_0, …, v_{N−1}`. The noise is drawn even when `noise_std = 0` (it is then exactly zero),
/// so the generator advances the same way whatever the noise level.
///
/// Fails if `noise_std` is negative or not finite.
pub fn simulate<S: Signal + ?Sized>(
    signal: &S,
    jitter: &dyn JitterModel,
    grid: &SampleGrid,
    noise_std: f64,
    rng: &mut dyn RngCore,
) -> Result<Simulation, SignalError> {
    finite("noise_std", noise_std)?;
    if noise_std < 0.0 {
        // `NotPositive` is the nearest variant; zero itself is allowed.
        return Err(SignalError::NotPositive {
            name: "noise_std",
            value: noise_std,
        });
    }
    let normal = Normal::new(0.0, noise_std).map_err(|_| SignalError::NotFinite {
        name: "noise_std",
        value: noise_std,
    })?;
    let n = grid.len();
    let tau: Vec<f64> = (0..n).map(|_| jitter.sample(rng)).collect();
    let noise: Vec<f64> = (0..n).map(|_| normal.sample(rng)).collect();
    let mut y = Vec::with_capacity(n);
    for ((t, &tau), &v) in grid.times().zip(&tau).zip(&noise) {
        if let Some(stop) = jitterid_numeric::budget::stop() {
            return Err(SignalError::Stopped(stop));
        }
        y.push(signal.value(t + tau) + v);
    }
    Ok(Simulation {
        grid: *grid,
        y,
        tau,
        noise,
    })
}
