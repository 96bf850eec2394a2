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
//! column at a time, in the same order as the explicit product (bit-identical to it).

use crate::criterion::Criterion;
use crate::finite_diff::{central_difference_vec, MOMENT_FD_STEP};
use crate::frequency_data::FrequencyData;
use crate::noise::NoiseModel;
use crate::solver::NormalEquations;
use crate::structure::ModelStructure;
use faer::Mat;
use jitterid_jitter::{JitterModel, NoJitter};
use jitterid_signal::Signal;
use jitterid_window::Window;

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
