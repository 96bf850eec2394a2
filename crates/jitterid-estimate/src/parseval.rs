//! The normal equations of a frequency-domain criterion without its Jacobian, by Parseval.
//!
//! On the half DFT grid `f_j = j/(NT)`, `0 ≤ j ≤ ⌊N/2⌋`, with the rectangular window and one
//! weight `w` for every frequency, the criterion's Jacobian columns are `−√w [Re A_j, Im A_j]`
//! with `A = DFT(a)` the transform of a time-domain sensitivity `a_k = ∂m_k/∂θ`. For real
//! sequences `a`, `b` the half-grid inner product follows from Parseval's relation and the
//! conjugate symmetry `A_{N−j} = conj A_j`:
//!
//! ```text
//! Σ_{j=0}^{⌊N/2⌋} Re(A_j conj B_j) = ½ (N Σ_k a_k b_k + S(a) S(b) + [N even] Alt(a) Alt(b))
//! ```
//!
//! with `S(a) = Σ_k a_k = A_0` and `Alt(a) = Σ_k (−1)^k a_k = A_{N/2}`. So `JᵀJ` is a sum over
//! samples of the time-domain sensitivities, accumulated sample by sample, and never needs the
//! `2F × p` frequency-domain Jacobian. `Jᵀr` is taken in the frequency domain, one transformed
//! column at a time, in the same order as the explicit product (bit-identical to it), except
//! for long records ([`TIME_DOMAIN_GRADIENT_MIN_SAMPLES`]): there the same identity moves it to
//! time,
//!
//! ```text
//! Σ_{j=0}^{⌊N/2⌋} Re(A_j conj R_j) = Σ_k a_k g_k,   g_k = Re Σ_{j=0}^{⌊N/2⌋} R_j e^{i2πjk/N},
//! ```
//!
//! with `R_j = r_{2j} + i r_{2j+1}` the residuals as a half spectrum: one FFT per evaluation
//! (`g`), none per column, so no column's transform buffers add to the memory of the others.

use crate::criterion::Criterion;
use crate::frequency_data::FrequencyData;
use crate::noise::NoiseModel;
use crate::solver::NormalEquations;
use crate::structure::ModelStructure;
use faer::Mat;
use jitterid_jitter::{JitterModel, NoJitter};
use jitterid_optim::finite_diff::{central_difference_vec, MOMENT_FD_STEP};
use jitterid_signal::Signal;
use jitterid_window::{fft_in_place, Complex64, Window};

/// Records of at least this many samples take `Jᵀr` in the time domain
/// ([`residual_synthesis`], [`time_domain_gradient`]). The frequency-domain product transforms
/// each sensitivity column while the others are live, and its FFT buffer and scratch (32 bytes
/// per sample) set the peak memory of a long fit; the time-domain product needs one FFT of the
/// residual spectrum before any column exists. It rounds differently, so shorter records keep
/// the frequency-domain product, bit-identical to the explicit Jacobian's (the reproduced
/// tables use a few hundred to a thousand samples, whose buffers are well under a MiB).
pub(crate) const TIME_DOMAIN_GRADIENT_MIN_SAMPLES: usize = 1 << 16;

/// The common weight `w` when the criterion on `data` is the half-grid, rectangular-window,
/// equally weighted case that Parseval turns into sums over samples, and its free parameters
/// all act through the first moment `m_k` (no noise-shape parameter in the weights).
pub(crate) fn parseval_weight<S, J, N, C, W>(
    criterion: &C,
    data: &FrequencyData<W>,
    model: &ModelStructure<S, J, N>,
) -> Option<f64>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: Criterion + ?Sized,
    W: Window,
{
    let grid = data.record().grid();
    let n = grid.len();
    let freqs = data.frequencies();
    let half_grid = freqs.dft_indices().is_some_and(|bins| {
        bins.len() == n / 2 + 1 && bins.iter().enumerate().all(|(i, &b)| i == b)
    });
    let (_, _, nn) = model.blocks();
    if !(half_grid && freqs.fits(grid) && data.window().is_rectangular()) {
        return None;
    }
    if (nn > 0 && criterion.uses_noise_model()) || criterion.model_dependent_weights() {
        return None;
    }
    let w = data.weights(criterion, model, None);
    let first = *w.first()?;
    (first.is_finite() && first >= 0.0 && w.iter().all(|&x| x == first)).then_some(first)
}

/// The time-domain sensitivities `∂m_k/∂θ_j` of the criterion's first moment, one column of
/// length `N` per free parameter (analytic for the signal, central differences for the jitter,
/// zero for parameters the first moment does not depend on). A jitter column that cannot be
/// differenced is NaN.
pub(crate) fn moment_sensitivities<S, J, N, C, W>(
    criterion: &C,
    data: &FrequencyData<W>,
    model: &ModelStructure<S, J, N>,
) -> Vec<Vec<f64>>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: Criterion + ?Sized,
    W: Window,
{
    let (ns, _, _) = model.blocks();
    let grid = data.record().grid();
    let signal_cols = if ns == 0 {
        Vec::new()
    } else if criterion.models_jitter() {
        model.signal.expected_values_gradient(grid, &model.jitter)
    } else {
        model.signal.expected_values_gradient(grid, &NoJitter)
    };
    with_other_sensitivities(criterion, data, model, signal_cols)
}

/// The criterion's first moment `m_k` and its [`moment_sensitivities`], the signal's part
/// from one pass over the jitter's expectations (the same numbers as the two separately).
pub(crate) fn moment_and_sensitivities<S, J, N, C, W>(
    criterion: &C,
    data: &FrequencyData<W>,
    model: &ModelStructure<S, J, N>,
) -> (Vec<f64>, Vec<Vec<f64>>)
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: Criterion + ?Sized,
    W: Window,
{
    let (ns, _, _) = model.blocks();
    let grid = data.record().grid();
    let (m, signal_cols) = if ns == 0 {
        (data.first_moment(criterion, model), Vec::new())
    } else if criterion.models_jitter() {
        model
            .signal
            .expected_values_and_gradient(grid, &model.jitter)
    } else {
        model.signal.expected_values_and_gradient(grid, &NoJitter)
    };
    (
        m,
        with_other_sensitivities(criterion, data, model, signal_cols),
    )
}

/// `signal_cols` followed by the jitter's columns (central differences) and the noise
/// shape's (zero: the first moment does not depend on it).
fn with_other_sensitivities<S, J, N, C, W>(
    criterion: &C,
    data: &FrequencyData<W>,
    model: &ModelStructure<S, J, N>,
    signal_cols: Vec<Vec<f64>>,
) -> Vec<Vec<f64>>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: Criterion + ?Sized,
    W: Window,
{
    let (_, nj, nn) = model.blocks();
    let grid = data.record().grid();
    let n = grid.len();
    let mut cols = signal_cols;
    cols.reserve(nj + nn);
    if nj > 0 {
        let theta = model.jitter.params();
        for j in 0..nj {
            let column = if criterion.models_jitter() {
                central_difference_vec(&theta, j, MOMENT_FD_STEP, |p| {
                    let jit = model.jitter.with_params(p).ok()?;
                    Some(model.signal.expected_values(grid, &jit))
                })
                .unwrap_or_else(|| vec![f64::NAN; n])
            } else {
                vec![0.0; n]
            };
            cols.push(column);
        }
    }
    cols.extend((0..nn).map(|_| vec![0.0; n]));
    cols
}

/// `S(a) = Σ a_k` and `Alt(a) = Σ (−1)^k a_k`: the transform at 0 and at the Nyquist bin.
pub(crate) fn edge_bins(a: &[f64]) -> (f64, f64) {
    let mut sum = 0.0;
    let mut alt = 0.0;
    for (k, &x) in a.iter().enumerate() {
        sum += x;
        alt += if k % 2 == 0 { x } else { -x };
    }
    (sum, alt)
}

/// `JᵀJ = w Σ_{j ≤ N/2} Re(A_j conj B_j)` over the sensitivities `cols`, by the module's
/// identity.
pub(crate) fn parseval_gram(cols: &[Vec<f64>], weight: f64) -> Mat<f64> {
    let n = cols.first().map_or(0, Vec::len);
    let edges: Vec<(f64, f64)> = cols.iter().map(|c| edge_bins(c)).collect();
    let even = if n % 2 == 0 { 1.0 } else { 0.0 };
    let p = cols.len();
    let mut g = Mat::zeros(p, p);
    for a in 0..p {
        for b in 0..=a {
            let inner = crate::solver::dot(&cols[a], &cols[b]);
            let v = 0.5
                * weight
                * (n as f64 * inner + edges[a].0 * edges[b].0 + even * edges[a].1 * edges[b].1);
            g[(a, b)] = v;
            g[(b, a)] = v;
        }
    }
    g
}

/// `Jᵀr` with column `a` of `J` the stacked `−√w [Re A_f, Im A_f]` of the transformed
/// sensitivity, one column transformed at a time, each freed before its FFT runs.
fn frequency_gradient<W: Window>(
    data: &FrequencyData<W>,
    cols: Vec<Vec<f64>>,
    weight: f64,
    residuals: &[f64],
) -> Vec<f64> {
    let sw = weight.sqrt();
    cols.into_iter()
        .map(|c| {
            let mu = data.transform_moment(c);
            mu.iter()
                .flat_map(|d| [-sw * d.re, -sw * d.im])
                .zip(residuals)
                .map(|(j, r)| j * r)
                .sum::<f64>()
        })
        .collect()
}

/// `g_k = Re Σ_{j ≤ N/2} R_j e^{i2πjk/N}` for the residuals `r` (length `2(⌊N/2⌋ + 1)`) read as
/// the half spectrum `R_j = r_{2j} + i r_{2j+1}`, `k < n`: the real part of the forward FFT of
/// `conj R`, zero-padded to `n`. NaN residuals give NaN values.
fn residual_synthesis(residuals: &[f64], n: usize) -> Vec<f64> {
    let mut z = vec![Complex64::new(0.0, 0.0); n];
    for (z, r) in z.iter_mut().zip(residuals.chunks_exact(2)) {
        *z = Complex64::new(r[0], -r[1]);
    }
    fft_in_place(&mut z);
    z.iter().map(|z| z.re).collect()
}

/// `Jᵀr` from the sensitivities and the [`residual_synthesis`] `g` of the residuals: the
/// column of `J` for `a` is `−√w [Re A_j, Im A_j]`, so `(Jᵀr)_a = −√w Σ_k a_k g_k`.
fn time_domain_gradient(cols: &[Vec<f64>], g: &[f64], weight: f64) -> Vec<f64> {
    let sw = weight.sqrt();
    cols.iter()
        .map(|c| -sw * crate::solver::dot(c, g))
        .collect()
}

/// `JᵀJ` and `Jᵀr` of `criterion` at `model`, without the `2F × p` Jacobian when the Parseval
/// identity applies (from the sensitivities `known` at `model` when given), from the explicit
/// Jacobian otherwise.
pub(crate) fn criterion_normal_equations<S, J, N, C, W>(
    criterion: &C,
    data: &FrequencyData<W>,
    model: &ModelStructure<S, J, N>,
    residuals: &[f64],
    known: Option<Vec<Vec<f64>>>,
) -> NormalEquations
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: Criterion + ?Sized,
    W: Window,
{
    let p = model.num_params();
    let explicit = || {
        NormalEquations::from_jacobian(&data.jacobian(criterion, model), residuals)
            .unwrap_or_else(|_| NormalEquations::not_finite(p))
    };
    match parseval_weight(criterion, data, model) {
        Some(weight) if residuals.len() == data.num_residuals() => {
            let n = data.record().grid().len();
            if n >= TIME_DOMAIN_GRADIENT_MIN_SAMPLES {
                // The synthesis first: its FFT buffers are freed before the columns exist.
                let g = residual_synthesis(residuals, n);
                let cols = known.unwrap_or_else(|| moment_sensitivities(criterion, data, model));
                return NormalEquations {
                    gram: parseval_gram(&cols, weight),
                    gradient: time_domain_gradient(&cols, &g, weight),
                };
            }
            let cols = known.unwrap_or_else(|| moment_sensitivities(criterion, data, model));
            let gram = parseval_gram(&cols, weight);
            NormalEquations {
                gram,
                gradient: frequency_gradient(data, cols, weight, residuals),
            }
        }
        _ => explicit(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Bcls, Record};
    use jitterid_jitter::Gaussian;
    use jitterid_signal::{simulate, LtiResponse, RandomBinary, Root, SampleGrid, Zpk};
    use jitterid_window::{DirichletWindow, FrequencySet};
    use rand::SeedableRng;

    type Sys = LtiResponse<Zpk>;

    fn eq17(k: f64, z: f64, re: f64, im: f64) -> Zpk {
        Zpk::new(k, vec![Root::Real(-z)], vec![Root::Pair { re, im }]).expect("valid")
    }

    /// A simulated record of `n` samples on the half DFT grid and a structure with the signal
    /// and the Gaussian jitter estimated, started off the truth.
    fn setup(
        n: usize,
        seed: u64,
    ) -> (
        FrequencyData<DirichletWindow>,
        ModelStructure<Sys, Gaussian>,
    ) {
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let u = RandomBinary::paper()
            .generate(0.0, n as f64 + 1.0, &mut rng)
            .expect("input");
        let grid = SampleGrid::new(0.0, 1.0, n).expect("grid");
        let truth = LtiResponse::new(eq17(0.2, 0.5, -0.25, 0.3), u.clone());
        let jitter = Gaussian::new(0.15).expect("jitter");
        let y = simulate(&truth, &jitter, &grid, 0.01, &mut rng)
            .expect("simulate")
            .y;
        let record = Record::new(grid, y).expect("record");
        let data =
            FrequencyData::new(record, DirichletWindow, FrequencySet::dft(&grid)).expect("data");
        let start = LtiResponse::new(eq17(0.21, 0.45, -0.27, 0.33), u);
        let structure = ModelStructure::joe(start, Gaussian::new(0.1).expect("jitter"));
        (data, structure)
    }

    /// `Jᵀr` of the explicit frequency-domain Jacobian (the independent route).
    fn explicit(
        data: &FrequencyData<DirichletWindow>,
        model: &ModelStructure<Sys, Gaussian>,
        r: &[f64],
    ) -> NormalEquations {
        NormalEquations::from_jacobian(&data.jacobian(&Bcls, model), r).expect("explicit")
    }

    /// `|x − y| ≤ 1e-12 max|y|` componentwise: both routes sum the same `N` products of
    /// transformed values in a different order (an FFT of the residuals instead of one per
    /// column), a rounding difference of some `ε log N` relative to the largest term.
    fn assert_close(x: &[f64], y: &[f64], what: &str) {
        let scale = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(scale > 0.0, "{what}: a zero gradient tests nothing");
        for (a, (x, y)) in x.iter().zip(y).enumerate() {
            assert!(
                (x - y).abs() <= 1e-12 * scale,
                "{what}: Jᵀr[{a}] {x} vs {y}"
            );
        }
    }

    #[test]
    fn time_domain_gradient_equals_the_explicit_one() {
        // Even and odd N (the Nyquist bin exists only for even N), short and long.
        for (n, seed) in [(200, 1), (201, 2), (64, 3), (17, 4)] {
            let (data, model) = setup(n, seed);
            let r = data.residuals(&Bcls, &model);
            let weight = parseval_weight(&Bcls, &data, &model).expect("Parseval case");
            let cols = moment_sensitivities(&Bcls, &data, &model);
            let g = residual_synthesis(&r, n);
            let got = time_domain_gradient(&cols, &g, weight);
            assert_close(
                &got,
                &explicit(&data, &model, &r).gradient,
                &format!("N = {n}"),
            );
        }
    }

    #[test]
    fn a_long_record_takes_the_time_domain_gradient() {
        // Odd, just past the threshold: the public route gives the explicit normal equations
        // to rounding, `JᵀJ` to 1e-12 of its largest entry as in the short-record route.
        let n = TIME_DOMAIN_GRADIENT_MIN_SAMPLES + 1;
        let (data, model) = setup(n, 6);
        let r = data.residuals(&Bcls, &model);
        let got = criterion_normal_equations(&Bcls, &data, &model, &r, None);
        let want = explicit(&data, &model, &r);
        assert_close(&got.gradient, &want.gradient, "long record");
        let p = model.num_params();
        let scale = (0..p * p).fold(0.0f64, |m, i| m.max(want.gram[(i / p, i % p)].abs()));
        for a in 0..p {
            for b in 0..p {
                let (x, y) = (got.gram[(a, b)], want.gram[(a, b)]);
                assert!((x - y).abs() <= 1e-12 * scale, "JᵀJ[{a},{b}] {x} vs {y}");
            }
        }
    }

    #[test]
    fn non_finite_residuals_give_a_non_finite_gradient() {
        let g = residual_synthesis(&[1.0, 0.0, f64::NAN, 0.0], 3);
        assert!(g.iter().all(|v| v.is_nan()));
    }
}
