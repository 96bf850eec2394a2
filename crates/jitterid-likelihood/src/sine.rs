//! A jittered sine record (the ADC-testing use): `y_k = A sin(2πf0(t_k + τ_k) + φ) + v_k`.
//!
//! * [`sine_least_squares`]: the classical start, a least-squares sine fit at the periodogram's
//!   peak, which sees only the baseband (aliased) frequency and the damped amplitude
//!   `A|γ(f0)|`.
//! * [`attenuation_sigma`]: the classical jitter estimate from that damping for Gaussian
//!   jitter, `σ = √(−2 ln(Â/A))/(2πf0)`, given the true amplitude `A`.
//! * [`fit_sine`]: maximum likelihood of `A, f0, φ`, the jitter and `σ_v` from a start at a
//!   chosen alias of the baseband frequency, with either likelihood criterion.
//!
//! # Aliases
//!
//! On the grid `t_k = kT`, tones at `f0` and `f0 + j/T` have the same samples, and their first
//! moments differ only by the damping `γ(f0)`, which the amplitude absorbs. The second moment
//! separates them when the jitter is known: the variance `λ_k` of a tone at `f0` grows like
//! `(2πf0σA)² cos²θ_k`, so a higher alias predicts more scatter. When the jitter's scale is
//! estimated too, nothing separates them for a scale family: `2πf0τ` is the only way `f0` and
//! `τ` enter `s(t_k + τ)` on the grid, so `(f0 + j/T, σ f0/(f0 + j/T))` gives exactly the same
//! distribution of every sample (all moments). Only prior knowledge of the jitter, or a second
//! tone sharing it, tells the aliases apart.

use super::criterion::LikelihoodCriterion;
use super::MlError;
use crate::fit_criterion::likelihood_fit;
use jitterid_estimate::solver::{Brent, Solver};
use jitterid_estimate::Fit;
use jitterid_estimate::ModelStructure;
use jitterid_estimate::Record;
use jitterid_estimate::{EstimateError, FitOptions};
use jitterid_jitter::JitterModel;
use jitterid_optim::Objective;
use jitterid_signal::{Signal, Sinusoid};
use serde::{Deserialize, Serialize};
use std::f64::consts::{PI, TAU};

/// Fewest samples [`sine_least_squares`] accepts.
pub const SINE_MIN_SAMPLES: usize = 8;

/// A least-squares sine fit ignoring the jitter.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SineLs {
    /// Amplitude `Â` (the damped `A|γ(f0)|` when the tone is jittered).
    pub amplitude: f64,
    /// Baseband frequency in `[0, 1/(2T)]` (Hz).
    pub frequency: f64,
    /// Phase (rad).
    pub phase: f64,
    /// Root mean square of the residuals.
    pub residual_rms: f64,
    /// Samples in the record.
    pub samples: usize,
    /// Sampling interval `T` (s).
    pub interval: f64,
}

/// Gauss–Newton polish of `y ≈ a sin(2πft) + b cos(2πft)` in `(a, b, f)` from `f`: a few
/// steps reach the precision of the data (Brent on the residual sum of squares alone stops
/// at `√ε` relative in `f`).
fn polish(record: &Record, f0: f64) -> Option<(f64, f64, f64)> {
    let grid = record.grid();
    let (a, b, _) = linear_fit_ab(record, f0)?;
    let mut p = [a, b, f0];
    for _ in 0..4 {
        let mut jtj = [[0.0; 3]; 3];
        let mut jtr = [0.0; 3];
        for (k, &y) in record.y().iter().enumerate() {
            let t = grid.time(k);
            let (sn, cs) = (TAU * (p[2] * t).fract()).sin_cos();
            let r = y - p[0] * sn - p[1] * cs;
            let j = [sn, cs, TAU * t * (p[0] * cs - p[1] * sn)];
            for u in 0..3 {
                jtr[u] += j[u] * r;
                for v in 0..3 {
                    jtj[u][v] += j[u] * j[v];
                }
            }
        }
        let d = solve3(jtj, jtr)?;
        for u in 0..3 {
            p[u] += d[u];
        }
    }
    Some((p[0], p[1], p[2]))
}

/// Solves a 3×3 system by Gaussian elimination with partial pivoting.
fn solve3(mut m: [[f64; 3]; 3], mut r: [f64; 3]) -> Option<[f64; 3]> {
    for c in 0..3 {
        let piv = (c..3).max_by(|&i, &j| m[i][c].abs().total_cmp(&m[j][c].abs()))?;
        if !(m[piv][c].abs() > 0.0) {
            return None;
        }
        m.swap(c, piv);
        r.swap(c, piv);
        for i in c + 1..3 {
            let f = m[i][c] / m[c][c];
            for j in c..3 {
                m[i][j] -= f * m[c][j];
            }
            r[i] -= f * r[c];
        }
    }
    let mut x = [0.0; 3];
    for c in (0..3).rev() {
        let s: f64 = (c + 1..3).map(|j| m[c][j] * x[j]).sum();
        x[c] = (r[c] - s) / m[c][c];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// `(Â, φ̂, rss)` of the linear least-squares fit `y ≈ a sin(2πft) + b cos(2πft)` on the grid.
fn linear_fit(record: &Record, f: f64) -> Option<(f64, f64, f64)> {
    let (a, b, rss) = linear_fit_ab(record, f)?;
    // a sin θ + b cos θ = A sin(θ + φ): a = A cos φ, b = A sin φ.
    Some((a.hypot(b), b.atan2(a), rss))
}

/// `(a, b, rss)` of the linear least-squares fit `y ≈ a sin(2πft) + b cos(2πft)`.
fn linear_fit_ab(record: &Record, f: f64) -> Option<(f64, f64, f64)> {
    let grid = record.grid();
    let (mut ss, mut cc, mut sc, mut ys, mut yc) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for (k, &y) in record.y().iter().enumerate() {
        let (s, c) = (TAU * ((f * grid.time(k)).fract())).sin_cos();
        ss += s * s;
        cc += c * c;
        sc += s * c;
        ys += y * s;
        yc += y * c;
    }
    let det = ss * cc - sc * sc;
    if !(det > 1e-9 * (ss * cc).max(1e-300)) {
        return None;
    }
    let a = (ys * cc - yc * sc) / det;
    let b = (yc * ss - ys * sc) / det;
    let yy: f64 = record.y().iter().map(|y| y * y).sum();
    let rss = (yy - a * ys - b * yc).max(0.0);
    Some((a, b, rss))
}

struct Rss<'a>(&'a Record);

impl Objective for Rss<'_> {
    fn num_params(&self) -> usize {
        1
    }
    fn cost(&self, theta: &[f64]) -> f64 {
        linear_fit(self.0, theta[0]).map_or(f64::INFINITY, |r| r.2)
    }
}

/// The least-squares sine fit at the periodogram's peak in `(0, 1/(2T))`, refined by Brent's
/// method on the residual sum of squares.
///
/// # Errors
///
/// [`MlError::SineRecordTooShort`] with fewer than [`SINE_MIN_SAMPLES`] samples or fewer than
/// two cycles of the baseband tone in the record (its frequency is then not resolved from
/// the record's length).
pub fn sine_least_squares(record: &Record) -> Result<SineLs, MlError> {
    let grid = record.grid();
    let n = grid.len();
    let t = grid.interval();
    let too_short = |cycles: f64| MlError::SineRecordTooShort {
        samples: n,
        cycles,
        min_samples: SINE_MIN_SAMPLES,
    };
    if n < SINE_MIN_SAMPLES {
        return Err(too_short(0.0));
    }
    // Zero-padded periodogram on (0, 1/(2T)).
    let pad = 8;
    let m = pad * n / 2;
    let freqs: Vec<f64> = (1..m)
        .map(|j| j as f64 / (pad as f64 * n as f64 * t))
        .collect();
    let spectrum = jitterid_window::dtft(grid, record.y(), None, &freqs)
        .map_err(|e| MlError::from(jitterid_estimate::EstimateError::from(e)))?;
    let (peak, _) = spectrum
        .iter()
        .enumerate()
        .fold((0, -1.0), |(bi, bv), (i, z)| {
            let v = z.norm_sqr();
            if v > bv {
                (i, v)
            } else {
                (bi, bv)
            }
        });
    let f_peak = freqs[peak];
    let cycles = f_peak * grid.duration();
    if cycles < 2.0 {
        return Err(too_short(cycles));
    }
    let df = 1.0 / (pad as f64 * n as f64 * t);
    let brent = Brent {
        bracket_step: 0.25 * df,
        tolerance: 1e-9 * df,
        max_iters: 200,
        ..Brent::default()
    };
    let report = brent
        .minimize(&Rss(record), &[f_peak])
        .map_err(MlError::from)?;
    let mut f = report.params[0];
    if !(f > 0.0 && f < 0.5 / t) || (f - f_peak).abs() > 2.0 * df {
        f = f_peak;
    }
    if let Some((_, _, fp)) = polish(record, f) {
        let better = linear_fit(record, fp).map(|r| r.2) <= linear_fit(record, f).map(|r| r.2);
        if fp > 0.0 && fp < 0.5 / t && (fp - f).abs() < df && better {
            f = fp;
        }
    }
    let (a, phi, rss) = linear_fit(record, f).ok_or_else(|| too_short(cycles))?;
    Ok(SineLs {
        amplitude: a,
        frequency: f,
        phase: phi,
        residual_rms: (rss / n as f64).sqrt(),
        samples: n,
        interval: t,
    })
}

/// The classical amplitude-attenuation estimate of a Gaussian jitter's standard deviation,
/// `σ = √(−2 ln(Â/A))/(2πf0)`, from the fitted (damped) amplitude `Â` and the true
/// amplitude `A`; `None` when `Â ≥ A` (no attenuation seen) or an argument is not positive.
pub fn attenuation_sigma(
    fitted_amplitude: f64,
    true_amplitude: f64,
    frequency: f64,
) -> Option<f64> {
    let r = fitted_amplitude.abs() / true_amplitude.abs();
    if !(r > 0.0 && r < 1.0 && frequency > 0.0) {
        return None;
    }
    Some((-2.0 * r.ln()).sqrt() / (TAU * frequency))
}

/// The start `(A, f, φ)` at the alias of the least-squares fit `ls` nearest to the nominal
/// `frequency` (`f = f_b + j/T` or `j/T − f_b` with the fitted baseband `f_b`), for a jitter
/// of characteristic function `γ` (the amplitude is undamped by `|γ(f)|`).
///
/// # Errors
///
/// [`MlError::InvalidArgument`] if `frequency` is not positive or not within `1/(2NT)` of
/// an alias of `ls.frequency`.
pub fn alias_start<J: JitterModel + ?Sized>(
    ls: &SineLs,
    frequency: f64,
    jitter: &J,
) -> Result<(f64, f64, f64), MlError> {
    let bad = MlError::InvalidArgument {
        name: "alias frequency",
        value: frequency,
        reason: "must be > 0 and within 1/(2NT) of an alias f_b + j/T or j/T − f_b of the baseband frequency",
    };
    let t = ls.interval;
    if !(frequency > 0.0) {
        return Err(bad);
    }
    let tol = 0.5 / ls.samples as f64;
    let x = frequency * t;
    let xb = ls.frequency * t;
    let (f, phase) = if (x - xb - (x - xb).round()).abs() < tol {
        (((x - xb).round() + xb) / t, ls.phase)
    } else if (x + xb - (x + xb).round()).abs() < tol {
        // sin(−2πf_b t + φ') = sin(2πf_b t + φ) with φ' = π − φ.
        (((x + xb).round() - xb) / t, PI - ls.phase)
    } else {
        return Err(bad);
    };
    if !(f > 0.0) {
        return Err(bad);
    }
    let damping = jitter.cf(f).norm().max(1e-3);
    Ok((ls.amplitude / damping, f, phase))
}

/// A maximum-likelihood sine fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SineFit {
    /// Amplitude `Â ≥ 0`.
    pub amplitude: f64,
    /// Frequency `f̂0` (Hz).
    pub frequency: f64,
    /// Phase `φ̂` (rad) in `(−π, π]`. `A sin(ωt + φ)` is the same tone for `φ + 2πk` and for
    /// `(−A, φ + π)`; the search may end on any of these, and `estimate.params` keeps the
    /// value it ended on.
    pub phase: f64,
    /// The jitter's parameters at the estimate (estimated or known).
    pub jitter_params: Vec<f64>,
    /// The jitter's standard deviation at the estimate.
    pub jitter_std: f64,
    /// `σ̂_v` (estimated or known).
    pub noise_std: f64,
    /// The full estimate (names, covariance, termination).
    pub estimate: Fit,
}

/// The representative of `(A, φ)` with `A ≥ 0` and `φ ∈ (−π, π]` (the same tone).
fn canonical_amplitude_phase(amplitude: f64, phase: f64) -> (f64, f64) {
    let (a, phi) = if amplitude < 0.0 {
        (-amplitude, phase + PI)
    } else {
        (amplitude, phase)
    };
    // rem_euclid gives [0, 2π); shift so that π maps to π and −π to π.
    let wrapped = PI - (PI - phi).rem_euclid(TAU);
    (a, wrapped)
}

/// Fits `A, f0, φ`, the jitter's parameters (if `estimate_jitter`) and `σ_v` (unless
/// `noise_std` is given) by maximum likelihood, starting at the alias of the least-squares
/// fit `ls` nearest to the nominal `frequency` ([`alias_start`]) with jitter `jitter` (known,
/// or the start).
///
/// # Errors
///
/// Those of [`alias_start`] and of the likelihood's [`fit`](jitterid_estimate::fit).
#[allow(clippy::too_many_arguments)]
pub fn fit_sine<J, C>(
    record: &Record,
    ls: &SineLs,
    frequency: f64,
    jitter: J,
    estimate_jitter: bool,
    noise_std: Option<f64>,
    criterion: &C,
    options: &FitOptions,
) -> Result<SineFit, MlError>
where
    J: JitterModel + Clone,
    C: LikelihoodCriterion,
{
    let (a, f, phi) = alias_start(ls, frequency, &jitter)?;
    let signal = Sinusoid::new(a, f, phi)?;
    let mut structure =
        ModelStructure::oe(signal, jitter).with_estimated(true, estimate_jitter, false);
    if let Some(s) = noise_std {
        structure = structure.with_noise_std(s)?;
    }
    let mut opts = options.clone();
    if opts.noise_std_start.is_none() && noise_std.is_none() {
        opts.noise_std_start = Some((0.5 * ls.residual_rms).max(1e-6 * ls.amplitude.abs()));
    }
    let estimate = likelihood_fit(criterion, &structure, record, &opts).map_err(|e| match e {
        EstimateError::Likelihood(e) => *e,
        other => MlError::Estimate(other),
    })?;
    let (model, sigma) = super::param::split(&structure, &estimate.params)?;
    let p = model.signal.params();
    let (amplitude, phase) = canonical_amplitude_phase(p[0], p[2]);
    Ok(SineFit {
        amplitude,
        frequency: p[1],
        phase,
        jitter_params: model.jitter.params(),
        jitter_std: model.jitter.std_dev(),
        noise_std: sigma,
        estimate,
    })
}

#[cfg(test)]
mod tests {
    use super::canonical_amplitude_phase;
    use std::f64::consts::PI;

    #[test]
    fn amplitude_and_phase_are_canonical_and_the_same_tone() {
        for (a, phi) in [
            (1.0, 0.3),
            (1.0, 0.3 + 2.0 * PI),
            (-1.0, 0.3 - PI),
            (2.0, -7.0),
            (1.0, PI),
            (1.0, -PI),
        ] {
            let (b, psi) = canonical_amplitude_phase(a, phi);
            assert!(b >= 0.0 && psi > -PI && psi <= PI, "{a} {phi} -> {b} {psi}");
            for t in [0.0, 0.37, 1.9] {
                let x = a * (3.0 * t + phi).sin();
                let y = b * (3.0 * t + psi).sin();
                assert!((x - y).abs() < 1e-14, "{a} {phi}: {x} vs {y}");
            }
        }
    }
}
