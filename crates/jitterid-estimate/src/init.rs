//! Initial values for rational continuous-time models, from the data and without the truth.
//!
//! # Method
//!
//! A frequency-response fit over the low-frequency DFT bins, linear in the coefficients, made
//! nearly output-error by the Sanathanan–Koerner iteration:
//!
//! 1. **Data side.** `Y(f_j)`, the DTFT of the record at `f_j = j/(NT)` for
//!    `0 ≤ j ≤ J` with `f_J ≤` [`InitOptions::max_frequency`] (`0.25/T` by default, half of
//!    Nyquist, where the aliasing of a sampled continuous-time response is small).
//! 2. **Input side.** The sample `y_k` stands for the cell `[t_k − T/2, t_k + T/2)`, so
//!    `T·Y(f) ≈ ∫_W s(t) e^{−i2πf(t−t0)} dt` over the window `W = [t0 − T/2, t0 + NT − T/2)`
//!    (midpoint rule). For `s = g ∗ u` the windowed transform is exactly
//!    `G(i2πf) U_W(f) + e^{−i2πf(t_a − t0)} I(i2πf)/A(i2πf)` at the DFT frequencies, where
//!    `U_W` is the windowed transform of the known continuous-time input (closed form for a
//!    piecewise-constant input and for tones), `A` the denominator and `I` a real polynomial of
//!    degree `n − 1` that carries the states at the window's two ends (the *transient* term;
//!    both ends share the phase because `e^{−i2πf_j NT} = 1`). With the jitter, the mean of the
//!    samples is the response to the input smoothed by the jitter's density, whose transform
//!    is `γ(−f)·U`; the jitter's damping is included when [`InitOptions::compensate_jitter`].
//! 3. **Linear fit.** `A(s) Y = B(s) Ũ + E I(s)` with `Ũ = γ(−f) U_W/T`, `E = e^{iπfT}/T`,
//!    `A` monic, in the normalised variable `s/ω_n` (`ω_n = 2π f_J`) for conditioning: Levy's
//!    equation-error fit first, then Sanathanan–Koerner iterations that divide each equation by
//!    `|A_prev(s_j)|`, so that at a fixed point the residual is the output error
//!    `Y − (BŨ + EI)/A`. The iterate with the lowest output error is kept.
//! 4. **A valid model.** Unstable poles are reflected into the left half plane
//!    (`p → −p̄`), poles on the axis are pushed off it, repeated ones separated, and real roots
//!    and complex pairs are matched to the template's parameterisation (two real roots become a
//!    pair at their mean, a pair becomes two real roots at `re ± im`). With the denominator
//!    fixed, the numerator (and the transient) is fitted again, linearly and in output-error
//!    form, so that reflecting a pole does not leave a wrong gain behind.
//!
//! The result is a start for [`fit`](crate::fit), not an estimate: the midpoint
//! rule and the smoothed-input approximation are accurate to a few per cent at the frequencies
//! used, which is what a start needs. The default robust fit runs
//! [`MultiStart`](crate::solver::MultiStart) around it (see `cargo xtask reproduce starts`).
//!
//! # Example
//!
//! ```
//! use jitterid_estimate::{fit, initialize, Bcls, FitOptions, InitOptions, ModelStructure, Record};
//! use jitterid_jitter::UniformSum;
//! use jitterid_signal::{simulate, LtiResponse, RandomBinary, Root, SampleGrid, Zpk};
//! use rand::SeedableRng;
//!
//! let truth = Zpk::new(0.2, vec![Root::Real(-0.5)], vec![Root::Pair { re: -0.25, im: 0.3 }])?;
//! let mut rng = rand::rngs::StdRng::seed_from_u64(3);
//! let u = RandomBinary::paper().generate(0.0, 201.0, &mut rng)?;
//! let jitter = UniformSum::new(2, 0.5 / 3f64.sqrt())?;
//! let grid = SampleGrid::new(0.0, 1.0, 200)?;
//! let data = simulate(&LtiResponse::new(truth, u.clone()), &jitter, &grid, 0.01, &mut rng)?;
//! let record = Record::new(grid, data.y)?;
//!
//! // Only the structure is given: one real zero, one complex pair; the values are placeholders.
//! let template = Zpk::new(1.0, vec![Root::Real(-1.0)], vec![Root::Pair { re: -1.0, im: 1.0 }])?;
//! let structure = ModelStructure::oe(LtiResponse::new(template, u), jitter);
//! let start = initialize(&structure, &record, &InitOptions::default())?;
//! let estimate = fit(&start, &record, &Bcls, &FitOptions::default())?;
//! assert!(estimate.converged);
//! assert!((estimate.params[3] - 0.3).abs() < 0.02);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Why one file of about 820 lines (its method documented above, a sixth of them and the tests
//! another eighth): the three steps share the model's private coefficient layout and are only
//! meaningful in order.

use crate::data::Record;
use crate::noise::NoiseModel;
use crate::structure::ModelStructure;
use faer::Mat;
use jitterid_jitter::JitterModel;
use jitterid_signal::{
    poly, Input, LtiResponse, RationalModel, Root, SignalError, TransferFunction, Zpk,
};
use jitterid_window::{transform, DirichletWindow, FrequencySet};
use num_complex::Complex64;
use std::f64::consts::{PI, TAU};

/// Singular values below this fraction of the largest make the linear fit rank deficient.
const RANK_TOL: f64 = 1e-12;

/// Relative separation given to poles that come out repeated. A [`Zpk`] takes repeated poles
/// (through its realisation rather than its modal form), but a start with distinct poles lets
/// the search move each one; the reproduced starts depend on this value.
const SEPARATION: f64 = 1e-6;

/// Options of the initializer.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct InitOptions {
    /// Highest frequency (Hz) of the bins used; `None` for `0.25/T`. More bins are taken (up to
    /// Nyquist) when these are too few for the unknowns.
    pub max_frequency: Option<f64>,
    /// Largest number of Sanathanan–Koerner iterations after Levy's fit. Default 30.
    pub iterations: usize,
    /// Stop when no normalised denominator coefficient changes by more than this (relative).
    /// Default `1e-10`.
    pub tolerance: f64,
    /// Include the jitter's damping `γ(−f)` of the structure's jitter model. Default true.
    pub compensate_jitter: bool,
    /// The record has an unknown output offset `y₀` (an operating point): leave out the bin
    /// `f = 0`, the only DFT bin a constant reaches (it adds `N y₀` there and nothing at
    /// `j/(NT)`, `j ≠ 0`), so that the model is fitted to the bins the offset leaves alone.
    /// The offset's own start is then [`offset_start`]. Default false.
    #[serde(default)]
    pub offset: bool,
}

impl Default for InitOptions {
    fn default() -> Self {
        Self {
            max_frequency: None,
            iterations: 30,
            tolerance: 1e-10,
            compensate_jitter: true,
            offset: false,
        }
    }
}

/// Why no initial model could be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum InitError {
    /// Fewer real equations than unknowns of the linear fit (a record that is too short).
    #[error("{equations} real equations cannot determine the {unknowns} unknowns of the frequency-response fit")]
    TooFewFrequencies {
        /// Real equations available (two per bin, one at 0 Hz and at Nyquist).
        equations: usize,
        /// Unknowns: denominator, numerator and transient coefficients.
        unknowns: usize,
    },
    /// The linear fit is rank deficient: the input does not excite the bins used, or the data
    /// are zero there.
    #[error("the input and data do not determine a model of this order (the frequency-response fit is rank deficient)")]
    NotExcited,
    /// The data's DTFT or the input's spectrum is not finite.
    #[error("the data or the input spectrum is not finite at {frequency} Hz")]
    NonFinite {
        /// The first offending frequency.
        frequency: f64,
    },
    /// The fit produced a numerator or denominator without a usable leading coefficient.
    #[error("the fitted {what} is degenerate")]
    Degenerate {
        /// Which polynomial.
        what: &'static str,
    },
    /// An option out of its range.
    #[error("initializer option `{name}` = {value} is invalid")]
    InvalidOption {
        /// The option.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// The model could not be built from the fitted roots.
    #[error(transparent)]
    Signal(#[from] SignalError),
}

/// A rational parameterisation that the initializer can fill from fitted polynomials.
pub trait InitialModel: RationalModel {
    /// Numbers of zeros and of poles, counted with multiplicity.
    fn orders(&self) -> (usize, usize);

    /// A model of the same parameterisation (same kinds of roots in the same order) from a fit.
    fn with_fit(&self, fit: &RationalFit) -> Result<Self, InitError>;
}

/// A fitted rational function `G(s) = gain · Π(s − z_i) / Π(s − p_i)`, poles stable and
/// distinct.
#[derive(Debug, Clone, PartialEq)]
pub struct RationalFit {
    /// Leading numerator coefficient (the denominator is monic).
    pub gain: f64,
    /// The zeros (conjugate pairs complete).
    pub zeros: Vec<Complex64>,
    /// The poles (conjugate pairs complete), matched to the template's real roots and pairs.
    pub poles: Vec<Complex64>,
    /// Numerator coefficients in decreasing powers of `s` (length: zeros + 1).
    pub num: Vec<f64>,
    /// Monic denominator coefficients in decreasing powers of `s`.
    pub den: Vec<f64>,
}

impl InitialModel for TransferFunction {
    fn orders(&self) -> (usize, usize) {
        (self.num().len() - 1, self.den().len() - 1)
    }

    fn with_fit(&self, fit: &RationalFit) -> Result<Self, InitError> {
        Ok(TransferFunction::new(&fit.num, &fit.den)?)
    }
}

fn count(roots: &[Root]) -> usize {
    roots.iter().map(Root::count).sum()
}

impl InitialModel for Zpk {
    fn orders(&self) -> (usize, usize) {
        (count(self.zeros()), count(self.poles()))
    }

    fn with_fit(&self, fit: &RationalFit) -> Result<Self, InitError> {
        let zeros = match_kinds(self.zeros(), &fit.zeros);
        let poles = match_kinds(self.poles(), &fit.poles);
        Ok(Zpk::new(fit.gain, zeros, poles)?)
    }
}

/// An initial model of `template`'s parameterisation (its values are ignored) from `record`,
/// driven by the known `input`, with the samples' mean damped by `jitter` when given.
///
/// # Errors
///
/// See [`InitError`]: too short a record, an input that does not excite the bins used,
/// non-finite data, invalid options.
pub fn initial_model<M: InitialModel>(
    template: &M,
    record: &Record,
    input: &Input,
    jitter: Option<&dyn JitterModel>,
    options: &InitOptions,
) -> Result<M, InitError> {
    let (m, n) = template.orders();
    let fit = fit_rational(record, input, jitter, m, n, options)?;
    template.with_fit(&fit)
}

/// The structure with its signal's model replaced by an initial model fitted to `record` (see
/// [`initial_model`]); the jitter (for the damping) and the input are the structure's.
///
/// # Errors
///
/// Those of [`initial_model`].
pub fn initialize<M, J, N>(
    structure: &ModelStructure<LtiResponse<M>, J, N>,
    record: &Record,
    options: &InitOptions,
) -> Result<ModelStructure<LtiResponse<M>, J, N>, InitError>
where
    M: InitialModel,
    J: JitterModel + Clone,
    N: NoiseModel,
{
    let input = structure.signal.input();
    let jitter: Option<&dyn JitterModel> = if options.compensate_jitter {
        Some(&structure.jitter)
    } else {
        None
    };
    let model = initial_model(structure.signal.model(), record, input, jitter, options)?;
    let mut out = structure.clone();
    out.signal = LtiResponse::new(model, input.clone());
    Ok(out)
}

/// The start of an output offset `y₀` for a model whose response (without the offset) is
/// `response`: `mean(y) − mean(m_k)` with `m_k = E[s(t_k + τ)]` under `jitter`, the value that
/// zeroes the residuals' mean, which is the least-squares offset for the response held (time
/// domain) and the one that fits the bin `f = 0` exactly (frequency domain, where the offset
/// adds `N y₀`).
pub fn offset_start<S: jitterid_signal::Signal + ?Sized>(
    response: &S,
    record: &Record,
    jitter: &dyn JitterModel,
) -> f64 {
    let m = response.expected_values(record.grid(), jitter);
    let n = record.y().len().max(1) as f64;
    record.y().iter().zip(&m).map(|(y, m)| y - m).sum::<f64>() / n
}

/// The linear frequency-response fit with `m` zeros and `n` poles; see the module docs.
///
/// # Errors
///
/// See [`InitError`].
pub fn fit_rational(
    record: &Record,
    input: &Input,
    jitter: Option<&dyn JitterModel>,
    m: usize,
    n: usize,
    options: &InitOptions,
) -> Result<RationalFit, InitError> {
    if n == 0 || m > n {
        return Err(SignalError::Improper { zeros: m, poles: n }.into());
    }
    if !(options.tolerance.is_finite() && options.tolerance >= 0.0) {
        return Err(InitError::InvalidOption {
            name: "tolerance",
            value: options.tolerance,
        });
    }
    let grid = record.grid();
    let (len, t) = (grid.len(), grid.interval());
    let unknowns = 2 * n + m + 1;
    let f_max = match options.max_frequency {
        None => 0.25 / t,
        Some(f) if f.is_finite() && f > 0.0 => f,
        Some(f) => {
            return Err(InitError::InvalidOption {
                name: "max_frequency",
                value: f,
            })
        }
    };
    // Bins 0..=last: `last` from the band, raised until the equations suffice, capped at N/2.
    let first = usize::from(options.offset);
    let equations = |last: usize| {
        let nyquist = len % 2 == 0 && last == len / 2 && last > 0;
        // One real equation at 0 Hz (left out with an offset) and at Nyquist, two elsewhere.
        (2 * (last + 1) - 1 - usize::from(nyquist)).saturating_sub(first)
    };
    let mut last = ((f_max * len as f64 * t).floor() as usize).min(len / 2);
    while equations(last) < unknowns + 1 && last < len / 2 {
        last += 1;
    }
    if equations(last) < unknowns {
        return Err(InitError::TooFewFrequencies {
            equations: equations(last),
            unknowns,
        });
    }
    let freqs: Vec<f64> = (0..=last).map(|j| j as f64 / (len as f64 * t)).collect();
    let set = FrequencySet::list(grid, freqs.clone()).map_err(|_| InitError::NonFinite {
        frequency: freqs[last],
    })?;
    let y =
        transform(grid, &DirichletWindow, record.y(), &set).map_err(|_| InitError::NonFinite {
            frequency: freqs[0],
        })?;
    let (t0, t_a) = (grid.start(), grid.start() - 0.5 * t);
    let t_b = t_a + len as f64 * t;
    let omega_n = TAU * freqs[last];
    let mut bins = Vec::with_capacity(freqs.len());
    for (j, &f) in freqs.iter().enumerate().skip(first) {
        let damp = jitter.map_or(Complex64::new(1.0, 0.0), |g| g.cf(f).conj());
        let u = damp * windowed_input(input, t_a, t_b, t0, f) / t;
        let e = Complex64::from_polar(1.0 / t, PI * f * t);
        if !(y[j].is_finite() && u.is_finite()) {
            return Err(InitError::NonFinite { frequency: f });
        }
        bins.push(Bin {
            s: Complex64::new(0.0, TAU * f / omega_n),
            y: y[j],
            u,
            e,
        });
    }
    let lsq = Fit::new(&bins, m, n);

    // Levy, then Sanathanan–Koerner; keep the iterate with the lowest output error.
    let mut alpha = lsq.solve_denominator(None)?;
    let mut best = (lsq.output_error(&alpha)?, alpha.clone());
    for _ in 0..options.iterations {
        // An iteration that fails (a reweighted system that is numerically singular) ends the
        // iterations; the best iterate so far is kept.
        let Ok(next) = lsq.solve_denominator(Some(&alpha)) else {
            break;
        };
        let change = next
            .iter()
            .zip(&alpha)
            .map(|(a, b)| (a - b).abs() / b.abs().max(1.0))
            .fold(0.0, f64::max);
        alpha = next;
        let Ok(cost) = lsq.output_error(&alpha) else {
            break;
        };
        if cost < best.0 {
            best = (cost, alpha.clone());
        }
        if !(change > options.tolerance) {
            break;
        }
    }
    let alpha = best.1;

    // Poles in the normalised variable, made valid, then the numerator refitted.
    let mut den_dec: Vec<f64> = std::iter::once(1.0)
        .chain(alpha.iter().rev().copied())
        .collect();
    let poles = poly::roots(&den_dec).ok_or(InitError::Degenerate {
        what: "denominator",
    })?;
    let poles = stabilize(&poles);
    den_dec = real_poly(&poles);
    let alpha: Vec<f64> = den_dec[1..].iter().rev().copied().collect();
    let (beta, _) = lsq.solve_numerator(&alpha)?;
    let num_dec: Vec<f64> = beta.iter().rev().copied().collect();
    if !(num_dec[0] != 0.0 && num_dec.iter().all(|c| c.is_finite())) {
        return Err(InitError::Degenerate { what: "numerator" });
    }
    let zeros = poly::roots(&num_dec).ok_or(InitError::Degenerate { what: "numerator" })?;

    // Back to s: roots scale by ω_n; coefficients of power k by ω_n^{n−k} (denominator monic).
    let scale = |c: &[f64], lead_power: usize| -> Vec<f64> {
        c.iter()
            .enumerate()
            .map(|(i, &x)| x * omega_n.powi((n - (lead_power - i)) as i32))
            .collect()
    };
    let num = scale(&num_dec, m);
    let den = scale(&den_dec, n);
    let fit = RationalFit {
        gain: num[0],
        zeros: zeros.iter().map(|z| z * omega_n).collect(),
        poles: poles.iter().map(|p| p * omega_n).collect(),
        num,
        den,
    };
    if !(fit.gain.is_finite() && fit.den.iter().all(|c| c.is_finite())) {
        return Err(InitError::Degenerate {
            what: "denominator",
        });
    }
    Ok(fit)
}

/// `∫_{t_a}^{t_b} u(t) e^{−i2πf(t − t0)} dt`, in closed form.
fn windowed_input(input: &Input, t_a: f64, t_b: f64, t0: f64, f: f64) -> Complex64 {
    match input {
        Input::Piecewise(p) => p
            .levels()
            .iter()
            .zip(p.edges().windows(2))
            .filter_map(|(&u, e)| {
                let (lo, hi) = (e[0].max(t_a), e[1].min(t_b));
                (hi > lo).then(|| {
                    let d = hi - lo;
                    let mid = 0.5 * (lo + hi) - t0;
                    Complex64::from_polar(u * d * sinc(PI * f * d), -TAU * f * mid)
                })
            })
            .sum(),
        Input::Tones(ms) => {
            // A sin(2πνt + φ) = (A/2i)(e^{iφ} e^{i2πνt} − e^{−iφ} e^{−i2πνt}).
            let (len, mid) = (t_b - t_a, 0.5 * (t_a + t_b));
            let line = |nu: f64| {
                Complex64::from_polar(
                    len * sinc(PI * (nu - f) * len),
                    TAU * (nu * mid - f * (mid - t0)),
                )
            };
            ms.tones()
                .iter()
                .map(|c| {
                    let k = Complex64::from_polar(c.amplitude, c.phase) / Complex64::new(0.0, 2.0);
                    k * line(c.frequency) - k.conj() * line(-c.frequency)
                })
                .sum()
        }
    }
}

/// `sin x / x`.
fn sinc(x: f64) -> f64 {
    if x.abs() < 1e-4 {
        1.0 - x * x / 6.0
    } else {
        x.sin() / x
    }
}

/// One DFT bin: normalised `s`, the data, the (damped, scaled) input and the transient's phase.
struct Bin {
    s: Complex64,
    y: Complex64,
    u: Complex64,
    e: Complex64,
}

/// The linear least-squares problems of the fit over a set of bins.
struct Fit<'a> {
    bins: &'a [Bin],
    m: usize,
    n: usize,
    /// Block scales of the data, input and transient columns.
    scale: (f64, f64, f64),
}

/// `Σ_i c_i s^i` (increasing powers).
fn eval_inc(c: &[f64], s: Complex64) -> Complex64 {
    c.iter()
        .rev()
        .fold(Complex64::new(0.0, 0.0), |acc, &x| acc * s + x)
}

/// `A(s) = s^n + Σ_{i<n} α_i s^i`.
fn monic(alpha: &[f64], s: Complex64) -> Complex64 {
    s.powi(alpha.len() as i32) + eval_inc(alpha, s)
}

impl<'a> Fit<'a> {
    fn new(bins: &'a [Bin], m: usize, n: usize) -> Self {
        let max = |g: fn(&Bin) -> Complex64| bins.iter().map(|b| g(b).norm()).fold(0.0, f64::max);
        let nonzero = |x: f64| if x > 0.0 { x } else { 1.0 };
        Self {
            bins,
            m,
            n,
            scale: (
                nonzero(max(|b| b.y)),
                nonzero(max(|b| b.u)),
                nonzero(max(|b| b.e)),
            ),
        }
    }

    /// Solves `A(s)Y − B(s)Ũ − E·I(s) = 0` for `α` (and `β`, `I`), each equation divided by
    /// `|A_prev(s)|` when given.
    fn solve_denominator(&self, prev: Option<&[f64]>) -> Result<Vec<f64>, InitError> {
        let (n, m) = (self.n, self.m);
        let (sy, su, se) = self.scale;
        let cols = 2 * n + m + 1;
        let mut a = Mat::<f64>::zeros(2 * self.bins.len(), cols);
        let mut rhs = vec![0.0; 2 * self.bins.len()];
        for (j, b) in self.bins.iter().enumerate() {
            let w = prev.map_or(1.0, |p| 1.0 / monic(p, b.s).norm());
            let mut row = Vec::with_capacity(cols);
            let mut sp = Complex64::new(w, 0.0);
            let mut powers = Vec::with_capacity(n + 1);
            for _ in 0..=n {
                powers.push(sp);
                sp *= b.s;
            }
            row.extend((0..n).map(|i| powers[i] * b.y / sy));
            row.extend((0..=m).map(|i| -powers[i] * b.u / su));
            row.extend((0..n).map(|i| -powers[i] * b.e / se));
            let r = -powers[n] * b.y / sy;
            for (c, v) in row.iter().enumerate() {
                a[(2 * j, c)] = v.re;
                a[(2 * j + 1, c)] = v.im;
            }
            rhs[2 * j] = r.re;
            rhs[2 * j + 1] = r.im;
        }
        let x = lstsq(&a, &rhs)?;
        Ok(x[..n].to_vec())
    }

    /// With `A` fixed: `B(s)Ũ + E·I(s) ≈ A(s)Y` divided by `|A(s)|` (the output error, linear in
    /// `β` and `I`). Returns `(β, I)` in increasing powers, unscaled.
    fn solve_numerator(&self, alpha: &[f64]) -> Result<(Vec<f64>, Vec<f64>), InitError> {
        let (n, m) = (self.n, self.m);
        let (sy, su, se) = self.scale;
        let cols = n + m + 1;
        let mut a = Mat::<f64>::zeros(2 * self.bins.len(), cols);
        let mut rhs = vec![0.0; 2 * self.bins.len()];
        for (j, b) in self.bins.iter().enumerate() {
            let den = monic(alpha, b.s);
            let w = 1.0 / den.norm();
            let mut sp = Complex64::new(w, 0.0);
            for i in 0..=m.max(n.saturating_sub(1)) {
                if i <= m {
                    let v = sp * b.u / su;
                    a[(2 * j, i)] = v.re;
                    a[(2 * j + 1, i)] = v.im;
                }
                if i < n {
                    let v = sp * b.e / se;
                    a[(2 * j, m + 1 + i)] = v.re;
                    a[(2 * j + 1, m + 1 + i)] = v.im;
                }
                sp *= b.s;
            }
            let r = den * w * b.y / sy;
            rhs[2 * j] = r.re;
            rhs[2 * j + 1] = r.im;
        }
        let x = lstsq(&a, &rhs)?;
        // Undo the block scaling: the unknowns solved for are β·su/sy and I·se/sy.
        let beta = x[..=m].iter().map(|v| v * sy / su).collect();
        let transient = x[m + 1..].iter().map(|v| v * sy / se).collect();
        Ok((beta, transient))
    }

    /// `Σ_j |Y − (BŨ + E·I)/A|²` with the numerator and transient fitted for this `A`.
    fn output_error(&self, alpha: &[f64]) -> Result<f64, InitError> {
        let (beta, transient) = self.solve_numerator(alpha)?;
        let cost = self
            .bins
            .iter()
            .map(|b| {
                let model = (eval_inc(&beta, b.s) * b.u + eval_inc(&transient, b.s) * b.e)
                    / monic(alpha, b.s);
                (b.y - model).norm_sqr()
            })
            .sum::<f64>();
        Ok(if cost.is_nan() { f64::INFINITY } else { cost })
    }
}

/// Least squares by the thin SVD; [`InitError::NotExcited`] if rank deficient.
fn lstsq(a: &Mat<f64>, b: &[f64]) -> Result<Vec<f64>, InitError> {
    let finite = (0..a.nrows()).all(|i| (0..a.ncols()).all(|j| a[(i, j)].is_finite()))
        && b.iter().all(|x| x.is_finite());
    if !finite {
        return Err(InitError::NotExcited);
    }
    let svd = a.thin_svd().map_err(|_| InitError::NotExcited)?;
    let s = svd.S().column_vector();
    let (u, v) = (svd.U(), svd.V());
    let k = a.ncols();
    let smax = (0..k).map(|i| s[i]).fold(0.0, f64::max);
    if !(smax > 0.0) || (0..k).any(|i| !(s[i] > RANK_TOL * smax)) {
        return Err(InitError::NotExcited);
    }
    let mut x = vec![0.0; k];
    for i in 0..k {
        let c = (0..a.nrows()).map(|r| u[(r, i)] * b[r]).sum::<f64>() / s[i];
        for (j, xj) in x.iter_mut().enumerate() {
            *xj += v[(j, i)] * c;
        }
    }
    if x.iter().all(|v| v.is_finite()) {
        Ok(x)
    } else {
        Err(InitError::NotExcited)
    }
}

/// Poles made valid: reflected into the open left half plane, pushed off the origin and the
/// imaginary axis, repeated ones separated, pairs exact. The input comes from [`poly::roots`]
/// (pairs exact, real roots with `im = 0`), in the normalised variable (unit scale is the top of
/// the band).
fn stabilize(poles: &[Complex64]) -> Vec<Complex64> {
    // Smallest modulus and relative damping given to a pole.
    const TINY: f64 = 1e-3;
    let fix = |p: &Complex64| {
        let mut q = Complex64::new(-p.re.abs(), p.im.abs());
        if q.norm() < TINY {
            q = if q.im == 0.0 {
                Complex64::new(-TINY, 0.0)
            } else {
                Complex64::new(-TINY, TINY)
            };
        }
        if q.re > -TINY * q.norm() {
            q.re = -TINY * q.norm();
        }
        q
    };
    let separate = |v: &mut Vec<Complex64>| {
        for i in 1..v.len() {
            for j in 0..i {
                if (v[i] - v[j]).norm() <= SEPARATION * v[i].norm() {
                    v[i] *= 1.0 + 2.0 * SEPARATION;
                }
            }
        }
    };
    let mut reals: Vec<Complex64> = poles.iter().filter(|p| p.im == 0.0).map(fix).collect();
    let mut uppers: Vec<Complex64> = poles.iter().filter(|p| p.im > 0.0).map(fix).collect();
    separate(&mut reals);
    separate(&mut uppers);
    let lowers: Vec<Complex64> = uppers.iter().map(|p| p.conj()).collect();
    reals.into_iter().chain(uppers).chain(lowers).collect()
}

/// Monic real polynomial (decreasing powers) with the given roots (conjugate pairs complete).
fn real_poly(roots: &[Complex64]) -> Vec<f64> {
    let mut p = vec![1.0];
    let mut used = vec![false; roots.len()];
    for i in 0..roots.len() {
        if used[i] {
            continue;
        }
        used[i] = true;
        let r = roots[i];
        if r.im == 0.0 {
            p = poly::mul(&p, &[1.0, -r.re]);
        } else {
            if let Some(j) =
                (0..roots.len()).find(|&j| !used[j] && (roots[j] - r.conj()).norm() == 0.0)
            {
                used[j] = true;
            }
            p = poly::mul(&p, &[1.0, -2.0 * r.re, r.norm_sqr()]);
        }
    }
    p
}

/// Assigns fitted roots (pairs complete) to a template's kinds: each template `Real` gets a real
/// root, each `Pair` a pair. Surplus real roots are merged into pairs (closest first), surplus
/// pairs split into two real roots at `re ± im` (most nearly real first).
fn match_kinds(template: &[Root], roots: &[Complex64]) -> Vec<Root> {
    let mut reals: Vec<f64> = roots.iter().filter(|r| r.im == 0.0).map(|r| r.re).collect();
    let mut pairs: Vec<(f64, f64)> = roots
        .iter()
        .filter(|r| r.im > 0.0)
        .map(|r| (r.re, r.im))
        .collect();
    let wanted = |kind: fn(&Root) -> bool| template.iter().filter(|r| kind(r)).count();
    let want_reals = wanted(|r| matches!(r, Root::Real(_)));
    let want_quadratics = wanted(|r| matches!(r, Root::Quadratic { .. }));
    reals.sort_by(f64::total_cmp);
    // The two closest adjacent reals, taken out of `reals`.
    let closest = |reals: &mut Vec<f64>| {
        let i = (0..reals.len() - 1)
            .min_by(|&a, &b| (reals[a + 1] - reals[a]).total_cmp(&(reals[b + 1] - reals[b])))
            .unwrap_or(0);
        let (x, y) = (reals[i], reals[i + 1]);
        reals.drain(i..=i + 1);
        (x, y)
    };
    // Surplus reals go first to the quadratic factors, which take two reals exactly as they
    // are, then merge into pairs.
    let mut quadratics: Vec<(f64, f64)> = Vec::new();
    while reals.len() >= want_reals + 2 && quadratics.len() < want_quadratics {
        let (x, y) = closest(&mut reals);
        quadratics.push((-(x + y), x * y));
    }
    while reals.len() > want_reals && reals.len() >= 2 {
        let (x, y) = closest(&mut reals);
        let re = 0.5 * (x + y);
        let im = (0.5 * (y - x)).max(SEPARATION * re.abs().max(f64::MIN_POSITIVE));
        pairs.push((re, im));
    }
    while reals.len() < want_reals && !pairs.is_empty() {
        let i = (0..pairs.len())
            .min_by(|&a, &b| {
                let r = |(re, im): (f64, f64)| im / re.abs().max(f64::MIN_POSITIVE);
                r(pairs[a]).total_cmp(&r(pairs[b]))
            })
            .unwrap_or(0);
        let (re, im) = pairs.remove(i);
        reals.push(re - im);
        reals.push(re + im);
    }
    // Fill the template in order; reals from the slowest (closest to 0) down, pairs by modulus;
    // a quadratic factor takes two reals when there were any to spare, otherwise a pair.
    reals.sort_by(|a, b| b.total_cmp(a));
    pairs.sort_by(|a, b| (a.0.hypot(a.1)).total_cmp(&b.0.hypot(b.1)));
    let (mut ri, mut pi, mut qi) = (reals.into_iter(), pairs.into_iter(), quadratics.into_iter());
    let mut next_pair = || pi.next().unwrap_or((f64::NAN, f64::NAN));
    template
        .iter()
        .map(|r| match r {
            Root::Real(_) => Root::Real(ri.next().unwrap_or(f64::NAN)),
            Root::Pair { .. } => {
                let (re, im) = next_pair();
                Root::Pair { re, im }
            }
            Root::Quadratic { .. } => {
                let (a1, a0) = qi.next().unwrap_or_else(|| {
                    let (re, im) = next_pair();
                    (-2.0 * re, re * re + im * im)
                });
                Root::Quadratic { a1, a0 }
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use jitterid_jitter::UniformSum;
    use jitterid_signal::{simulate, PiecewiseConstant, RandomBinary, SampleGrid, Signal};
    use rand::SeedableRng;

    fn paper() -> Zpk {
        Zpk::new(
            0.2,
            vec![Root::Real(-0.5)],
            vec![Root::Pair { re: -0.25, im: 0.3 }],
        )
        .unwrap()
    }

    /// The paper's input (seed 11), jitter and grid, and the exact mean `m_k` of its system.
    fn exact_mean() -> (PiecewiseConstant, UniformSum, SampleGrid, Vec<f64>) {
        let mut rng = rand::rngs::StdRng::seed_from_u64(11);
        let u = RandomBinary::paper()
            .generate(0.0, 201.0, &mut rng)
            .unwrap();
        let jitter = UniformSum::new(2, 0.5 / 3f64.sqrt()).unwrap();
        let grid = SampleGrid::new(0.0, 1.0, 200).unwrap();
        let m = LtiResponse::new(paper(), u.clone()).expected_values(&grid, &jitter);
        (u, jitter, grid, m)
    }

    #[test]
    fn recovers_the_paper_system_from_its_exact_mean() {
        let (u, jitter, grid, m) = exact_mean();
        let record = Record::new(grid, m).unwrap();
        let template = Zpk::new(
            1.0,
            vec![Root::Real(-1.0)],
            vec![Root::Pair { re: -1.0, im: 1.0 }],
        )
        .unwrap();
        let g = initial_model(
            &template,
            &record,
            &u.into(),
            Some(&jitter),
            &InitOptions::default(),
        )
        .unwrap();
        let p = g.params();
        for (got, want) in p.iter().zip([0.2, -0.5, -0.25, 0.3]) {
            assert!((got - want).abs() < 0.05 * want.abs(), "{p:?}");
        }
    }

    #[test]
    fn kinds_are_matched_and_poles_stabilised() {
        let roots = [Complex64::new(-1.0, 0.0), Complex64::new(-3.0, 0.0)];
        assert_eq!(
            match_kinds(&[Root::Pair { re: 0.0, im: 1.0 }], &roots),
            vec![Root::Pair { re: -2.0, im: 1.0 }]
        );
        let pair = [Complex64::new(-2.0, 0.5), Complex64::new(-2.0, -0.5)];
        assert_eq!(
            match_kinds(&[Root::Real(0.0), Root::Real(0.0)], &pair),
            vec![Root::Real(-1.5), Root::Real(-2.5)]
        );
        let s = stabilize(&[
            Complex64::new(0.5, 2.0),
            Complex64::new(0.5, -2.0),
            Complex64::new(0.0, 0.0),
        ]);
        assert!(s.iter().all(|p| p.re < 0.0));
        assert_eq!(s.len(), 3);
        assert_eq!(s[1], s[2].conj());
        assert_eq!(s[1], Complex64::new(-0.5, 2.0));
    }

    #[test]
    fn simulated_record_gives_a_start_in_the_basin() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(5);
        let u = RandomBinary::paper()
            .generate(0.0, 201.0, &mut rng)
            .unwrap();
        let jitter = UniformSum::new(2, 0.5 / 3f64.sqrt()).unwrap();
        let grid = SampleGrid::new(0.0, 1.0, 200).unwrap();
        let data = simulate(
            &LtiResponse::new(paper(), u.clone()),
            &jitter,
            &grid,
            0.01,
            &mut rng,
        )
        .unwrap();
        let record = Record::new(grid, data.y).unwrap();
        let tf = TransferFunction::new(&[1.0, 1.0], &[1.0, 1.0, 1.0]).unwrap();
        let g = initial_model(
            &tf,
            &record,
            &u.into(),
            Some(&jitter),
            &InitOptions::default(),
        )
        .unwrap();
        // b1, b0, a1, a0 of 0.2 (s + 0.5) / (s² + 0.5 s + 0.1525).
        for (got, want) in g.params().iter().zip([0.2, 0.1, 0.5, 0.1525]) {
            assert!((got - want).abs() < 0.15 * want, "{:?}", g.params());
        }
    }

    /// With `offset`, the fit leaves out the bin `f = 0`, the only one a constant reaches: the
    /// exact mean moved by `y₀ = 3` gives the model of the unmoved mean (to the rounding of the
    /// DTFT, `y₀ N ε`), and [`offset_start`] of that model gives back `y₀`.
    #[test]
    fn an_offset_leaves_the_model_and_is_started_from_the_mean() {
        let (u, jitter, grid, m) = exact_mean();
        let moved: Vec<f64> = m.iter().map(|v| v + 3.0).collect();
        let options = InitOptions {
            offset: true,
            ..InitOptions::default()
        };
        let input: Input = u.into();
        let fit = |y: Vec<f64>| {
            let record = Record::new(grid, y).unwrap();
            let g = initial_model(&paper(), &record, &input, Some(&jitter), &options).unwrap();
            (g, record)
        };
        let (plain, _) = fit(m);
        let (g, record) = fit(moved);
        for (a, b) in g.params().iter().zip(plain.params()) {
            assert!(
                (a - b).abs() < 1e-8,
                "{:?} vs {:?}",
                g.params(),
                plain.params()
            );
        }
        for (got, want) in g.params().iter().zip([0.2, -0.5, -0.25, 0.3]) {
            assert!(
                (got - want).abs() < 0.05 * f64::abs(want),
                "{:?}",
                g.params()
            );
        }
        let truth = LtiResponse::new(paper(), input.clone());
        assert!((offset_start(&truth, &record, &jitter) - 3.0).abs() < 1e-12);
        // Without the option the bin f = 0 pulls the model towards the offset.
        let record = Record::new(grid, record.y().to_vec()).unwrap();
        let pulled = initial_model(
            &paper(),
            &record,
            &input,
            Some(&jitter),
            &InitOptions::default(),
        )
        .unwrap();
        let moved_by = (pulled.params()[0] - g.params()[0]).abs();
        assert!(moved_by > 1e-3, "{:?}", pulled.params());
    }
}
