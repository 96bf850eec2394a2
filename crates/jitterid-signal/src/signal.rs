use crate::{SampleGrid, SignalError};
use jitterid_jitter::JitterModel;
use std::fmt;

/// Derivatives of a vector quantity with respect to the parameters: `columns[j][k] = ∂x_k/∂θ_j`.
pub type Jacobian = Vec<Vec<f64>>;

/// A continuous-time signal model `s(t; θ)`, known in the time domain.
///
/// Required: the parameters, `s(t)` and its gradient, and the fastest local rate. Provided:
/// the breakpoints (none), and the jitter expectations `m_k = E[s(t_k + τ)]`, its gradient and
/// `E[s(t_k + τ)²]` by the jitter's quadrature rule, which a model overrides with a faster
/// exact route where it has one (the LTI response does). This is all that simulation and
/// estimation need; the closed-form spectrum, used only by the frequency-integral reference
/// route, is the separate [`Spectrum`](crate::Spectrum) trait.
///
/// The provided expectations use [`JitterModel::rule`] rather than a general-purpose adaptive
/// quadrature: the jitter law may have atoms (two-point, no jitter) and densities with kinks at
/// known points (uniform sums), which the rule places exactly, and the rule is cut at this
/// signal's [`breakpoints`](Self::breakpoints) inside each sample's reach, so every node
/// interval holds an integrand that is analytic. A forgotten breakpoint therefore costs
/// accuracy; `testing::check_contract` catches it.
pub trait Signal: fmt::Debug + Send + Sync {
    /// Names of the parameters `θ`, in order.
    fn param_names(&self) -> Vec<String>;

    /// The current parameters `θ`.
    fn params(&self) -> Vec<f64>;

    /// The same model with parameters `θ`, validated like the constructor.
    fn with_params(&self, params: &[f64]) -> Result<Self, SignalError>
    where
        Self: Sized;

    /// `s(t)`.
    fn value(&self, t: f64) -> f64;

    /// `∂s(t)/∂θ_j` for every parameter, into `grad`.
    fn value_gradient(&self, t: f64, grad: &mut [f64]);

    /// `s(t)`, with `∂s(t)/∂θ_j` into `grad`: what a table of the signal and its gradient
    /// needs at each point. Provided: [`value_gradient`](Self::value_gradient) then
    /// [`value`](Self::value); a model whose two share their work overrides it.
    fn value_and_gradient(&self, t: f64, grad: &mut [f64]) -> f64 {
        self.value_gradient(t, grad);
        self.value(t)
    }

    /// Times where `s` is not analytic (input switches, start and end of the response), in
    /// increasing order.
    fn breakpoints(&self) -> Vec<f64> {
        Vec::new()
    }

    /// Fastest local rate of `s` in 1/s (largest pole modulus, `2πf` of the fastest tone):
    /// sets the resolution of quadrature over the jitter.
    fn rate(&self) -> f64;

    /// Number of parameters.
    fn num_params(&self) -> usize {
        self.params().len()
    }

    /// `m_k = E[s(t_k + τ)]` for every requested instant.
    fn expected_values(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Vec<f64> {
        let breaks = self.breakpoints();
        let (lo, hi) = jitter.reach();
        grid.times()
            .map(|t| {
                // Unfinished once the budget is spent: the caller's budget reports it.
                if jitterid_numeric::budget::spent() {
                    return f64::NAN;
                }
                let rule = jitter.rule(&local_breaks(&breaks, t, lo, hi), self.rate());
                rule.expect(|tau| self.value(t + tau))
            })
            .collect()
    }

    /// `∂m_k/∂θ_j` as columns, one per parameter.
    fn expected_values_gradient(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Jacobian {
        let p = self.num_params();
        let mut cols = vec![vec![0.0; grid.len()]; p];
        let breaks = self.breakpoints();
        let (lo, hi) = jitter.reach();
        let mut g = vec![0.0; p];
        for (k, t) in grid.times().enumerate() {
            if jitterid_numeric::budget::spent() {
                cols.iter_mut().for_each(|c| c[k] = f64::NAN);
                continue;
            }
            let rule = jitter.rule(&local_breaks(&breaks, t, lo, hi), self.rate());
            for (&tau, &w) in rule.nodes.iter().zip(&rule.weights) {
                self.value_gradient(t + tau, &mut g);
                for (col, gj) in cols.iter_mut().zip(&g) {
                    col[k] += w * gj;
                }
            }
        }
        cols
    }

    /// `m_k` and `∂m_k/∂θ_j` together: one pass over the jitter's expectations where a model
    /// shares them between the value and its gradient (the values equal
    /// [`expected_values`](Self::expected_values), the columns
    /// [`expected_values_gradient`](Self::expected_values_gradient)).
    fn expected_values_and_gradient(
        &self,
        grid: &SampleGrid,
        jitter: &dyn JitterModel,
    ) -> (Vec<f64>, Jacobian) {
        (
            self.expected_values(grid, jitter),
            self.expected_values_gradient(grid, jitter),
        )
    }

    /// `E[s(t_k + τ)²]` for every requested instant (for the second moment
    /// `Var y_k = σ_v² + E[s(t_k+τ)²] − m_k²`).
    fn expected_squares(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Vec<f64> {
        let breaks = self.breakpoints();
        let (lo, hi) = jitter.reach();
        grid.times()
            .map(|t| {
                if jitterid_numeric::budget::spent() {
                    return f64::NAN;
                }
                let rule = jitter.rule(&local_breaks(&breaks, t, lo, hi), 2.0 * self.rate());
                rule.expect(|tau| self.value(t + tau).powi(2))
            })
            .collect()
    }
}

/// The breakpoints of `s` (sorted) seen from instant `t` within the jitter's reach `[lo, hi]`,
/// in jitter time `τ = b - t`. Cost `O(log B)` plus the number returned.
pub fn local_breaks(breaks: &[f64], t: f64, lo: f64, hi: f64) -> Vec<f64> {
    let first = breaks.partition_point(|&b| b - t <= lo);
    breaks[first..]
        .iter()
        .map(|b| b - t)
        .take_while(|&tau| tau < hi)
        .collect()
}
