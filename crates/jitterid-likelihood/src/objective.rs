//! The likelihood criteria as [`Objective`]s in the likelihood's parameter vector.

use super::criterion::{GradientRequest, LikelihoodCriterion, LikelihoodData};
use super::param::{split, Layout};
use super::MlError;
use jitterid_estimate::ModelStructure;
use jitterid_estimate::NoiseModel;
use jitterid_jitter::JitterModel;
use jitterid_optim::finite_diff::{partial, LIKELIHOOD_FD_STEP};
use jitterid_optim::Objective;
use jitterid_signal::Signal;
use std::sync::Mutex;

/// Values kept by a [`LikelihoodObjective`]: a fit asks for the value at its start twice (the
/// typed check, then the solver's first step), and a refinement starts where a coarse fit
/// ended, whose value is known. The criterion is deterministic (bit-identical for any number
/// of threads), so a kept value is the value a new evaluation would return.
const KEPT_VALUES: usize = 4;

/// A likelihood criterion on a record as an [`Objective`] in the likelihood's parameter
/// vector ([`likelihood_param_names`](super::likelihood_param_names)): the structure's free
/// parameters, then `σ_v` when it is estimated.
///
/// Gradients: analytic in the signal's parameters and `σ_v`, central differences in the
/// jitter's and the noise shape's.
#[derive(Debug)]
pub struct LikelihoodObjective<'a, S, J, N, C> {
    structure: &'a ModelStructure<S, J, N>,
    criterion: &'a C,
    data: LikelihoodData,
    layout: Layout,
    /// The last few `(θ bits, value)` evaluated or handed over (see [`KEPT_VALUES`]).
    kept: Mutex<Vec<(Vec<u64>, f64)>>,
}

impl<'a, S, J, N, C> LikelihoodObjective<'a, S, J, N, C>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: LikelihoodCriterion,
{
    /// Prepares `record` for `criterion` at parameters of `structure`.
    pub fn new(
        structure: &'a ModelStructure<S, J, N>,
        criterion: &'a C,
        record: &jitterid_estimate::Record,
    ) -> Self {
        LikelihoodObjective {
            structure,
            criterion,
            data: criterion.prepare(structure, record),
            layout: Layout::of(structure),
            kept: Mutex::new(Vec::new()),
        }
    }

    /// Like [`new`](Self::new) with data prepared already (shared between fits of one record).
    pub(crate) fn with_data(
        structure: &'a ModelStructure<S, J, N>,
        criterion: &'a C,
        data: LikelihoodData,
    ) -> Self {
        LikelihoodObjective {
            structure,
            criterion,
            data,
            layout: Layout::of(structure),
            kept: Mutex::new(Vec::new()),
        }
    }

    /// The criterion's value at `theta`, with the reason when it is not defined.
    ///
    /// # Errors
    ///
    /// An invalid parameter vector or any error of the criterion (see [`MlError`]).
    pub fn evaluate(&self, theta: &[f64]) -> Result<f64, MlError> {
        if let Some(v) = self.kept_value(theta) {
            return Ok(v);
        }
        let (model, sigma) = split(self.structure, theta)?;
        let v = self
            .criterion
            .evaluate(&self.data, &model, sigma, GradientRequest::default())?
            .nll;
        self.keep(theta, v);
        Ok(v)
    }

    /// Records that the criterion's value at `theta` is `value` (a value this objective, or
    /// one on the same data and structure, computed), so that it is not evaluated again.
    pub(crate) fn keep(&self, theta: &[f64], value: f64) {
        let key: Vec<u64> = theta.iter().map(|v| v.to_bits()).collect();
        let mut kept = self.kept.lock().unwrap_or_else(|e| e.into_inner());
        if kept.iter().any(|(k, _)| *k == key) {
            return;
        }
        if kept.len() == KEPT_VALUES {
            kept.remove(0);
        }
        kept.push((key, value));
    }

    /// The kept value at exactly `theta`, if any.
    fn kept_value(&self, theta: &[f64]) -> Option<f64> {
        let kept = self.kept.lock().unwrap_or_else(|e| e.into_inner());
        kept.iter()
            .find(|(k, _)| {
                k.len() == theta.len() && k.iter().zip(theta).all(|(b, v)| *b == v.to_bits())
            })
            .map(|&(_, v)| v)
    }

    /// The prepared data.
    pub fn data(&self) -> &LikelihoodData {
        &self.data
    }
}

impl<S, J, N, C> Objective for LikelihoodObjective<'_, S, J, N, C>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: LikelihoodCriterion,
{
    fn num_params(&self) -> usize {
        self.layout.len()
    }

    fn cost(&self, theta: &[f64]) -> f64 {
        match self.evaluate(theta) {
            Ok(v) if v.is_finite() => v,
            _ => f64::INFINITY,
        }
    }

    fn cost_gradient(&self, theta: &[f64]) -> (f64, Vec<f64>) {
        let nan = || (f64::INFINITY, vec![f64::NAN; theta.len()]);
        let Ok((model, sigma)) = split(self.structure, theta) else {
            return nan();
        };
        let l = self.layout;
        let request = GradientRequest {
            signal: l.ns > 0,
            noise_std: l.sigma,
        };
        let Ok(ev) = self.criterion.evaluate(&self.data, &model, sigma, request) else {
            return nan();
        };
        if !ev.nll.is_finite() {
            return nan();
        }
        let mut g = vec![0.0; l.len()];
        if let Some(gs) = &ev.signal_gradient {
            g[..l.ns].copy_from_slice(gs);
        }
        for j in l.jitter_range().chain(l.noise_range()) {
            g[j] = partial(|p| self.cost(p), theta, j, ev.nll, LIKELIHOOD_FD_STEP);
        }
        if let (Some(i), Some(d)) = (l.sigma_index(), ev.noise_std_gradient) {
            g[i] = d;
        }
        (ev.nll, g)
    }
}
