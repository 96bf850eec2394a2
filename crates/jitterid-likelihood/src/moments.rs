//! Second moments of jittered samples (`docs/method.md`, "Second moments"):
//!
//! ```text
//! m_k = E[s(t_k + τ)],   λ_k = Var y_k = σ_v² + E[s(t_k + τ)²] − m_k²
//! ```
//!
//! computed by the signal's own exact routes ([`Signal::expected_values`],
//! [`Signal::expected_squares`]; closed forms for sinusoids, the fast modal recursion for LTI
//! responses), with gradients: analytic in the signal's parameters
//! (`∂E[s²]/∂θ = E[2 s ∂s/∂θ]` by the jitter's quadrature rule), central differences in the
//! jitter's parameters, `2σ_v` in `σ_v`. The samples are independent, so the covariance of the
//! residual DTFT `D(f) = Σ_k c_k (y_k − m_k) e^{−i2πfkT}` over a frequency set follows:
//! `E[D(f1) D(f2)*] = Σ_k c_k² λ_k e^{−i2π(f1−f2)kT}` and
//! `E[D(f1) D(f2)] = Σ_k c_k² λ_k e^{−i2π(f1+f2)kT}` ([`dtft_covariance`]).

use super::param::Layout;
use super::MlError;
use jitterid_estimate::ModelStructure;
use jitterid_estimate::NoiseModel;
use jitterid_jitter::JitterModel;
use jitterid_optim::finite_diff::{central_difference, LIKELIHOOD_FD_STEP};
use jitterid_signal::{local_breaks, Jacobian, SampleGrid, Signal};
use jitterid_window::{dtft, fft_grid, FrequencySet, Window};
use num_complex::Complex64;

/// The first two moments of every sample of a record, with gradients when requested.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SecondMoments {
    /// `m_k = E[s(t_k + τ)]`.
    pub mean: Vec<f64>,
    /// `E[s(t_k + τ)²] − m_k²`, the jitter's part of the variance (clamped at 0 against
    /// rounding).
    pub jitter_variance: Vec<f64>,
    /// `λ_k = σ_v² + E[s(t_k + τ)²] − m_k²`.
    pub variance: Vec<f64>,
    /// The measurement-noise standard deviation `σ_v` used.
    pub noise_std: f64,
    /// Names of the parameters of the gradients (see
    /// [`likelihood_param_names`](super::likelihood_param_names)).
    pub names: Vec<String>,
    /// `∂m_k/∂θ_j` as columns `[j][k]`, when requested.
    pub mean_gradient: Option<Jacobian>,
    /// `∂λ_k/∂θ_j` as columns `[j][k]`, when requested.
    pub variance_gradient: Option<Jacobian>,
}

/// `E[2 s(t_k+τ) ∂s(t_k+τ)/∂θ_j]` by the jitter's quadrature rule (split at the signal's
/// breakpoints, resolved for the rate of `s²`).
pub fn expected_squares_gradient<S: Signal + ?Sized>(
    signal: &S,
    grid: &SampleGrid,
    jitter: &dyn JitterModel,
) -> Jacobian {
    let p = signal.num_params();
    let mut cols = vec![vec![0.0; grid.len()]; p];
    let breaks = signal.breakpoints();
    let (lo, hi) = jitter.reach();
    let mut g = vec![0.0; p];
    let mut shared = None;
    for (k, t) in grid.times().enumerate() {
        let local = local_breaks(&breaks, t, lo, hi);
        let own;
        let rule = if local.is_empty() {
            shared.get_or_insert_with(|| jitter.rule(&[], 2.0 * signal.rate()))
        } else {
            own = jitter.rule(&local, 2.0 * signal.rate());
            &own
        };
        for (&tau, &w) in rule.nodes.iter().zip(&rule.weights) {
            let s = signal.value(t + tau);
            signal.value_gradient(t + tau, &mut g);
            for (col, gj) in cols.iter_mut().zip(&g) {
                col[k] += 2.0 * w * s * gj;
            }
        }
    }
    cols
}

/// `(m, E[s²])` of the structure's signal under its jitter.
fn moments_of<S: Signal + ?Sized>(
    signal: &S,
    jitter: &dyn JitterModel,
    grid: &SampleGrid,
) -> (Vec<f64>, Vec<f64>) {
    (
        signal.expected_values(grid, jitter),
        signal.expected_squares(grid, jitter),
    )
}

/// The first two moments of every sample of `grid` for `signal` under `jitter` with
/// measurement-noise level `noise_std`: `m_k`, the jitter's part `E[s²] − m_k²` (clamped at 0
/// against rounding) and `λ_k`, without gradients (`names` is empty). The one place `λ_k` is
/// formed: [`second_moments`] and the bindings call it.
///
/// # Errors
///
/// A negative or non-finite noise level.
pub fn second_moments_of<S: Signal + ?Sized>(
    signal: &S,
    jitter: &dyn JitterModel,
    grid: &SampleGrid,
    noise_std: f64,
) -> Result<SecondMoments, MlError> {
    if !(noise_std.is_finite() && noise_std >= 0.0) {
        return Err(jitterid_estimate::EstimateError::BadNoiseStd { value: noise_std }.into());
    }
    let (mean, sq) = moments_of(signal, jitter, grid);
    let jitter_variance: Vec<f64> = sq
        .iter()
        .zip(&mean)
        .map(|(s, m)| (s - m * m).max(0.0))
        .collect();
    let variance = jitter_variance
        .iter()
        .map(|v| v + noise_std * noise_std)
        .collect();
    Ok(SecondMoments {
        mean,
        jitter_variance,
        variance,
        noise_std,
        names: Vec::new(),
        mean_gradient: None,
        variance_gradient: None,
    })
}

/// The second moments of every sample of `grid` under `structure`, with measurement-noise
/// level `noise_std` (used when the structure does not fix it), and the gradients in the
/// likelihood's parameters when `gradient` is true.
///
/// The noise shape of a Box–Jenkins structure does not enter `λ_k` (the per-sample variance
/// of white noise of level `σ_v`); its columns are zero.
///
/// # Errors
///
/// A negative or non-finite noise level; a jitter parameter at which neither side of the
/// central difference is valid.
pub fn second_moments<S, J, N>(
    structure: &ModelStructure<S, J, N>,
    grid: &SampleGrid,
    noise_std: f64,
    gradient: bool,
) -> Result<SecondMoments, MlError>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
{
    let sigma = structure.noise_std.unwrap_or(noise_std);
    let moments = second_moments_of(&structure.signal, &structure.jitter, grid, sigma)?;
    let m = &moments.mean;
    let layout = Layout::of(structure);
    let names = super::likelihood_param_names(structure);
    let (mean_gradient, variance_gradient) = if gradient {
        let n = grid.len();
        let mut dm = vec![vec![0.0; n]; layout.len()];
        let mut dl = vec![vec![0.0; n]; layout.len()];
        if layout.ns > 0 {
            let gm = structure
                .signal
                .expected_values_gradient(grid, &structure.jitter);
            let gs = expected_squares_gradient(&structure.signal, grid, &structure.jitter);
            for j in 0..layout.ns {
                for k in 0..n {
                    dm[j][k] = gm[j][k];
                    dl[j][k] = gs[j][k] - 2.0 * m[k] * gm[j][k];
                }
            }
        }
        if layout.nj > 0 {
            let theta = structure.jitter.params();
            for j in 0..layout.nj {
                let d = central_difference(
                    &theta,
                    j,
                    LIKELIHOOD_FD_STEP,
                    |p| {
                        let jit = structure.jitter.with_params(p).ok()?;
                        Some(moments_of(&structure.signal, &jit, grid))
                    },
                    |a, b, h| {
                        // Stacked [∂m, ∂E[s²]].
                        a.0.iter()
                            .zip(&b.0)
                            .map(|(x, y)| (x - y) / h)
                            .chain(a.1.iter().zip(&b.1).map(|(x, y)| (x - y) / h))
                            .collect()
                    },
                )
                .ok_or_else(|| {
                    MlError::Unsupported(format!(
                        "jitter parameter {j} = {} admits no finite difference",
                        theta[j]
                    ))
                })?;
                let col = layout.ns + j;
                for k in 0..n {
                    dm[col][k] = d[k];
                    dl[col][k] = d[n + k] - 2.0 * m[k] * d[k];
                }
            }
        }
        if let Some(i) = layout.sigma_index() {
            dl[i].iter_mut().for_each(|v| *v = 2.0 * sigma);
        }
        (Some(dm), Some(dl))
    } else {
        (None, None)
    };
    Ok(SecondMoments {
        names,
        mean_gradient,
        variance_gradient,
        ..moments
    })
}

/// The covariance of the residual DTFT `D(f) = Σ_k c_k (y_k − m_k) e^{−i2πfkT}` over a
/// frequency set, for independent samples of variance `λ_k`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct DtftCovariance {
    /// The frequencies (Hz).
    pub frequencies: Vec<f64>,
    /// `C[a][b] = E[D(f_a) D(f_b)*] = Σ_k c_k² λ_k e^{−i2π(f_a−f_b)kT}` (Hermitian).
    pub covariance: Vec<Vec<Complex64>>,
    /// `P[a][b] = E[D(f_a) D(f_b)] = Σ_k c_k² λ_k e^{−i2π(f_a+f_b)kT}` (symmetric).
    pub pseudo_covariance: Vec<Vec<Complex64>>,
}

impl DtftCovariance {
    /// `Var Y(f_a) = E|D(f_a)|² = Σ_k c_k² λ_k` (the same at every frequency: the jitter's
    /// noise floor is flat).
    pub fn variance(&self, a: usize) -> f64 {
        self.covariance[a][a].re
    }

    /// The real `2F × 2F` covariance of `[Re D(f_0), Im D(f_0), Re D(f_1), …]`, the stacking
    /// of the frequency-domain criteria's residuals.
    pub fn real(&self) -> Vec<Vec<f64>> {
        let f = self.frequencies.len();
        let mut out = vec![vec![0.0; 2 * f]; 2 * f];
        for a in 0..f {
            for b in 0..f {
                let (c, p) = (self.covariance[a][b], self.pseudo_covariance[a][b]);
                out[2 * a][2 * b] = 0.5 * (p.re + c.re);
                out[2 * a + 1][2 * b + 1] = 0.5 * (c.re - p.re);
                out[2 * a][2 * b + 1] = 0.5 * (p.im - c.im);
                out[2 * a + 1][2 * b] = 0.5 * (p.im + c.im);
            }
        }
        out
    }
}

/// The covariance of the windowed residual DTFT over `freqs` for independent samples of
/// variance `variance[k]` (for example [`SecondMoments::variance`]).
///
/// # Errors
///
/// A variance vector of the wrong length or with a negative or non-finite entry; a
/// frequency set built for another record.
pub fn dtft_covariance<W: Window + ?Sized>(
    grid: &SampleGrid,
    variance: &[f64],
    window: &W,
    freqs: &FrequencySet,
) -> Result<DtftCovariance, MlError> {
    let n = grid.len();
    if variance.len() != n {
        return Err(jitterid_estimate::EstimateError::DataLength {
            expected: n,
            got: variance.len(),
        }
        .into());
    }
    if let Some((index, &value)) = variance
        .iter()
        .enumerate()
        .find(|(_, v)| !(v.is_finite() && **v >= 0.0))
    {
        return Err(MlError::NonFinite {
            what: "variance",
            index,
            value,
        });
    }
    if !freqs.fits(grid) {
        return Err(MlError::InvalidArgument {
            name: "frequency set length",
            value: freqs.record_len() as f64,
            reason: "must be built for this record",
        });
    }
    let taper = window.weights(n);
    let v: Vec<f64> = variance
        .iter()
        .zip(&taper)
        .map(|(l, c)| l * c * c)
        .collect();
    let f = freqs.frequencies();
    let nf = f.len();
    let mut cov = vec![vec![Complex64::new(0.0, 0.0); nf]; nf];
    let mut pseudo = cov.clone();
    let window_err =
        |e: jitterid_window::WindowError| MlError::from(jitterid_estimate::EstimateError::from(e));
    if let Some(idx) = freqs.dft_indices() {
        // Differences and sums of DFT-grid points are DFT-grid points: one FFT.
        let all = fft_grid(&v, None).map_err(window_err)?;
        for a in 0..nf {
            for b in 0..nf {
                cov[a][b] = all[(idx[a] + n - idx[b] % n) % n];
                pseudo[a][b] = all[(idx[a] + idx[b]) % n];
            }
        }
    } else {
        let mut diffs = Vec::with_capacity(2 * nf * nf);
        for &fa in f {
            for &fb in f {
                diffs.push(fa - fb);
                diffs.push(fa + fb);
            }
        }
        let d = dtft(grid, &v, None, &diffs).map_err(window_err)?;
        for a in 0..nf {
            for b in 0..nf {
                cov[a][b] = d[2 * (a * nf + b)];
                pseudo[a][b] = d[2 * (a * nf + b) + 1];
            }
        }
    }
    Ok(DtftCovariance {
        frequencies: f.to_vec(),
        covariance: cov,
        pseudo_covariance: pseudo,
    })
}
