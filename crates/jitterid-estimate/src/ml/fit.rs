//! Maximum-likelihood estimation: [`ml_estimate`] and the integer-`n` profile
//! [`ml_profile_uniform_sum`], with the covariance of the estimate from the inverse Hessian of
//! the negative log-likelihood.

use super::criterion::{LikelihoodCriterion, LikelihoodData};
use super::fisher::gaussian_fisher;
use super::moments::second_moments;
use super::objective::{LikelihoodObjective, Objective, TransformedObjective};
use super::optim::{Brent, MlSolver};
use super::param::{default_transforms, likelihood_param_names, likelihood_params, Layout};
use super::MlError;
use crate::covariance::inverse_gram;
use crate::data::Record;
use crate::noise::NoiseModel;
use crate::solver::{Termination, Transform};
use crate::structure::ModelStructure;
use crate::EstimateError;
use faer::Mat;
use jitterid_jitter::{JitterModel, UniformSum};
use jitterid_signal::Signal;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// How [`ml_estimate`] runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct MlOptions {
    /// The minimiser (default: Brent for one parameter, BFGS otherwise).
    pub solver: MlSolver,
    /// Whether to compute the covariance from the inverse Hessian (default false; set it for
    /// standard errors).
    pub covariance: bool,
    /// Constraints, one per likelihood parameter; default [`default_transforms`].
    pub transforms: Option<Vec<Transform>>,
    /// Start of `σ_v` when it is estimated; default from the residuals' variance minus the
    /// jitter's.
    pub noise_std_start: Option<f64>,
}

/// The result of [`ml_estimate`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MlEstimate {
    /// The criterion's name.
    pub criterion: String,
    /// Names of the likelihood's parameters (the structure's free ones, then `noise.std` when
    /// `σ_v` is estimated).
    pub names: Vec<String>,
    /// `θ̂`.
    pub params: Vec<f64>,
    /// The inverse of the Hessian of `−log L` at `θ̂`, if computed and positive definite.
    pub covariance: Option<Vec<Vec<f64>>>,
    /// Square roots of the covariance's diagonal.
    pub std_errors: Option<Vec<f64>>,
    /// `−log L(θ̂)`.
    pub neg_log_likelihood: f64,
    /// Iterations of the minimiser.
    pub iterations: u64,
    /// Why the minimiser stopped.
    pub termination: Termination,
    /// Whether it met a convergence test.
    pub converged: bool,
    /// The measurement-noise standard deviation at the estimate (known or estimated).
    pub noise_std: f64,
}

impl MlEstimate {
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

/// The default start of `σ_v`: the residuals' mean square minus the jitter's mean variance,
/// floored at `1e-3` of the data's standard deviation.
fn noise_start<S: Signal + Clone, J: JitterModel + Clone, N: NoiseModel>(
    structure: &ModelStructure<S, J, N>,
    record: &Record,
) -> f64 {
    let y = record.y();
    let n = y.len() as f64;
    let mean = y.iter().sum::<f64>() / n;
    let sd = (y.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
    let floor = (1e-3 * sd).max(1e-12);
    match second_moments(structure, record.grid(), 0.0, false) {
        Ok(m) => {
            let ms = y
                .iter()
                .zip(&m.mean)
                .map(|(y, m)| (y - m).powi(2))
                .sum::<f64>()
                / n;
            let jv = m.jitter_variance.iter().sum::<f64>() / n;
            (ms - jv).max(floor * floor).sqrt()
        }
        Err(_) => floor,
    }
}

/// The Hessian of `objective` at `theta` by central differences of its gradient, symmetrised;
/// `None` if a gradient is not finite.
pub(crate) fn hessian<O: Objective + ?Sized>(objective: &O, theta: &[f64]) -> Option<Mat<f64>> {
    let p = theta.len();
    let mut h = Mat::<f64>::zeros(p, p);
    for i in 0..p {
        let step = 1e-4 * theta[i].abs().max(1e-4);
        let mut up = theta.to_vec();
        up[i] += step;
        let mut dn = theta.to_vec();
        dn[i] -= step;
        let (fu, gu) = objective.cost_gradient(&up);
        let (fd, gd) = objective.cost_gradient(&dn);
        let lo_ok = fd.is_finite() && gd.iter().all(|v| v.is_finite());
        let hi_ok = fu.is_finite() && gu.iter().all(|v| v.is_finite());
        let col: Vec<f64> = match (hi_ok, lo_ok) {
            (true, true) => gu
                .iter()
                .zip(&gd)
                .map(|(a, b)| (a - b) / (2.0 * step))
                .collect(),
            (true, false) | (false, true) => {
                let (f0, g0) = objective.cost_gradient(theta);
                if !f0.is_finite() || g0.iter().any(|v| !v.is_finite()) {
                    return None;
                }
                if hi_ok {
                    gu.iter().zip(&g0).map(|(a, b)| (a - b) / step).collect()
                } else {
                    g0.iter().zip(&gd).map(|(a, b)| (a - b) / step).collect()
                }
            }
            (false, false) => return None,
        };
        for j in 0..p {
            h[(j, i)] = col[j];
        }
    }
    let sym = Mat::from_fn(p, p, |i, j| 0.5 * (h[(i, j)] + h[(j, i)]));
    Some(sym)
}

/// The inverse of a symmetric matrix (a Hessian or a Fisher matrix), if it is positive
/// definite, well enough conditioned to invert ([`inverse_gram`]) and the result finite with
/// a positive diagonal.
pub(crate) fn spd_inverse(m: &Mat<f64>) -> Option<Vec<Vec<f64>>> {
    let p = m.nrows();
    let inv = inverse_gram(m)?;
    let out: Vec<Vec<f64>> = (0..p)
        .map(|i| (0..p).map(|j| inv[(i, j)]).collect())
        .collect();
    out.iter()
        .flatten()
        .all(|v| v.is_finite())
        .then_some(out)
        .filter(|o| (0..p).all(|i| o[i][i] > 0.0))
}

/// Estimates the likelihood's parameters (the structure's free parameters, then `σ_v` when
/// the structure does not fix it) by minimising `criterion`'s negative log-likelihood from
/// the structure's current parameters.
///
/// # Errors
///
/// Nothing to estimate; coloured noise with a criterion that needs white noise; a criterion
/// not defined at the start (the typed reason: [`MlError::LikelihoodUnderflow`],
/// [`MlError::VanishingVariance`], [`MlError::ReachExceedsRecord`], …); a start outside the
/// constraints; invalid solver options. A search that stops without converging is not an
/// error: see [`MlEstimate::converged`] and [`MlEstimate::termination`].
pub fn ml_estimate<S, J, N, C>(
    structure: &ModelStructure<S, J, N>,
    record: &Record,
    criterion: &C,
    options: &MlOptions,
) -> Result<MlEstimate, MlError>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: LikelihoodCriterion,
{
    ml_estimate_with(structure, record, None, criterion, options)
}

/// [`ml_estimate`] with optionally prepared data (valid for `structure`'s fixed parts).
fn ml_estimate_with<S, J, N, C>(
    structure: &ModelStructure<S, J, N>,
    record: &Record,
    data: Option<&LikelihoodData>,
    criterion: &C,
    options: &MlOptions,
) -> Result<MlEstimate, MlError>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: LikelihoodCriterion,
{
    let layout = Layout::of(structure);
    let p = layout.len();
    if p == 0 {
        return Err(EstimateError::NothingToEstimate.into());
    }
    if !structure.noise.is_white() && !criterion.supports_coloured_noise() {
        return Err(MlError::ColouredNoise {
            criterion: criterion.name(),
        });
    }
    if record.y().len() < p {
        return Err(EstimateError::TooFewData {
            what: "samples",
            available: record.y().len(),
            params: p,
        }
        .into());
    }
    let sigma0 = match structure.noise_std {
        Some(s) => s,
        None => options
            .noise_std_start
            .unwrap_or_else(|| noise_start(structure, record)),
    };
    let start = likelihood_params(structure, sigma0);
    let objective = match data {
        Some(d) => LikelihoodObjective::with_data(structure, criterion, d.clone()),
        None => LikelihoodObjective::new(structure, criterion, record),
    };
    // The typed reason if the criterion is not defined at the start.
    objective.evaluate(&start)?;
    let transforms = options
        .transforms
        .clone()
        .unwrap_or_else(|| default_transforms(structure));
    let constrained = TransformedObjective::new(&objective, transforms)?;
    let phi0 = constrained.to_internal(&start)?;
    // The metric of BFGS: the inverse of the Gaussian (Slepian–Bangs) information at the start
    // in the unconstrained coordinates, which puts parameters of very different curvature
    // (a frequency and an amplitude) on one scale.
    let metric = if p > 1 {
        gaussian_fisher(structure, record.grid(), sigma0)
            .ok()
            .and_then(|info| {
                let d: Vec<f64> = phi0
                    .iter()
                    .zip(constrained.transforms())
                    .map(|(&f, t)| t.derivative(f))
                    .collect();
                spd_inverse(&Mat::from_fn(p, p, |i, j| d[i] * info.matrix[i][j] * d[j]))
            })
    } else {
        None
    };
    let report = options
        .solver
        .minimize_with_metric(&constrained, &phi0, metric.as_deref())?;
    let params = constrained.to_external(&report.params);
    let (_, sigma) = super::param::split(structure, &params)?;
    let covariance = if options.covariance {
        hessian(&objective, &params).and_then(|h| spd_inverse(&h))
    } else {
        None
    };
    let std_errors = covariance
        .as_ref()
        .map(|c| (0..p).map(|i| c[i][i].sqrt()).collect());
    Ok(MlEstimate {
        criterion: criterion.name().to_string(),
        names: likelihood_param_names(structure),
        params,
        covariance,
        std_errors,
        neg_log_likelihood: report.cost,
        iterations: report.iterations,
        termination: report.termination,
        converged: report.converged,
        noise_std: sigma,
    })
}

/// In the integer-`n` profile of a one-parameter fit, every `n` is first fitted to a loose
/// tolerance (`3e-3` in `ln a`: with a standard error of `ln â` of 0.02 or more, a curvature
/// of `−log L` of at most 2500, that leaves `−log L` within about `1e-2` of its minimum), and
/// only the `n` whose loose minimum is within this margin of the best are refined; the others
/// cannot win (refining lowers a loose minimum by less than its `1e-2` error, so the margin
/// leaves a factor 25). The test `staged_profile_equals_full_refinement` checks the choice
/// against refining every `n`.
pub const PROFILE_MARGIN: f64 = 0.25;

/// The result of [`ml_profile_uniform_sum`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MlProfile {
    /// The winning `n̂`.
    pub n: u32,
    /// The fit at `n̂`.
    pub estimate: MlEstimate,
    /// `−log L` at every `n` tried (`None` where the fit failed to run).
    pub costs: Vec<(u32, Option<f64>)>,
}

impl MlProfile {
    /// `σ̂ = â/√(3(n̂+1))`, if the jitter's `a` was estimated.
    pub fn sigma(&self) -> Option<f64> {
        Some(self.estimate.param("jitter.a")? / (3.0 * (f64::from(self.n) + 1.0)).sqrt())
    }

    /// The standard error of `σ̂` at `n̂` by the delta method (conditional on `n̂`).
    pub fn sigma_std(&self) -> Option<f64> {
        Some(self.estimate.std_error("jitter.a")? / (3.0 * (f64::from(self.n) + 1.0)).sqrt())
    }
}

/// Fits `structure` (whose jitter is a [`UniformSum`]) for every `n` in `ns`, each from the
/// `a` that keeps the structure's jitter standard deviation, in parallel, and returns the
/// converged fit with the largest likelihood (the largest of all if none converged). The
/// covariance, if asked for, is computed for the winner only.
///
/// # Errors
///
/// The first error if no `n` could be fitted.
pub fn ml_profile_uniform_sum<S, N, C>(
    structure: &ModelStructure<S, UniformSum, N>,
    record: &Record,
    criterion: &C,
    options: &MlOptions,
    ns: impl IntoIterator<Item = u32>,
) -> Result<MlProfile, MlError>
where
    S: Signal + Clone,
    N: NoiseModel,
    C: LikelihoodCriterion,
{
    let sigma = structure.jitter.std_dev();
    let ns: Vec<u32> = ns.into_iter().collect();
    let layout = Layout::of(structure);
    // One parameter with the default solver: a coarse pass for every n, then the n that can
    // still win refined (see `PROFILE_MARGIN`).
    let staged = layout.len() == 1 && layout.nj == 1 && options.solver == MlSolver::Auto;
    let inner = MlOptions {
        covariance: false,
        solver: if staged {
            MlSolver::Brent(Brent {
                tolerance: 3e-3,
                ..Brent::default()
            })
        } else {
            options.solver.clone()
        },
        ..options.clone()
    };
    // The record prepared once for all n, for the widest reach of the profile.
    let data = ns.iter().max().and_then(|&n| {
        let a = sigma * (3.0 * (f64::from(n) + 1.0)).sqrt();
        let mut s = structure.clone();
        s.jitter = UniformSum::new(n, a).ok()?;
        Some(criterion.prepare(&s, record))
    });
    let fit_at = |n: u32, a: f64, opts: &MlOptions| {
        UniformSum::new(n, a).map_err(MlError::from).and_then(|j| {
            let mut s = structure.clone();
            s.jitter = j;
            ml_estimate_with(&s, record, data.as_ref(), criterion, opts)
        })
    };
    let mut fits: Vec<(u32, Result<MlEstimate, MlError>)> = ns
        .par_iter()
        .map(|&n| {
            let a = sigma * (3.0 * (f64::from(n) + 1.0)).sqrt();
            (n, fit_at(n, a, &inner))
        })
        .collect();
    if staged {
        let best = fits
            .iter()
            .filter_map(|(_, f)| f.as_ref().ok().filter(|e| e.converged))
            .map(|e| e.neg_log_likelihood)
            .fold(f64::INFINITY, f64::min);
        let fine = MlOptions {
            covariance: false,
            solver: MlSolver::Brent(Brent {
                bracket_step: 0.01,
                ..Brent::default()
            }),
            ..options.clone()
        };
        fits.par_iter_mut().for_each(|(n, fit)| {
            let refine = match fit {
                Ok(e) => !(e.neg_log_likelihood > best + PROFILE_MARGIN),
                Err(_) => false,
            };
            if refine {
                if let Ok(e) = fit {
                    let a = e.params[0];
                    if let Ok(better) = fit_at(*n, a, &fine) {
                        *fit = Ok(better);
                    }
                }
            }
        });
    }
    let mut best: Option<(u32, MlEstimate)> = None;
    let mut costs = Vec::new();
    let mut first_error = None;
    for (n, fit) in fits {
        match fit {
            Ok(e) => {
                costs.push((n, Some(e.neg_log_likelihood)));
                let better = match &best {
                    None => true,
                    Some((_, b)) => {
                        (e.converged && !b.converged)
                            || (e.converged == b.converged
                                && e.neg_log_likelihood < b.neg_log_likelihood)
                    }
                };
                if better {
                    best = Some((n, e));
                }
            }
            Err(err) => {
                costs.push((n, None));
                first_error.get_or_insert(err);
            }
        }
    }
    let Some((n, mut estimate)) = best else {
        return Err(first_error.unwrap_or(EstimateError::NothingToEstimate.into()));
    };
    if options.covariance {
        let mut s = structure.clone();
        let k = layout;
        let theta = estimate.params.clone();
        // Rebuild the winning structure and evaluate the Hessian there.
        let a = if k.nj > 0 {
            theta[k.ns]
        } else {
            sigma * (3.0 * (f64::from(n) + 1.0)).sqrt()
        };
        s.jitter = UniformSum::new(n, a)?;
        let objective = LikelihoodObjective::new(&s, criterion, record);
        estimate.covariance = hessian(&objective, &theta).and_then(|h| spd_inverse(&h));
        estimate.std_errors = estimate
            .covariance
            .as_ref()
            .map(|c| (0..theta.len()).map(|i| c[i][i].sqrt()).collect());
    }
    Ok(MlProfile { n, estimate, costs })
}
