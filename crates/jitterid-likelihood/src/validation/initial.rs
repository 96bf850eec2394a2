//! `fit_initial_state`: a record's own initial state for a model fitted on another record.

use faer::Mat;
use jitterid_estimate::{EstimateError, ModelStructure, NoiseModel};
use jitterid_jitter::JitterModel;
use jitterid_signal::registry::SignalRegistry;
pub use jitterid_signal::INITIAL_PREFIX;
use jitterid_signal::{AnySignal, Input, SampleGrid, Signal};

/// Singular values below this fraction of the largest are dropped: directions of the initial
/// state that the record cannot see (a mode that has decayed before the first sample).
const RANK_TOL: f64 = 1e-10;

/// The structure with its free-response coefficients (the signal's parameters named
/// `initial.*`) re-estimated on the record `y`, every other parameter held.
///
/// A validation record starts from its own unknown state, not from the estimation record's,
/// so [`compare`](super::compare) on it needs that state estimated, as in any prediction-error
/// toolbox's comparison. The expected samples are affine in the coefficients (the free
/// response is linear in them and the jitter's expectation is linear), so the least-squares
/// coefficients are exact: `m(q) = m(0) + B q` with the columns of `B` from `m(e_j) − m(0)`,
/// and `q̂` minimises `‖y − m(q)‖²` by a truncated singular value decomposition (directions
/// the record cannot see, singular values under `1e-10` of the largest, are left at zero).
/// A signal without `initial.*` parameters is returned unchanged.
///
/// Errors: `y` of another length than the grid or not finite; a signal that rejects the
/// coefficients.
pub fn fit_initial_state<S, J, N>(
    structure: &ModelStructure<S, J, N>,
    grid: &SampleGrid,
    y: &[f64],
) -> Result<ModelStructure<S, J, N>, EstimateError>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel + Clone,
{
    if y.len() != grid.len() {
        return Err(EstimateError::DataLength {
            expected: grid.len(),
            got: y.len(),
        });
    }
    if let Some(k) = y.iter().position(|v| !v.is_finite()) {
        return Err(EstimateError::NonFiniteData {
            index: k,
            value: y[k],
        });
    }
    let free: Vec<usize> = structure
        .signal
        .param_names()
        .iter()
        .enumerate()
        .filter(|(_, n)| n.starts_with(INITIAL_PREFIX))
        .map(|(i, _)| i)
        .collect();
    if free.is_empty() {
        return Ok(structure.clone());
    }
    let mut theta = structure.signal.params();
    let at = |theta: &[f64]| -> Result<Vec<f64>, EstimateError> {
        let s = structure.signal.with_params(theta)?;
        Ok(s.expected_values(grid, &structure.jitter))
    };
    for &i in &free {
        theta[i] = 0.0;
    }
    let base = at(&theta)?;
    let mut b = Mat::<f64>::zeros(y.len(), free.len());
    for (c, &i) in free.iter().enumerate() {
        theta[i] = 1.0;
        let m = at(&theta)?;
        theta[i] = 0.0;
        for (r, (m, m0)) in m.iter().zip(&base).enumerate() {
            b[(r, c)] = m - m0;
        }
    }
    let rhs: Vec<f64> = y.iter().zip(&base).map(|(y, m0)| y - m0).collect();
    for (&i, q) in free.iter().zip(min_norm_lstsq(&b, &rhs)) {
        theta[i] = q;
    }
    let mut out = structure.clone();
    out.signal = structure.signal.with_params(&theta)?;
    Ok(out)
}

/// The minimum-norm least-squares solution of `a x ≈ b` over the singular values above
/// [`RANK_TOL`] of the largest (zero when `a` is zero or not finite).
fn min_norm_lstsq(a: &Mat<f64>, b: &[f64]) -> Vec<f64> {
    let k = a.ncols();
    let mut x = vec![0.0; k];
    let finite = (0..a.nrows()).all(|i| (0..k).all(|j| a[(i, j)].is_finite()));
    let Some(svd) = finite.then(|| a.thin_svd().ok()).flatten() else {
        return x;
    };
    let s = svd.S().column_vector();
    let (u, v) = (svd.U(), svd.V());
    let smax = (0..k).map(|i| s[i]).fold(0.0, f64::max);
    for i in (0..k).filter(|&i| s[i] > RANK_TOL * smax) {
        let c = (0..a.nrows()).map(|r| u[(r, i)] * b[r]).sum::<f64>() / s[i];
        for (j, xj) in x.iter_mut().enumerate() {
            *xj += v[(j, i)] * c;
        }
    }
    x
}

/// A fitted structure carried over to another record `y` on `grid`: its signal driven by
/// `input` (the fitted one's input when `None`) and, for a signal with a free response, that
/// response's time origin moved to the record's first requested instant and its coefficients
/// re-estimated on the record ([`fit_initial_state`]); every other parameter (system, delay,
/// jitter, noise) is held. This is how a model fitted on one record is compared on another.
///
/// # Errors
///
/// Those of the signal registry rebuilding the signal with the new input (a kind that takes
/// no such input, say) and those of [`fit_initial_state`].
pub fn on_record<J, N>(
    fitted: &ModelStructure<AnySignal, J, N>,
    grid: &SampleGrid,
    y: &[f64],
    input: Option<&Input>,
) -> Result<ModelStructure<AnySignal, J, N>, EstimateError>
where
    J: JitterModel + Clone,
    N: NoiseModel + Clone,
{
    let mut spec = fitted.signal.spec();
    let free = spec.contains_key("initial");
    if !free && input.is_none() {
        return Ok(fitted.clone());
    }
    if free {
        spec.insert("origin".into(), serde_json::json!(grid.time(0)));
    }
    let mut carried = fitted.clone();
    carried.signal = SignalRegistry::builtin().build(&spec, input)?;
    if !free {
        return Ok(carried);
    }
    fit_initial_state(&carried, grid, y)
}
