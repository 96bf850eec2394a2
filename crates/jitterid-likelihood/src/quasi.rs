//! The Gaussian quasi-likelihood of the first two moments.
//!
//! With white measurement noise the samples are independent with mean `m_k` and variance
//! `λ_k = σ_v² + E[s(t_k+τ)²] − m_k²`, and the criterion is
//!
//! ```text
//! V(θ) = ½ Σ_k [ ln(2π λ_k) + (y_k − m_k)² / λ_k ]
//! ```
//!
//! (equivalently, by the unitarity of the DFT, the Gaussian likelihood of the residual DTFT on
//! the full DFT grid with the covariance of [`dtft_covariance`](super::dtft_covariance)).
//! Unlike the first-moment criteria it sees the jitter where it is strongest: in the variance,
//! which is large exactly where the signal moves fast.
//!
//! With coloured (Box–Jenkins) noise `v = H(q) e`, `e ~ N(0, σ_v²)`, the jittered samples are
//! still independent of the noise, and the Gaussian approximation has the covariance
//! `Σ = diag(E[s²] − m²) + σ_v² R`, with `R` the autocovariance of `H` (from its spectrum
//! `|H(f)|²` by a dense inverse DFT); then `V = ½ [ln det(2πΣ) + eᵀ Σ⁻¹ e]`, by Cholesky.

use super::criterion::{Evaluation, GradientRequest, LikelihoodCriterion, LikelihoodData};
use super::moments::expected_squares_gradient;
use super::MlError;
use faer::linalg::solvers::DenseSolveCore;
use faer::{Mat, Side};
use jitterid_estimate::ModelStructure;
use jitterid_estimate::NoiseModel;
use jitterid_jitter::JitterModel;
use jitterid_signal::{SampleGrid, Signal};
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

/// `ln 2π`.
const LN_2PI: f64 = 1.837_877_066_409_345_5;

/// The Gaussian quasi-maximum-likelihood criterion (see the module docs).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct QuasiMl;

/// The autocovariance `r(l) = ∫ |H(f)|² e^{i2πflT} T df`, `l = 0..n`, of unit-variance white
/// noise filtered by the shape, from `M ≥ 16n` samples of the spectrum (aliasing error of
/// order `r(M − l)`).
pub fn noise_autocovariance<N: NoiseModel>(noise: &N, interval: f64, n: usize) -> Vec<f64> {
    let m = (16 * n).max(4096);
    let mut r = vec![0.0; n];
    for j in 0..m {
        let f = j as f64 / (m as f64 * interval);
        let s = noise.shape(f, interval) / m as f64;
        // cos(2π j l / m) by rotation, re-anchored every 64 lags.
        let step = TAU * j as f64 / m as f64;
        let rot = num_complex::Complex64::from_polar(1.0, step);
        let mut z = num_complex::Complex64::new(1.0, 0.0);
        for (l, rl) in r.iter_mut().enumerate() {
            if l % 64 == 0 {
                let ang = TAU * ((j as f64 * l as f64 / m as f64).fract());
                z = num_complex::Complex64::from_polar(1.0, ang);
            }
            *rl += s * z.re;
            z *= rot;
        }
    }
    r
}

/// `(m, E[s²] − m², ∂m, ∂(E[s²] − m²))` with the signal gradients when asked.
type Moments = (Vec<f64>, Vec<f64>, Option<(Vec<Vec<f64>>, Vec<Vec<f64>>)>);

fn moments<S: Signal + Clone, J: JitterModel>(
    signal: &S,
    jitter: &J,
    grid: &SampleGrid,
    gradient: bool,
) -> Moments {
    let m = signal.expected_values(grid, jitter);
    let sq = signal.expected_squares(grid, jitter);
    let jv: Vec<f64> = sq
        .iter()
        .zip(&m)
        .map(|(s, m)| (s - m * m).max(0.0))
        .collect();
    let grads = gradient.then(|| {
        let gm = signal.expected_values_gradient(grid, jitter);
        let gs = expected_squares_gradient(signal, grid, jitter);
        let gv: Vec<Vec<f64>> = gm
            .iter()
            .zip(&gs)
            .map(|(cm, cs)| {
                cm.iter()
                    .zip(cs)
                    .zip(&m)
                    .map(|((dm, ds), m)| ds - 2.0 * m * dm)
                    .collect()
            })
            .collect();
        (gm, gv)
    });
    (m, jv, grads)
}

impl LikelihoodCriterion for QuasiMl {
    fn name(&self) -> &'static str {
        "quasi-ml"
    }

    fn supports_coloured_noise(&self) -> bool {
        true
    }

    fn evaluate<S: Signal + Clone, J: JitterModel + Clone, N: NoiseModel>(
        &self,
        data: &LikelihoodData,
        model: &ModelStructure<S, J, N>,
        noise_std: f64,
        gradient: GradientRequest,
    ) -> Result<Evaluation, MlError> {
        let sigma = model.noise_std.unwrap_or(noise_std);
        if !(sigma.is_finite() && sigma >= 0.0) {
            return Err(jitterid_estimate::EstimateError::BadNoiseStd { value: sigma }.into());
        }
        let record = &data.record;
        super::criterion::check_reach(&model.jitter, record.grid())?;
        let grid = record.grid();
        let (m, jv, grads) = moments(&model.signal, &model.jitter, grid, gradient.signal);
        let y = record.y();
        if model.noise.is_white() {
            let mut nll = 0.0;
            let ns = model.signal.num_params();
            let mut gs = vec![0.0; if gradient.signal { ns } else { 0 }];
            let mut gsig = 0.0;
            for k in 0..y.len() {
                let lambda = jv[k] + sigma * sigma;
                if !(lambda > 0.0 && lambda.is_finite()) {
                    return Err(MlError::VanishingVariance {
                        index: k,
                        variance: lambda,
                    });
                }
                let e = y[k] - m[k];
                nll += 0.5 * (LN_2PI + lambda.ln() + e * e / lambda);
                // ∂V/∂λ and ∂V/∂m.
                let dl = 0.5 * (1.0 / lambda - e * e / (lambda * lambda));
                let dm = -e / lambda;
                if let Some((gm, gv)) = &grads {
                    for j in 0..ns {
                        gs[j] += dl * gv[j][k] + dm * gm[j][k];
                    }
                }
                gsig += dl * 2.0 * sigma;
            }
            if !nll.is_finite() {
                return Err(MlError::NonFinite {
                    what: "quasi-likelihood of record",
                    index: 0,
                    value: nll,
                });
            }
            return Ok(Evaluation {
                nll,
                signal_gradient: gradient.signal.then_some(gs),
                noise_std_gradient: gradient.noise_std.then_some(gsig),
            });
        }
        coloured(y, &m, &jv, grads.as_ref(), model, grid, sigma, gradient)
    }
}

#[allow(clippy::too_many_arguments)]
fn coloured<S: Signal + Clone, J: JitterModel + Clone, N: NoiseModel>(
    y: &[f64],
    m: &[f64],
    jv: &[f64],
    grads: Option<&(Vec<Vec<f64>>, Vec<Vec<f64>>)>,
    model: &ModelStructure<S, J, N>,
    grid: &SampleGrid,
    sigma: f64,
    gradient: GradientRequest,
) -> Result<Evaluation, MlError> {
    let n = y.len();
    let r = noise_autocovariance(&model.noise, grid.interval(), n);
    let s2 = sigma * sigma;
    let cov = Mat::from_fn(n, n, |i, j| {
        let base = s2 * r[i.abs_diff(j)];
        if i == j {
            base + jv[i]
        } else {
            base
        }
    });
    let Ok(llt) = cov.llt(Side::Lower) else {
        return Err(MlError::VanishingVariance {
            index: 0,
            variance: s2 * r[0] + jv[0],
        });
    };
    let l = llt.L();
    let mut logdet = 0.0;
    for i in 0..n {
        logdet += 2.0 * l[(i, i)].ln();
    }
    let e = Mat::from_fn(n, 1, |i, _| y[i] - m[i]);
    let alpha = faer::linalg::solvers::Solve::solve(&llt, &e);
    let quad: f64 = (0..n).map(|i| e[(i, 0)] * alpha[(i, 0)]).sum();
    let nll = 0.5 * (n as f64 * LN_2PI + logdet + quad);
    if !nll.is_finite() {
        return Err(MlError::NonFinite {
            what: "quasi-likelihood of record",
            index: 0,
            value: nll,
        });
    }
    let want = gradient.signal || gradient.noise_std;
    let (mut gs, mut gsig) = (Vec::new(), 0.0);
    if want {
        let inv = llt.inverse();
        if let Some((gm, gv)) = grads.filter(|_| gradient.signal) {
            gs = gm
                .iter()
                .zip(gv)
                .map(|(cm, cv)| {
                    (0..n)
                        .map(|k| {
                            let a = alpha[(k, 0)];
                            0.5 * (inv[(k, k)] - a * a) * cv[k] - cm[k] * a
                        })
                        .sum()
                })
                .collect();
        }
        if gradient.noise_std {
            // ∂Σ = 2σ R: σ (tr(Σ⁻¹R) − αᵀRα).
            let mut tr = 0.0;
            let mut ara = 0.0;
            for i in 0..n {
                for j in 0..n {
                    let rij = r[i.abs_diff(j)];
                    tr += inv[(i, j)] * rij;
                    ara += alpha[(i, 0)] * rij * alpha[(j, 0)];
                }
            }
            gsig = sigma * (tr - ara);
        }
    }
    Ok(Evaluation {
        nll,
        signal_gradient: gradient.signal.then_some(gs),
        noise_std_gradient: gradient.noise_std.then_some(gsig),
    })
}
