//! The noise parameters of a Box–Jenkins fit by the exact restricted likelihood in time.
//!
//! The frequency-domain Box–Jenkins criterion treats the DFT bins as independent with variance
//! `σ_e²|H(f)|² + λ̄`. For the signal's parameters that is enough, but the noise shape keeps an
//! `O(1/N)` bias towards white noise that is several Monte Carlo standard errors at `N = 200`
//! with jitter (`docs/reproduction.md`, "Box–Jenkins noise floor"): the jitter's noise
//! `y_k − m_k` is white in expectation but heteroscedastic, its variance `λ_k` concentrated at
//! the input's transitions, exactly where the signal's sensitivities are, and the bins of a
//! short record are not independent.
//!
//! Here the samples' covariance is written down exactly,
//!
//! ```text
//! Σ(φ, σ_e²) = σ_e² R_H(φ) + diag(λ_k),     λ_k = E[s(t_k+τ)²] − m_k²
//! ```
//!
//! (`R_H` the autocovariance of the noise shape `|H|²`, the measurement part alone, without a
//! floor), and the noise shape `φ` and level `σ_e²` minimise the restricted (REML) Gaussian
//! likelihood of the residuals `e = y − m(θ̂)` with the mean's sensitivities `X = ∂m/∂θ`:
//!
//! ```text
//! ½ [ log det Σ + log det(XᵀΣ⁻¹X) + eᵀ(Σ⁻¹ − Σ⁻¹X(XᵀΣ⁻¹X)⁻¹XᵀΣ⁻¹)e ]
//! ```
//!
//! Every term of its score has expectation zero at the truth whatever the jitter's law (only
//! the covariance enters), and the floor is known in absolute terms (`λ_k` from the jitter
//! and signal models), so no ratio `ρ` has to be refitted. The cost is a dense Cholesky of an
//! `N × N` matrix per evaluation, so it is used up to [`RESTRICTED_NOISE_MAX_SAMPLES`]; above,
//! the frequency-domain estimate stands (its `O(1/N)` bias shrinks faster than its `1/√N`
//! spread).

use crate::noise::NoiseModel;
use crate::solver::{Bfgs, Solver};
use crate::structure::ModelStructure;
use crate::EstimateError;
use faer::linalg::solvers::{DenseSolveCore, Solve};
use faer::{Mat, Side};
use jitterid_jitter::JitterModel;
use jitterid_optim::finite_diff::{central_difference_vec, hessian, MOMENT_FD_STEP};
use jitterid_optim::Objective;
use jitterid_signal::{SampleGrid, Signal};
use num_complex::Complex64;
use rustfft::FftPlanner;

/// The longest record whose noise parameters are refined by the restricted likelihood in time
/// (one evaluation is a Cholesky of `N × N`, about `N³/3` flops).
pub const RESTRICTED_NOISE_MAX_SAMPLES: usize = 1024;

/// The noise parameters of [`restricted_noise_fit`].
#[derive(Debug, Clone, PartialEq)]
pub struct NoiseEstimate {
    /// The noise shape's parameters (in the order of [`NoiseModel::params`]).
    pub params: Vec<f64>,
    /// The measurement-noise standard deviation `σ_e` (the known one when the structure has it).
    pub noise_std: f64,
    /// The covariance of [`params`](Self::params), the inverse Hessian of the restricted
    /// likelihood (with the level profiled in); `None` if it is not positive definite.
    pub covariance: Option<Vec<Vec<f64>>>,
    /// Whether the minimiser met a convergence test.
    pub converged: bool,
}

/// The restricted likelihood of the noise parameters with the mean fixed at the structure's.
struct RestrictedNoise<'a, N> {
    noise: &'a N,
    interval: f64,
    residual: Vec<f64>,
    jitter_var: Vec<f64>,
    /// Columns `∂m/∂θ` of the estimated mean parameters.
    sens: Vec<Vec<f64>>,
    /// The level `σ_e²` when known; otherwise `ln σ_e²` is the last parameter.
    known_var: Option<f64>,
}

impl<N: NoiseModel> RestrictedNoise<'_, N> {
    fn evaluate(&self, theta: &[f64]) -> Option<f64> {
        let shape_len = self.noise.params().len();
        let noise = self.noise.with_params(&theta[..shape_len]).ok()?;
        let var = match self.known_var {
            Some(v) => v,
            None => theta[shape_len].exp(),
        };
        let n = self.residual.len();
        let r = measurement_autocovariance(&noise, self.interval, n);
        let cov = Mat::from_fn(n, n, |i, j| {
            let base = var * r[i.abs_diff(j)];
            if i == j {
                base + self.jitter_var[i]
            } else {
                base
            }
        });
        let llt = cov.llt(Side::Lower).ok()?;
        let l = llt.L();
        let log_det: f64 = (0..n).map(|i| 2.0 * l[(i, i)].ln()).sum();
        let p = self.sens.len();
        let b = Mat::from_fn(n, p + 1, |i, j| {
            if j == 0 {
                self.residual[i]
            } else {
                self.sens[j - 1][i]
            }
        });
        let s = llt.solve(&b);
        let dot = |a: usize, c: usize| (0..n).map(|i| b[(i, a)] * s[(i, c)]).sum::<f64>();
        let mut quad = dot(0, 0);
        let mut log_det_x = 0.0;
        if p > 0 {
            let gram = Mat::from_fn(p, p, |i, j| dot(i + 1, j + 1));
            let xe = Mat::from_fn(p, 1, |i, _| dot(i + 1, 0));
            let g = gram.llt(Side::Lower).ok()?;
            let gl = g.L();
            log_det_x = (0..p).map(|i| 2.0 * gl[(i, i)].ln()).sum();
            let coef = g.solve(&xe);
            quad -= (0..p).map(|i| xe[(i, 0)] * coef[(i, 0)]).sum::<f64>();
        }
        let cost = 0.5 * (log_det + log_det_x + quad);
        cost.is_finite().then_some(cost)
    }
}

impl<N: NoiseModel> Objective for RestrictedNoise<'_, N> {
    fn num_params(&self) -> usize {
        self.noise.params().len() + usize::from(self.known_var.is_none())
    }
    fn cost(&self, theta: &[f64]) -> f64 {
        self.evaluate(theta).unwrap_or(f64::INFINITY)
    }
}

/// The autocovariance `r(l)`, `l = 0..n`, of unit-variance white noise through the
/// measurement part of the shape (`|H|²` less its floor, which is the jitter's and already in
/// `λ_k`), from `M` samples of the spectrum by one FFT: `M` the power of two at least
/// `max(16n, 4096)`, the same spectral sampling as
/// `jitterid_likelihood::noise_autocovariance` (aliasing error of order
/// `r(M − l)`) in `O(M log M)` instead of `O(M n)`.
pub fn measurement_autocovariance<N: NoiseModel>(noise: &N, interval: f64, n: usize) -> Vec<f64> {
    let m = (16 * n).max(4096).next_power_of_two();
    let floor = noise.floor();
    let mut z: Vec<Complex64> = (0..m)
        .map(|j| {
            let f = j as f64 / (m as f64 * interval);
            Complex64::new((noise.shape(f, interval) - floor) / m as f64, 0.0)
        })
        .collect();
    FftPlanner::<f64>::new().plan_fft_forward(m).process(&mut z);
    z.iter().take(n).map(|v| v.re).collect()
}

/// `∂m/∂θ` of the structure's estimated mean parameters: the signal's analytically, the
/// jitter's by central differences.
fn mean_sensitivities<S, J, N>(
    structure: &ModelStructure<S, J, N>,
    grid: &SampleGrid,
) -> Vec<Vec<f64>>
where
    S: Signal,
    J: JitterModel + Clone,
    N: NoiseModel,
{
    let mut cols = Vec::new();
    if structure.estimate_signal {
        cols.extend(
            structure
                .signal
                .expected_values_gradient(grid, &structure.jitter),
        );
    }
    if structure.estimate_jitter {
        let theta = structure.jitter.params();
        let m = |p: &[f64]| {
            let j = structure.jitter.with_params(p).ok()?;
            Some(structure.signal.expected_values(grid, &j))
        };
        for j in 0..theta.len() {
            if let Some(c) = central_difference_vec(&theta, j, MOMENT_FD_STEP, m) {
                cols.push(c);
            }
        }
    }
    cols
}

/// The noise shape's parameters and level of `structure` (at its current parameters, the mean
/// `m(θ̂)` fixed) by the restricted likelihood of the module docs, started at the structure's
/// noise parameters and at `noise_std` (the structure's known level if it has one). `grid` and
/// `y` are the record's.
///
/// # Errors
///
/// [`EstimateError::Noise`] when the covariance at the start is not positive definite or the
/// record is longer than [`RESTRICTED_NOISE_MAX_SAMPLES`]; the minimiser's errors.
pub fn restricted_noise_fit<S, J, N>(
    structure: &ModelStructure<S, J, N>,
    grid: &SampleGrid,
    y: &[f64],
    noise_std: f64,
) -> Result<NoiseEstimate, EstimateError>
where
    S: Signal,
    J: JitterModel + Clone,
    N: NoiseModel,
{
    let n = grid.len();
    if n > RESTRICTED_NOISE_MAX_SAMPLES {
        return Err(EstimateError::Noise(format!(
            "the restricted likelihood in time takes at most {RESTRICTED_NOISE_MAX_SAMPLES} samples, the record has {n}"
        )));
    }
    let m = structure.signal.expected_values(grid, &structure.jitter);
    let sq = structure.signal.expected_squares(grid, &structure.jitter);
    let jitter_var = sq
        .iter()
        .zip(&m)
        .map(|(s, m)| (s - m * m).max(0.0))
        .collect();
    let residual = y.iter().zip(&m).map(|(y, m)| y - m).collect();
    let known_var = structure.noise_std.map(|s| s * s);
    let problem = RestrictedNoise {
        noise: &structure.noise,
        interval: grid.interval(),
        residual,
        jitter_var,
        sens: mean_sensitivities(structure, grid),
        known_var,
    };
    let mut start = structure.noise.params();
    if known_var.is_none() {
        start.push((noise_std * noise_std).ln());
    }
    if !problem.cost(&start).is_finite() {
        return Err(EstimateError::Noise(format!(
            "the restricted likelihood of the noise is not defined at its start {start:?}"
        )));
    }
    let report = Bfgs::default().minimize(&problem, &start)?;
    let shape_len = structure.noise.params().len();
    let covariance = hessian(&problem, &report.params)
        .and_then(|h| h.llt(Side::Lower).ok().map(|l| l.inverse()))
        .map(|inv| {
            (0..shape_len)
                .map(|i| (0..shape_len).map(|j| inv[(i, j)]).collect())
                .collect::<Vec<Vec<f64>>>()
        })
        .filter(|c: &Vec<Vec<f64>>| (0..shape_len).all(|i| c[i][i].is_finite() && c[i][i] > 0.0));
    let noise_std = match known_var {
        Some(v) => v.sqrt(),
        None => (0.5 * report.params[shape_len]).exp(),
    };
    Ok(NoiseEstimate {
        params: report.params[..shape_len].to_vec(),
        noise_std,
        covariance,
        converged: report.converged,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::noise::ArmaNoise;
    use rand::{Rng, SeedableRng};

    const PHI: f64 = 0.6;
    const N: usize = 60;

    /// Stationary AR(1) noise plus heteroscedastic white noise, and the white noise's variances.
    fn record() -> (Vec<f64>, Vec<f64>) {
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        let lambda: Vec<f64> = (0..N)
            .map(|k| {
                if k % 9 == 4 {
                    4e-4
                } else {
                    1e-6 * (k % 3) as f64
                }
            })
            .collect();
        let mut x = rng.random_range(-1.0..1.0) * 0.0125;
        let y = lambda
            .iter()
            .map(|l| {
                x = PHI * x + 0.01 * rng.random_range(-1.7..1.7);
                x + l.sqrt() * rng.random_range(-1.7..1.7)
            })
            .collect();
        (y, lambda)
    }

    /// `½ Σ [ln S_k + ν_k² / S_k]` of the Kalman filter of `x_k = φ x_{k−1} + e_k`,
    /// `y_k = x_k + w_k`, `Var w_k = λ_k`, started stationary: the exact likelihood by a route
    /// that never forms `Σ`.
    fn kalman(y: &[f64], lambda: &[f64], var: f64) -> f64 {
        let (mut x, mut p) = (0.0, var / (1.0 - PHI * PHI));
        let mut cost = 0.0;
        for (k, (&y, &l)) in y.iter().zip(lambda).enumerate() {
            if k > 0 {
                x *= PHI;
                p = PHI * PHI * p + var;
            }
            let s = p + l;
            let nu = y - x;
            cost += 0.5 * (s.ln() + nu * nu / s);
            let gain = p / s;
            x += gain * nu;
            p *= 1.0 - gain;
        }
        cost
    }

    // The FFT autocovariance against the likelihood layer's direct sums is tested in
    // jitterid-likelihood (tests/restricted_noise.rs), which sees both.

    #[test]
    fn without_a_mean_the_cost_is_the_kalman_filters_exact_likelihood() {
        let (y, lambda) = record();
        let noise = ArmaNoise::new(vec![], vec![-PHI]).unwrap();
        let problem = RestrictedNoise {
            noise: &noise,
            interval: 1.0,
            residual: y.clone(),
            jitter_var: lambda.clone(),
            sens: Vec::new(),
            known_var: None,
        };
        for var in [1e-4_f64, 3e-4] {
            let cost = problem.cost(&[-PHI, var.ln()]);
            let want = kalman(&y, &lambda, var);
            assert!((cost - want).abs() <= 1e-9 * want.abs(), "{cost} vs {want}");
        }
    }

    #[test]
    fn with_a_mean_the_cost_is_the_likelihood_of_the_error_contrasts() {
        let (y, lambda) = record();
        let x: Vec<f64> = (0..N).map(|k| (0.3 * k as f64).sin() + 0.5).collect();
        let noise = ArmaNoise::new(vec![], vec![-PHI]).unwrap();
        let var = 2e-4;
        let problem = RestrictedNoise {
            noise: &noise,
            interval: 1.0,
            residual: y.clone(),
            jitter_var: lambda.clone(),
            sens: vec![x.clone()],
            known_var: Some(var),
        };
        let cost = problem.cost(&[-PHI]);
        // The contrasts `Aᵀy`, `A` the orthonormal complement of `x` from the Householder
        // reflection `Q = I − 2uuᵀ/uᵀu` that maps `x` to `−|x| e₁`: 2·cost =
        // log det(AᵀΣA) + (Aᵀy)ᵀ(AᵀΣA)⁻¹(Aᵀy) + log(xᵀx).
        let norm = x.iter().map(|v| v * v).sum::<f64>().sqrt();
        let mut u = x.clone();
        u[0] += norm;
        let uu: f64 = u.iter().map(|v| v * v).sum();
        let q = Mat::from_fn(N, N, |i, j| {
            f64::from(u8::from(i == j)) - 2.0 * u[i] * u[j] / uu
        });
        let sigma = Mat::from_fn(N, N, |i, j| {
            let r = PHI.powi(i.abs_diff(j) as i32) / (1.0 - PHI * PHI);
            var * r + if i == j { lambda[i] } else { 0.0 }
        });
        let qsq = &q * &sigma * &q;
        let m = N - 1;
        let inner = Mat::from_fn(m, m, |i, j| qsq[(i + 1, j + 1)]);
        let qy: Vec<f64> = (0..N)
            .map(|i| (0..N).map(|j| q[(i, j)] * y[j]).sum())
            .collect();
        let c = Mat::from_fn(m, 1, |i, _| qy[i + 1]);
        let llt = inner.llt(Side::Lower).unwrap();
        let l = llt.L();
        let log_det: f64 = (0..m).map(|i| 2.0 * l[(i, i)].ln()).sum();
        let s = llt.solve(&c);
        let quad: f64 = (0..m).map(|i| c[(i, 0)] * s[(i, 0)]).sum();
        let want = 0.5 * (log_det + quad + (norm * norm).ln());
        assert!((cost - want).abs() <= 1e-8 * want.abs(), "{cost} vs {want}");
    }
}
