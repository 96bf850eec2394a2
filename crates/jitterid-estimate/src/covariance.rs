//! The asymptotic covariance of a frequency-domain least-squares estimate, in sandwich form.
//!
//! With `r = √W A d`, where `d_k = y_k − m_k` are the independent sample deviations and `A` maps
//! them to `[Re D(f), Im D(f)]`, the estimate's covariance is
//! `H⁻¹ (Jᵀ Σ_r J) H⁻¹` with `H = JᵀJ` and `Σ_r = √W A Λ Aᵀ √W`. Jittered samples are
//! heteroscedastic: `Λ = diag(λ_k)`, `λ_k = σ_v² + E[s(t_k+τ)²] − m_k²` (`docs/method.md`),
//! so the simple `σ² H⁻¹` would be wrong. For coloured (Box–Jenkins) noise, its part of `Σ_r`
//! is the asymptotic diagonal `N Φ_v(f)/2` per real and imaginary part.

use crate::criterion::Criterion;
use crate::frequency_data::FrequencyData;
use crate::noise::NoiseModel;
use crate::parseval::{edge_bins, moment_sensitivities, parseval_gram, parseval_weight};
use crate::structure::ModelStructure;
use faer::linalg::solvers::DenseSolveCore;
use faer::{Mat, Side};
use jitterid_jitter::JitterModel;
use jitterid_signal::Signal;
use jitterid_window::Window;
use num_complex::Complex64;
use std::f64::consts::TAU;

/// The sandwich covariance and the noise standard deviation it used (known, or estimated by
/// moments from the residuals). `None` when `JᵀJ` is singular or not finite.
///
/// In the Parseval case ([`parseval_weight`]) with white noise, `JᵀJ` and the meat are sums over
/// samples of the time-domain sensitivities and the Jacobian is never formed; otherwise the
/// explicit Jacobian is mapped back to time.
///
/// Parameters in `held` (on the boundary of their domain, see [`crate::boundary`]) get zero
/// rows and columns; the others their covariance conditional on the held ones. `known` are the
/// time-domain sensitivities at `model`, when already computed.
pub(crate) fn sandwich<S, J, N, C, W>(
    data: &FrequencyData<W>,
    model: &ModelStructure<S, J, N>,
    criterion: &C,
    held: &[usize],
    known: Option<Vec<Vec<f64>>>,
) -> (Option<Vec<Vec<f64>>>, f64)
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: Criterion + ?Sized,
    W: Window,
{
    let (gram, meat, noise_var) = sandwich_parts(data, model, criterion, known);
    sandwich_of(&gram, &meat, held, noise_var)
}

/// The sandwich covariance of a first-moment criterion's estimate taken to be `model` (its
/// parameters, nothing held), on `data`: what a fit that stopped at `model` would report,
/// without the search. Experiment design evaluates it at a prior model on the expected
/// (noise-free) record of a planned experiment; give `model` its noise level
/// (`with_noise_std`), since noise-free data hold none to estimate. `None` when `JᵀJ` is
/// singular, badly conditioned or not finite.
pub fn sandwich_covariance<S, J, N, C, W>(
    data: &FrequencyData<W>,
    model: &ModelStructure<S, J, N>,
    criterion: &C,
) -> Option<Vec<Vec<f64>>>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: Criterion + ?Sized,
    W: Window,
{
    sandwich(data, model, criterion, &[], None).0
}

/// The bread `JᵀJ`, the meat `Jᵀ Σ_r J` and the noise variance of one record's sandwich: the
/// parts that sum over the records of a joint fit. `known` are the time-domain sensitivities at
/// `model`, when already computed.
pub(crate) fn sandwich_parts<S, J, N, C, W>(
    data: &FrequencyData<W>,
    model: &ModelStructure<S, J, N>,
    criterion: &C,
    known: Option<Vec<Vec<f64>>>,
) -> (Mat<f64>, Mat<f64>, f64)
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: Criterion + ?Sized,
    W: Window,
{
    let (jitter_var, noise_var) = sample_variances(data, model);
    let white = model.noise.is_white();
    let (gram, meat) = match parseval_weight(criterion, data, model) {
        Some(weight) if white => {
            let cols = known.unwrap_or_else(|| moment_sensitivities(criterion, data, model));
            let meat = time_domain_meat(&cols, weight, &jitter_var, noise_var);
            (parseval_gram(&cols, weight), meat)
        }
        _ => {
            let jac = data.jacobian(criterion, model);
            let meat = projected_meat(data, model, criterion, &jac, &jitter_var, noise_var);
            (crate::solver::gram(&jac), meat)
        }
    };
    (gram, meat, noise_var)
}

/// `H⁻¹ M H⁻¹` from the bread `H` and the meat `M`, with the `held` parameters' rows and
/// columns zero, and `σ_v`.
pub(crate) fn sandwich_of(
    gram: &Mat<f64>,
    meat: &Mat<f64>,
    held: &[usize],
    noise_var: f64,
) -> (Option<Vec<Vec<f64>>>, f64) {
    let p = gram.nrows();
    let free: Vec<usize> = (0..p).filter(|i| !held.contains(i)).collect();
    let block = |m: &Mat<f64>| Mat::from_fn(free.len(), free.len(), |a, b| m[(free[a], free[b])]);
    let Some(hinv) = inverse_gram(&block(gram)) else {
        return (None, noise_var.sqrt());
    };
    let cov = &hinv * &block(meat) * &hinv;
    let mut out = vec![vec![0.0; p]; p];
    for (a, &i) in free.iter().enumerate() {
        for (b, &j) in free.iter().enumerate() {
            out[i][j] = cov[(a, b)];
        }
    }
    let finite = out.iter().flatten().all(|v| v.is_finite());
    (finite.then_some(out), noise_var.sqrt())
}

/// The jitter part of each sample's variance, `E[s(t_k+τ)²] − m_k²`, and the measurement-noise
/// variance (known, or estimated by moments from the residuals).
fn sample_variances<S, J, N, W>(
    data: &FrequencyData<W>,
    model: &ModelStructure<S, J, N>,
) -> (Vec<f64>, f64)
where
    S: Signal,
    J: JitterModel,
    N: NoiseModel,
    W: Window,
{
    let record = data.record();
    let grid = record.grid();
    let n = grid.len();
    // The data's true variance always involves the jitter, whatever the criterion models.
    let m = model.signal.expected_values(grid, &model.jitter);
    let mut jitter_var = model.signal.expected_squares(grid, &model.jitter);
    jitter_var
        .iter_mut()
        .zip(&m)
        .for_each(|(s, m)| *s = (*s - m * m).max(0.0));
    let mean_jitter_var = jitter_var.iter().sum::<f64>() / n as f64;
    let freqs = data.frequencies();
    let t = grid.interval();
    let noise_var = match model.noise_std {
        Some(s) => s * s,
        None if model.noise.is_white() => {
            let mse = record
                .y()
                .iter()
                .zip(&m)
                .map(|(y, m)| (y - m).powi(2))
                .sum::<f64>()
                / n as f64;
            (mse - mean_jitter_var).max(0.0)
        }
        None => {
            let mu = data.transform_moment(&m);
            let power: Vec<f64> = data
                .dtft()
                .iter()
                .zip(&mu)
                .map(|(y, mu)| (y - mu).norm_sqr() / n as f64)
                .collect();
            let shape: Vec<f64> = freqs
                .frequencies()
                .iter()
                .map(|&f| measurement_shape(&model.noise, f, t))
                .collect();
            // The signal's fit takes `p` of the `M` real residuals' power (REML's `M − p`,
            // as in the Box–Jenkins criterion).
            let residuals = 2 * power.len();
            let p = if model.estimate_signal {
                model.signal.num_params()
            } else {
                0
            };
            let power: Vec<f64> = if p < residuals {
                let scale = residuals as f64 / (residuals - p) as f64;
                power.iter().map(|q| q * scale).collect()
            } else {
                power
            };
            coloured_noise_variance(&power, &shape, mean_jitter_var)
        }
    };
    (jitter_var, noise_var)
}

/// Rounds of [`coloured_noise_variance`]'s reweighting: each multiplies the distance to the
/// root by about `λ̄ / (σ²|H|² + λ̄)` at worst, so a few suffice; the loop stops earlier once
/// the estimate settles.
const NOISE_VARIANCE_ROUNDS: usize = 50;

/// `σ_e²` from the residual powers `P_f = |D(f)|²/N`, whose expectation is `σ_e²|H_f|² + λ̄`
/// (`λ̄` the jitter's mean sample variance, a flat floor): the root of the Whittle score
/// `Σ_f (P_f − Φ_f) |H_f|² / Φ_f² = 0`, `Φ_f = σ_e²|H_f|² + λ̄`, by iterated weighted least
/// squares. Every term has expectation zero at the truth, so the estimate is consistent; a
/// per-frequency `max(P_f − λ̄, 0)` would not be (it is biased up wherever the floor dominates).
/// Without a floor the root is `mean_f P_f / |H_f|²`. Clamped at 0 (residuals with less power
/// than the floor alone).
fn coloured_noise_variance(power: &[f64], shape: &[f64], floor: f64) -> f64 {
    let bins = power.len().max(1) as f64;
    let plain = power.iter().zip(shape).map(|(p, h)| p / h).sum::<f64>() / bins;
    if !(floor.is_finite() && floor > 0.0) {
        return plain;
    }
    // Start where the floor's expected share is taken out of every bin.
    let mut var = (plain - floor * shape.iter().map(|h| 1.0 / h).sum::<f64>() / bins).max(0.0);
    for _ in 0..NOISE_VARIANCE_ROUNDS {
        let (mut num, mut den) = (0.0, 0.0);
        for (&p, &h) in power.iter().zip(shape) {
            let phi = var * h + floor;
            let w = h / (phi * phi);
            num += w * (p - floor);
            den += w * h;
        }
        let next = (num / den).max(0.0);
        if !next.is_finite() {
            break;
        }
        let settled = (next - var).abs() <= 1e-12 * next.max(f64::MIN_POSITIVE);
        var = next;
        if settled {
            break;
        }
    }
    var
}

/// The measurement noise's own shape `|H(f)|²`: a jitter floor in the noise model is already in
/// the samples' jitter variances.
fn measurement_shape<N: NoiseModel>(noise: &N, f: f64, t: f64) -> f64 {
    noise.shape(f, t) - noise.floor()
}

/// `Jᵀ Σ_r J` for white noise in the Parseval case, accumulated sample by sample: the row of
/// `G = Aᵀ√W J` at sample `k` is `−w (N a_k + S(a) + [N even] (−1)^k Alt(a)) / 2` for each
/// sensitivity `a` (the real part of the half-grid inverse transform, as in
/// [`parseval`](crate::parseval)).
fn time_domain_meat(
    cols: &[Vec<f64>],
    weight: f64,
    jitter_var: &[f64],
    noise_var: f64,
) -> Mat<f64> {
    let p = cols.len();
    let n = jitter_var.len();
    let edges: Vec<(f64, f64)> = cols.iter().map(|c| edge_bins(c)).collect();
    let even = n % 2 == 0;
    let mut meat = Mat::<f64>::zeros(p, p);
    let mut gk = vec![0.0; p];
    for (k, &jv) in jitter_var.iter().enumerate() {
        let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
        for (a, g) in gk.iter_mut().enumerate() {
            let nyquist = if even { sign * edges[a].1 } else { 0.0 };
            *g = -0.5 * weight * (n as f64 * cols[a][k] + edges[a].0 + nyquist);
        }
        let lambda = jv + noise_var;
        for a in 0..p {
            for b in 0..p {
                meat[(a, b)] += lambda * gk[a] * gk[b];
            }
        }
    }
    meat
}

/// `Jᵀ Σ_r J` from the explicit Jacobian, mapped back to time (any window, frequency set and
/// weights; coloured noise adds its asymptotic diagonal per frequency).
fn projected_meat<S, J, N, C, W>(
    data: &FrequencyData<W>,
    model: &ModelStructure<S, J, N>,
    criterion: &C,
    jac: &Mat<f64>,
    jitter_var: &[f64],
    noise_var: f64,
) -> Mat<f64>
where
    S: Signal,
    J: JitterModel,
    N: NoiseModel,
    C: Criterion + ?Sized,
    W: Window,
{
    let grid = data.record().grid();
    let n = grid.len();
    let p = jac.ncols();
    let freqs = data.frequencies();
    let t = grid.interval();
    let white = model.noise.is_white();
    let w = data.weights(criterion, model, None);
    let taper = data.window().weights(n);

    let g = project_to_time(jac, freqs, &w, n, t);
    let mut meat = Mat::<f64>::zeros(p, p);
    for (k, gk) in g.chunks_exact(p.max(1)).enumerate().take(n) {
        let ck = taper[k];
        let lambda = jitter_var[k] + if white { noise_var } else { 0.0 };
        for a in 0..p {
            for b in 0..p {
                meat[(a, b)] += lambda * ck * ck * gk[a] * gk[b];
            }
        }
    }
    if !white {
        let nyquist = 0.5 / t;
        let energy: f64 = taper.iter().map(|c| c * c).sum();
        for (fi, &f) in freqs.frequencies().iter().enumerate() {
            let phi = noise_var * measurement_shape(&model.noise, f, t) * energy;
            let edge = f == 0.0 || (f - nyquist).abs() < 1e-12 * nyquist;
            let (vre, vim) = if edge {
                (phi, 0.0)
            } else {
                (phi / 2.0, phi / 2.0)
            };
            // Var r = w_f · Var(Re V), w_f · Var(Im V): the rows of J already carry √w_f.
            for a in 0..p {
                for b in 0..p {
                    meat[(a, b)] += w[fi]
                        * (vre * jac[(2 * fi, a)] * jac[(2 * fi, b)]
                            + vim * jac[(2 * fi + 1, a)] * jac[(2 * fi + 1, b)]);
                }
            }
        }
    }
    meat
}

/// Largest 1-norm condition number of a symmetric positive definite matrix (`JᵀJ` here, the
/// likelihood's Hessian or Fisher matrix in `ml`) scaled to unit diagonal that counts as
/// invertible:
/// beyond it the inverse has fewer than about four correct digits, and a parameter combination
/// that the data do not determine (an exactly singular `JᵀJ` perturbed by rounding) would
/// otherwise get a small, meaningless standard error.
const MAX_CONDITION: f64 = 1e12;

/// `H⁻¹` for a symmetric positive definite `H` (here `JᵀJ`), through the unit-diagonal scaling
/// `D^{-1/2} H D^{-1/2}` (which removes the
/// parameters' units from the conditioning), or `None` if it is singular, not finite or worse
/// conditioned than `MAX_CONDITION`.
pub fn inverse_gram(h: &Mat<f64>) -> Option<Mat<f64>> {
    let p = h.nrows();
    let mut scale = Vec::with_capacity(p);
    for i in 0..p {
        let d = h[(i, i)];
        if !(d.is_finite() && d > 0.0) {
            return None;
        }
        scale.push(1.0 / d.sqrt());
    }
    let scaled = Mat::from_fn(p, p, |i, j| h[(i, j)] * scale[i] * scale[j]);
    let inv = scaled.llt(Side::Lower).ok()?.inverse();
    let norm1 = |m: &Mat<f64>| {
        (0..p)
            .map(|j| (0..p).map(|i| m[(i, j)].abs()).sum::<f64>())
            .fold(0.0, f64::max)
    };
    let condition = norm1(&scaled) * norm1(&inv);
    (condition.is_finite() && condition <= MAX_CONDITION)
        .then(|| Mat::from_fn(p, p, |i, j| inv[(i, j)] * scale[i] * scale[j]))
}

/// `G = Aᵀ√W·J` without the taper `c_k` (applied by the caller), row-major `N × p`:
/// `G[k][j] = Σ_f √w_f Re((J[2f,j] + i J[2f+1,j]) e^{i2π f kT})`.
///
/// On the DFT grid this is one inverse FFT per parameter, `O(p N log N)`; elsewhere a direct sum
/// with a rotation recurrence re-anchored every 128 samples, `O(p N F)`.
fn project_to_time(
    jac: &Mat<f64>,
    freqs: &jitterid_window::FrequencySet,
    w: &[f64],
    n: usize,
    t: f64,
) -> Vec<f64> {
    let p = jac.ncols();
    let mut g = vec![0.0; n * p];
    if let Some(bins) = freqs.dft_indices() {
        let fft = rustfft::FftPlanner::<f64>::new().plan_fft_inverse(n);
        let mut z = vec![Complex64::new(0.0, 0.0); n];
        for j in 0..p {
            z.iter_mut().for_each(|v| *v = Complex64::new(0.0, 0.0));
            for (fi, &b) in bins.iter().enumerate() {
                z[b] += w[fi].sqrt() * Complex64::new(jac[(2 * fi, j)], jac[(2 * fi + 1, j)]);
            }
            fft.process(&mut z);
            for (k, v) in z.iter().enumerate() {
                g[k * p + j] = v.re;
            }
        }
        return g;
    }
    for (fi, &f) in freqs.frequencies().iter().enumerate() {
        // `O(N)` per frequency: a spent budget leaves the projection (and so the covariance,
        // which the fit then drops) unfinished.
        if jitterid_numeric::budget::spent() {
            g.iter_mut().for_each(|v| *v = f64::NAN);
            break;
        }
        let sw = w[fi].sqrt();
        let step = Complex64::from_polar(1.0, TAU * f * t);
        let mut rot = Complex64::new(1.0, 0.0);
        for k in 0..n {
            if k % 128 == 0 {
                // Re-anchor the rotation so rounding does not accumulate over long records.
                rot = Complex64::from_polar(1.0, TAU * ((f * t * k as f64).fract()));
            }
            for j in 0..p {
                g[k * p + j] += sw * (rot.re * jac[(2 * fi, j)] - rot.im * jac[(2 * fi + 1, j)]);
            }
            rot *= step;
        }
    }
    g
}
