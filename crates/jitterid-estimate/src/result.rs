//! The one result type of every estimator: [`Fit`].

use crate::FitTermination;
use serde::{Deserialize, Serialize};

/// What [`Fit::cost`] measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CostKind {
    /// `½ Σ rᵢ²` of a first-moment criterion.
    SumOfSquares,
    /// `−log L` of a likelihood criterion (including all constants).
    NegLogLikelihood,
}

/// An estimate: the free parameters by name, their standard errors and covariance, the final
/// value of the criterion and how the solver stopped. Returned by [`fit`](crate::fit) for
/// every criterion (first-moment and likelihood alike) and by the profiles.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Fit {
    /// The criterion's name.
    pub criterion: String,
    /// Names of the estimated parameters (jitter and noise-shape parameters prefixed `jitter.`
    /// and `noise.`; the likelihoods' estimated noise level is `noise.std`).
    pub names: Vec<String>,
    /// `θ̂`, in the order of [`names`](Self::names).
    pub params: Vec<f64>,
    /// Standard errors, the square roots of the covariance's diagonal.
    pub std_errors: Option<Vec<f64>>,
    /// Asymptotic covariance of `θ̂`, if computed and defined: the sandwich form for the
    /// first-moment criteria, the inverse Hessian of `−log L` for the likelihoods.
    pub covariance: Option<Vec<Vec<f64>>>,
    /// The criterion at `θ̂` ([`cost_kind`](Self::cost_kind) says which).
    pub cost: f64,
    /// What [`cost`](Self::cost) measures.
    pub cost_kind: CostKind,
    /// Solver iterations.
    pub iterations: u64,
    /// Why the solver stopped.
    pub termination: FitTermination,
    /// Whether the solver met a convergence test (and, for criteria with flat residuals, the
    /// residual spectrum passed [`residual_flatness`](crate::residual_flatness)).
    pub converged: bool,
    /// The measurement-noise standard deviation at `θ̂` (known or estimated).
    pub noise_std: f64,
    /// Final residuals of a first-moment criterion (empty for the likelihoods).
    #[serde(default)]
    pub residuals: Vec<f64>,
    /// [`residual_flatness`](crate::residual_flatness) of the final residuals, for criteria
    /// whose residuals are flat at the truth ([`Criterion::flat_residuals`](crate::Criterion))
    /// and frequency sets large enough for a verdict: about 1–1.6 at a good fit; above
    /// [`FLATNESS_LIMIT`](crate::FLATNESS_LIMIT) the fit is reported as not converged.
    #[serde(default)]
    pub residual_flatness: Option<f64>,
}

impl Fit {
    /// The estimate of the parameter called `name`, if any.
    pub fn param(&self, name: &str) -> Option<f64> {
        Some(self.params[self.names.iter().position(|n| n == name)?])
    }

    /// The standard error of the parameter called `name`, if computed.
    pub fn std_error(&self, name: &str) -> Option<f64> {
        let i = self.names.iter().position(|n| n == name)?;
        Some(self.std_errors.as_ref()?[i])
    }
}
