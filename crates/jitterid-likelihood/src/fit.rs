//! Maximum-likelihood estimation: [`ml_estimate`] and the integer profile [`ml_profile`],
//! with the covariance of the estimate from the inverse Hessian of the negative
//! log-likelihood. They are what [`fit`](jitterid_estimate::fit) and
//! [`fit_profile`](jitterid_estimate::fit_profile) run for a likelihood (see
//! `fit_criterion.rs`), with the solver and window as types.

use super::criterion::{LikelihoodCriterion, LikelihoodData};
use super::fisher::{gaussian_fisher, spd_inverse};
use super::moments::second_moments;
use super::objective::LikelihoodObjective;
use super::param::{default_transforms, likelihood_param_names, likelihood_params, Layout};
use super::MlError;
use faer::Mat;
use jitterid_estimate::solver::{
    AnySolver, Brent, BrentOrBfgs, ObjectiveSolver, ProgressHook, Transform,
};
use jitterid_estimate::support::{best_of, fitted_jitter};
use jitterid_estimate::EstimateError;
use jitterid_estimate::ModelStructure;
use jitterid_estimate::NoiseModel;
use jitterid_estimate::Profile;
use jitterid_estimate::Record;
use jitterid_estimate::{CostKind, Fit};
use jitterid_jitter::JitterModel;
use jitterid_optim::finite_diff::hessian;
use jitterid_optim::TransformedObjective;
use jitterid_optim::{Objective, WithMetric};
use jitterid_signal::Signal;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::any::Any;

/// How [`ml_estimate`] runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(crate) struct MlOptions<V = BrentOrBfgs> {
    /// The minimiser (default: Brent for one parameter, BFGS otherwise, with the inverse of
    /// the Gaussian information at the start as BFGS's first metric).
    pub solver: V,
    /// Whether to compute the covariance from the inverse Hessian (default false; set it for
    /// standard errors).
    pub covariance: bool,
    /// Constraints, one per likelihood parameter; default [`default_transforms`].
    pub transforms: Option<Vec<Transform>>,
    /// Start of `σ_v` when it is estimated; default from the residuals' variance minus the
    /// jitter's.
    pub noise_std_start: Option<f64>,
}

impl Default for MlOptions {
    fn default() -> Self {
        MlOptions {
            solver: BrentOrBfgs::default(),
            covariance: false,
            transforms: None,
            noise_std_start: None,
        }
    }
}

impl<V> MlOptions<V> {
    /// The same options with another solver.
    pub(crate) fn with_solver<U>(&self, solver: U) -> MlOptions<U> {
        MlOptions {
            solver,
            covariance: self.covariance,
            transforms: self.transforms.clone(),
            noise_std_start: self.noise_std_start,
        }
    }
}

/// The default start of `σ_v`: the root of the score in `σ_v²` of the likelihood of
/// independent samples `y_k ~ N(m_k, σ_v² + v_k)` (the start's mean `m_k` and jitter variance
/// `v_k`, correlations left out), floored at `1e-3` of the data's standard deviation.
///
/// Why not the residuals' mean square minus the jitter's mean variance: where the jitter's
/// variance dominates (steep stretches after every input switch), that difference is the small
/// `σ_v²` minus a sampling fluctuation of the large jitter part, negative in many records. The
/// start then sat on the floor, the likelihood there was six orders of magnitude off its
/// optimum, and the first quasi-Newton steps threw the search into a region with `σ_v` near
/// `10¹¹¹` that it reported as converged. The score weights each sample by `1/(σ_v² + v_k)²`,
/// so the settled stretches, where `v_k` is small, decide `σ_v`.
fn noise_start<S: Signal + Clone, J: JitterModel + Clone, N: NoiseModel>(
    structure: &ModelStructure<S, J, N>,
    record: &Record,
) -> f64 {
    let y = record.y();
    let n = y.len() as f64;
    let mean = y.iter().sum::<f64>() / n;
    let sd = (y.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
    let floor = (1e-3 * sd).max(1e-12);
    let Ok(m) = second_moments(structure, record.grid(), 0.0, false) else {
        return floor;
    };
    let squares: Vec<f64> = y
        .iter()
        .zip(&m.mean)
        .map(|(y, m)| (y - m).powi(2))
        .collect();
    diagonal_noise_variance(&squares, &m.jitter_variance, floor * floor, sd * sd).sqrt()
}

/// The root in `s ∈ [lo, hi]` of `Σ (r_k − s − v_k)/(s + v_k)²`, the score of
/// `Σ log N(r_k; s + v_k)` (`r_k` squared residuals, `v_k` the jitter's variances), by
/// bisection on `log s`: `lo` when the score is already negative there, `hi` when it is still
/// positive at `hi`.
fn diagonal_noise_variance(squares: &[f64], jitter: &[f64], lo: f64, hi: f64) -> f64 {
    let score = |s: f64| -> f64 {
        squares
            .iter()
            .zip(jitter)
            .map(|(r, v)| {
                let t = s + v.max(0.0);
                (r - t) / (t * t)
            })
            .sum()
    };
    let hi = hi.max(lo);
    if !(score(lo) > 0.0) {
        return lo;
    }
    if score(hi) > 0.0 {
        return hi;
    }
    let (mut a, mut b) = (lo.ln(), hi.ln());
    // 60 halvings of at most ~60 e-folds leave a relative width below 1e-15.
    for _ in 0..60 {
        let c = 0.5 * (a + b);
        if score(c.exp()) > 0.0 {
            a = c;
        } else {
            b = c;
        }
    }
    (0.5 * (a + b)).exp()
}

/// Estimates the likelihood's parameters (the structure's free parameters, then `σ_v` when
/// the structure does not fix it) by minimising `criterion`'s negative log-likelihood from
/// the structure's current parameters.
///
/// # Errors
///
/// Nothing to estimate; constant data ([`EstimateError::ConstantData`]); coloured noise with a
/// criterion that needs white noise; a criterion
/// not defined at the start (the typed reason: [`MlError::LikelihoodUnderflow`],
/// [`MlError::VanishingVariance`], [`MlError::ReachExceedsRecord`], …); a start outside the
/// constraints; invalid solver options. A search that stops without converging is not an
/// error: see [`Fit::converged`] and [`Fit::termination`].
pub(crate) fn ml_estimate<S, J, N, C, V>(
    structure: &ModelStructure<S, J, N>,
    record: &Record,
    criterion: &C,
    options: &MlOptions<V>,
) -> Result<Fit, MlError>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: LikelihoodCriterion,
    V: ObjectiveSolver,
{
    ml_estimate_with(structure, record, None, None, criterion, options)
}

/// [`ml_estimate`] with optionally prepared data (valid for `structure`'s fixed parts) and
/// optionally a value of the criterion already known (`(θ, −log L)`, computed on the same
/// data), which is then not evaluated again.
fn ml_estimate_with<S, J, N, C, V>(
    structure: &ModelStructure<S, J, N>,
    record: &Record,
    data: Option<&LikelihoodData>,
    known: Option<(&[f64], f64)>,
    criterion: &C,
    options: &MlOptions<V>,
) -> Result<Fit, MlError>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: LikelihoodCriterion,
    V: ObjectiveSolver,
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
    // Checked before the search: on constant data the likelihood has no interior optimum
    // (σ_v and the system's gain drift towards zero), and the search would run to its budget.
    if let Some(&value) = record.y().first() {
        if record.y().iter().all(|&y| y == value) {
            return Err(EstimateError::ConstantData { value }.into());
        }
    }
    let sigma0 = match structure.noise_std {
        Some(s) => s,
        None => options
            .noise_std_start
            .unwrap_or_else(|| noise_start(structure, record)),
    };
    let start = likelihood_params(structure, sigma0);
    // A budget spent already leaves the start unevaluated: the fit stops there, as a solver
    // would at its first check (see the least-squares `estimate`).
    if let Some(stop) = jitterid_optim::budget_termination() {
        return Ok(Fit {
            criterion: criterion.name().to_string(),
            names: likelihood_param_names(structure),
            params: start,
            covariance: None,
            std_errors: None,
            cost: f64::NAN,
            cost_kind: CostKind::NegLogLikelihood,
            iterations: 0,
            termination: stop.into(),
            converged: false,
            noise_std: sigma0,
            residuals: Vec::new(),
            residual_flatness: None,
        });
    }
    let objective = match data {
        Some(d) => LikelihoodObjective::with_data(structure, criterion, d.clone()),
        None => LikelihoodObjective::new(structure, criterion, record),
    };
    if let Some((theta, value)) = known {
        objective.keep(theta, value);
    }
    let transforms = options
        .transforms
        .clone()
        .unwrap_or_else(|| default_transforms(structure));
    let constrained = TransformedObjective::new(&objective, transforms);
    // The typed reason if the criterion is not defined at the start, checked where the solver
    // first evaluates it (the start through the transforms and back, which can differ from
    // `start` in the last bit), so that the solver's first value is the kept one.
    let solver_start = constrained
        .as_ref()
        .ok()
        .and_then(|c| c.to_internal(&start).ok().map(|phi| c.to_external(&phi)))
        .filter(|t| t.iter().all(|v| v.is_finite()));
    objective.evaluate(solver_start.as_deref().unwrap_or(&start))?;
    let constrained = constrained?;
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
    let problem = WithMetric::new(&constrained, metric);
    let report = options.solver.minimize(&problem as &dyn Objective, &phi0)?;
    let params = constrained.to_external(&report.params);
    let (_, sigma) = super::param::split(structure, &params)?;
    let covariance = if options.covariance && !jitterid_numeric::budget::spent() {
        hessian(&objective, &params).and_then(|h| spd_inverse(&h))
    } else {
        None
    };
    // A budget spent in the search or the Hessian leaves the fit unfinished: its point is
    // reported, not converged, with the reason and without a covariance.
    let stopped = jitterid_optim::budget_termination();
    let covariance = covariance.filter(|_| stopped.is_none());
    let std_errors = covariance
        .as_ref()
        .map(|c| (0..p).map(|i| c[i][i].sqrt()).collect());
    Ok(Fit {
        criterion: criterion.name().to_string(),
        names: likelihood_param_names(structure),
        params,
        covariance,
        std_errors,
        cost: report.cost,
        cost_kind: CostKind::NegLogLikelihood,
        iterations: report.iterations,
        converged: report.converged && stopped.is_none(),
        termination: stopped.unwrap_or(report.termination).into(),
        noise_std: sigma,
        residuals: Vec::new(),
        residual_flatness: None,
    })
}

/// In the integer-`n` profile of a one-parameter fit, every `n` is first fitted loosely: to
/// `3e-3` in `ln a`, or until the parabola through the search's three best points predicts
/// less than `1e-3` of further decrease (with a standard error of `ln â`
/// of 0.02 or more, a curvature of `−log L` of at most 2500, either leaves `−log L` within
/// about `1e-2` of its minimum), and only the `n` whose loose minimum is within this margin of
/// the best are refined; the others cannot win (refining lowers a loose minimum by less than
/// its `1e-2` error, so the margin leaves a factor 10; the true winner is refined whenever its
/// loose value is within the margin of its minimum). The test
/// `staged_profile_equals_full_refinement` checks the choice against refining every `n`, and
/// that every loose minimum is within a tenth of the margin of the minimum. (0.25 until the
/// Table 1 reproduction showed the same figures at 0.1: where many `n` are nearly as likely,
/// each within the margin costs a refinement.)
pub const PROFILE_MARGIN: f64 = 0.1;

/// The first pass of the profile also stops when the parabola through its three best points
/// predicts a further decrease of `−log L` below this ([`Brent::cost_tolerance`]): near the
/// minimum, where the parabola is the function to within its cubic term, the value is then
/// known to about this much, and the point well enough to start the refinement.
const COARSE_COST_TOLERANCE: f64 = 1e-3;

/// First bracketing step (in the transformed parameter) of a first-pass fit started from the
/// previous value's fit: neighbouring `n` put `σ̂` within a few per cent of each other, so
/// the bracket closes in its first three points and the parabola through them is close to the
/// function.
const WARM_BRACKET_STEP: f64 = 0.03;

/// The tolerance of `solver`'s Brent stage if `solver` is the default likelihood solver up
/// to that tolerance (the profile's coarse-then-refine schedule replaces it for
/// one-parameter fits, and refines to that tolerance).
fn staged_tolerance<V: Any>(solver: &V) -> Option<f64> {
    as_default(solver)
        .filter(|s| {
            // A progress hook only observes: it does not make the solver another one.
            let mut plain = (*s).clone();
            plain.brent.progress = None;
            plain.bfgs.progress = None;
            plain.brent.tolerance = Brent::default().tolerance;
            plain == BrentOrBfgs::default()
        })
        .map(|s| s.brent.tolerance)
}

/// The progress hook of the default solver's Brent stage, handed on to the staged profile's
/// own Brent solvers.
fn brent_hook<V: Any>(solver: &V) -> Option<ProgressHook> {
    as_default(solver).and_then(|s| s.brent.progress.clone())
}

/// `solver` as the default likelihood solver, if it is one: by its type, or behind the
/// run-time [`AnySolver`] that [`fit`](jitterid_estimate::fit) hands on.
fn as_default<V: Any>(solver: &V) -> Option<&BrentOrBfgs> {
    let any = solver as &dyn Any;
    any.downcast_ref::<BrentOrBfgs>().or_else(|| {
        any.downcast_ref::<AnySolver>()?
            .downcast_ref::<BrentOrBfgs>()
    })
}

/// Fits `structure` with its jitter replaced by `build(v)` for every `v` in `values` and
/// returns the converged fit with the largest likelihood (the largest of all if
/// none converged). `build` makes the start jitter of a value (see
/// [`fit_profile`](jitterid_estimate::fit_profile)). The covariance, if asked for, is computed for the winner only.
///
/// With the default solver (whatever the tolerance of its Brent stage) and a single free
/// parameter (the jitter's), every value is first fitted loosely, on the criterion's
/// [`screening`](LikelihoodCriterion::screening) form if it has one, in order, each value after the first started where the previous fit put
/// the jitter's standard deviation (its parameter scaled by the ratio of fitted to start
/// standard deviations: exact for a scale parameter such as the uniform sum's `a`), and only
/// those within [`PROFILE_MARGIN`] of the best are refined, in parallel, on the criterion
/// itself to the Brent stage's tolerance; both stages run
/// Brent's iterations from their brackets' known values ([`Brent::from_bracket`]). With other
/// solvers or more parameters every value is fitted once, in parallel. The likelihood's
/// evaluations are themselves shared among threads.
///
/// # Errors
///
/// The first error if no value could be fitted (including errors of `build`).
pub(crate) fn ml_profile<S, J, N, C, V, E>(
    structure: &ModelStructure<S, J, N>,
    record: &Record,
    criterion: &C,
    options: &MlOptions<V>,
    values: impl IntoIterator<Item = i64>,
    build: impl Fn(i64) -> Result<J, E> + Sync,
) -> Result<Profile<J>, MlError>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: LikelihoodCriterion,
    V: ObjectiveSolver + Any + Clone + Sync,
    E: Into<MlError>,
{
    let values: Vec<i64> = values.into_iter().collect();
    let layout = Layout::of(structure);
    // One parameter with the default solver: a coarse pass for every value, then the values
    // that can still win refined (see `PROFILE_MARGIN`).
    // The refinement's tolerance when the profile is staged.
    let staged = staged_tolerance(&options.solver).filter(|_| layout.len() == 1 && layout.nj == 1);
    let at = |v: i64| -> Result<ModelStructure<S, J, N>, MlError> {
        let mut s = structure.clone();
        s.jitter = build(v).map_err(Into::into)?;
        Ok(s)
    };
    // The record prepared once for all values, for the widest reach of the profile.
    let data = values
        .iter()
        .filter_map(|&v| at(v).ok())
        .max_by(|a, b| {
            let width = |s: &ModelStructure<S, J, N>| {
                let (lo, hi) = s.jitter.reach();
                hi - lo
            };
            width(a).total_cmp(&width(b))
        })
        .map(|s| criterion.prepare(&s, record));
    let coarse = MlOptions {
        covariance: false,
        ..options.with_solver(Brent {
            tolerance: 3e-3,
            cost_tolerance: COARSE_COST_TOLERANCE,
            progress: brent_hook(&options.solver),
            from_bracket: true,
            ..Brent::default()
        })
    };
    let plain = MlOptions {
        covariance: false,
        ..options.clone()
    };
    // The first pass on the criterion's screening form, if it has one (its minima are only
    // compared with the margin), the refinement on the criterion itself.
    let screening = criterion.screening();
    let screen = screening.as_ref().unwrap_or(criterion);
    let fit_with = |s: &ModelStructure<S, J, N>,
                    staged_solver: Option<&MlOptions<Brent>>,
                    known: Option<(&[f64], f64)>,
                    by: &C| match staged_solver {
        Some(o) => ml_estimate_with(s, record, data.as_ref(), known, by, o),
        None => ml_estimate_with(s, record, data.as_ref(), known, by, &plain),
    };
    let mut fits: Vec<(i64, Result<Fit, MlError>)> = if staged.is_some() {
        // In order, each value after the first started where the previous fit put the
        // jitter's standard deviation, with a narrower bracket.
        let warm = MlOptions {
            covariance: false,
            ..options.with_solver(Brent {
                bracket_step: WARM_BRACKET_STEP,
                ..coarse.solver.clone()
            })
        };
        let mut ratio: Option<f64> = None;
        let mut out = Vec::with_capacity(values.len());
        for &v in &values {
            let fit = at(v).and_then(|s| {
                let started = ratio.and_then(|r| {
                    let p = s.params();
                    (p.len() == 1)
                        .then(|| s.with_params(&[p[0] * r]).ok())
                        .flatten()
                });
                match &started {
                    Some(w) => fit_with(w, Some(&warm), None, screen),
                    None => fit_with(&s, Some(&coarse), None, screen),
                }
                .map(|f| (f, s))
            });
            ratio = match &fit {
                Ok((f, s)) if f.converged => fitted_jitter(s, s.jitter.clone(), f)
                    .ok()
                    .map(|j| j.std_dev() / s.jitter.std_dev())
                    .filter(|r| r.is_finite() && *r > 0.0),
                _ => None,
            };
            out.push((v, fit.map(|(f, _)| f)));
        }
        out
    } else {
        let budget = jitterid_numeric::budget::current();
        values
            .par_iter()
            .map(|&v| {
                jitterid_numeric::budget::run_with(budget.clone(), || {
                    (v, at(v).and_then(|s| fit_with(&s, None, None, criterion)))
                })
            })
            .collect()
    };
    if let Some(tolerance) = staged {
        let best = fits
            .iter()
            .filter_map(|(_, f)| f.as_ref().ok().filter(|e| e.converged))
            .map(|e| e.cost)
            .fold(f64::INFINITY, f64::min);
        let fine = options.with_solver(Brent {
            bracket_step: 0.01,
            tolerance,
            progress: brent_hook(&options.solver),
            from_bracket: true,
            ..Brent::default()
        });
        let fine = MlOptions {
            covariance: false,
            ..fine
        };
        let budget = jitterid_numeric::budget::current();
        fits.par_iter_mut().for_each(|(v, fit)| {
            jitterid_numeric::budget::run_with(budget.clone(), || {
                let refine = match fit {
                    Ok(e) => !(e.cost > best + PROFILE_MARGIN),
                    Err(_) => false,
                };
                if refine {
                    if let Ok(e) = fit {
                        // Restart from the coarse minimum, whose value is known if the first
                        // pass was on the criterion itself.
                        let known = (screening.is_none() && e.cost.is_finite())
                            .then_some((e.params.as_slice(), e.cost));
                        let refined = at(*v).and_then(|s| {
                            let s = s.with_params(&e.params).map_err(MlError::from)?;
                            fit_with(&s, Some(&fine), known, criterion)
                        });
                        if let Ok(better) = refined {
                            *fit = Ok(better);
                        }
                    }
                }
            })
        });
    }
    let (best, costs, first_error) = best_of(fits);
    let Some((value, mut estimate)) = best else {
        return Err(first_error.unwrap_or(EstimateError::NothingToEstimate.into()));
    };
    let start = at(value)?;
    if options.covariance {
        // The Hessian at the winner, in the likelihood's parameters.
        let theta = estimate.params.clone();
        let objective = LikelihoodObjective::new(&start, criterion, record);
        estimate.covariance = hessian(&objective, &theta).and_then(|h| spd_inverse(&h));
        if let Some(stop) = jitterid_optim::budget_termination() {
            estimate.covariance = None;
            estimate.converged = false;
            estimate.termination = stop.into();
        }
        estimate.std_errors = estimate
            .covariance
            .as_ref()
            .map(|c| (0..theta.len()).map(|i| c[i][i].sqrt()).collect());
    }
    let jitter = fitted_jitter(&start, start.jitter.clone(), &estimate)?;
    Ok(Profile {
        value,
        jitter,
        estimate,
        costs,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ExactMl;
    use jitterid_jitter::UniformSum;
    use jitterid_signal::{simulate, LtiResponse, RandomBinary, Root, SampleGrid, Zpk};
    use rand::rngs::StdRng;
    use rand::SeedableRng;

    /// Without jitter the score's root is the mean square, exactly.
    #[test]
    fn the_noise_start_without_jitter_is_the_mean_square() {
        let r = [0.5, 2.0, 1.25, 0.25];
        let s = diagonal_noise_variance(&r, &[0.0; 4], 1e-9, 10.0);
        assert!((s - 1.0).abs() < 1e-12, "{s}");
    }

    /// With jitter variances, the start maximises the independent-samples likelihood: checked
    /// against the best of a fine grid of `s` (an independent route), and closer to the truth
    /// than the old start, the mean square minus the mean jitter variance.
    #[test]
    fn the_noise_start_maximises_the_diagonal_likelihood() {
        let mut rng = StdRng::seed_from_u64(11);
        let sigma2 = 0.0025;
        // Every fourth sample steep (jitter variance 0.16), the rest settled.
        let v: Vec<f64> = (0..400)
            .map(|k| if k % 4 == 0 { 0.16 } else { 1e-6 })
            .collect();
        let r: Vec<f64> = v
            .iter()
            .map(|v| {
                let e: f64 =
                    rand_distr::Distribution::sample(&rand_distr::StandardNormal, &mut rng);
                e * e * (sigma2 + v)
            })
            .collect();
        let loglik = |s: f64| -> f64 {
            r.iter()
                .zip(&v)
                .map(|(r, v)| -0.5 * ((s + v).ln() + r / (s + v)))
                .sum()
        };
        let s = diagonal_noise_variance(&r, &v, 1e-12, 1.0);
        let best = (0..20_000)
            .map(|i| 1e-5 * (1e5f64).powf(f64::from(i) / 20_000.0))
            .max_by(|a, b| loglik(*a).total_cmp(&loglik(*b)))
            .unwrap();
        assert!(
            (s / best - 1.0).abs() < 1e-3,
            "{s} against the grid's {best}"
        );
        // Within sampling error of the truth: 300 settled samples give a relative standard
        // error of √(2/300) ≈ 0.08 on σ_v²; four of those.
        assert!((s / sigma2 - 1.0).abs() < 0.33, "{s}");
        let naive = r.iter().sum::<f64>() / 400.0 - v.iter().sum::<f64>() / 400.0;
        assert!((naive - sigma2).abs() > (s - sigma2).abs(), "{naive} {s}");
    }

    /// A refinement handed the coarse fit's final value returns the same fit, to the bit, as
    /// one that evaluates it again: the value a fit reports is the criterion's value at the
    /// parameters it reports, on the same data.
    #[test]
    fn refinement_with_the_known_start_value_is_unchanged() {
        let grid = SampleGrid::new(0.0, 1.0, 120).unwrap();
        let g = Zpk::new(1.0, vec![], vec![Root::Real(-2.0)]).unwrap();
        let mut rng = StdRng::seed_from_u64(5);
        let u = RandomBinary::paper()
            .generate(0.0, 121.0, &mut rng)
            .unwrap();
        let signal = LtiResponse::new(g, u);
        let truth = UniformSum::new(1, 0.4).unwrap();
        let y = simulate(&signal, &truth, &grid, 0.01, &mut rng).unwrap().y;
        let record = Record::new(grid, y).unwrap();
        let structure = ModelStructure::oe(signal, UniformSum::new(1, 0.3).unwrap())
            .with_estimated(false, true, false)
            .with_noise_std(0.01)
            .unwrap();
        let criterion = ExactMl::default();
        let data = criterion.prepare(&structure, &record);
        let coarse = MlOptions::default().with_solver(Brent {
            tolerance: 3e-3,
            ..Brent::default()
        });
        let first =
            ml_estimate_with(&structure, &record, Some(&data), None, &criterion, &coarse).unwrap();
        assert!(first.cost.is_finite());
        // The premise: the reported cost is the criterion's value at the reported parameters.
        let fresh = LikelihoodObjective::with_data(&structure, &criterion, data.clone());
        assert_eq!(
            fresh.evaluate(&first.params).unwrap().to_bits(),
            first.cost.to_bits()
        );
        let fine = MlOptions::default().with_solver(Brent {
            bracket_step: 0.01,
            ..Brent::default()
        });
        let restart = structure.with_params(&first.params).unwrap();
        let known = Some((first.params.as_slice(), first.cost));
        let with = ml_estimate_with(&restart, &record, Some(&data), known, &criterion, &fine);
        let without = ml_estimate_with(&restart, &record, Some(&data), None, &criterion, &fine);
        assert_eq!(with.unwrap(), without.unwrap());
    }

    /// Brent's iterations started from the bracket's known values (the staged profile's
    /// solvers) reach the minimum that argmin's start reaches, to the tolerance, in fewer
    /// evaluations: the coarse fit of every `n`, then the refinement from its minimum.
    #[test]
    fn bracket_started_brent_reaches_the_same_minimum_in_fewer_evaluations() {
        let grid = SampleGrid::new(0.0, 1.0, 120).unwrap();
        let g = Zpk::new(1.0, vec![], vec![Root::Real(-2.0)]).unwrap();
        let mut rng = StdRng::seed_from_u64(9);
        let u = RandomBinary::paper()
            .generate(0.0, 121.0, &mut rng)
            .unwrap();
        let signal = LtiResponse::new(g, u);
        let truth = UniformSum::new(0, 0.5).unwrap();
        let y = simulate(&signal, &truth, &grid, 0.01, &mut rng).unwrap().y;
        let record = Record::new(grid, y).unwrap();
        let criterion = ExactMl::default();
        let (mut new_evals, mut old_evals) = (0, 0);
        for n in [0, 3] {
            let structure = ModelStructure::oe(signal.clone(), UniformSum::new(n, 0.45).unwrap())
                .with_estimated(false, true, false)
                .with_noise_std(0.01)
                .unwrap();
            let data = criterion.prepare(&structure, &record);
            for (tolerance, bracket_step) in [(3e-3, 0.1), (1e-8, 0.01)] {
                let fit = |from_bracket| {
                    let o = MlOptions::default().with_solver(Brent {
                        tolerance,
                        bracket_step,
                        from_bracket,
                        ..Brent::default()
                    });
                    ml_estimate_with(&structure, &record, Some(&data), None, &criterion, &o)
                        .unwrap()
                };
                let (new, old) = (fit(true), fit(false));
                assert!(new.converged && old.converged);
                // Brent's stopping test leaves each minimiser within 2 tol of the minimum of
                // ln a (tol = √ε |ln a| + tolerance), so they are within 4 tol of each other
                // (8 tol allowed; 1e-7 more for the flat bottom, where −log L changes by about
                // 1e-12 over 1e-8 in ln a), and their costs within ½ C (4 tol)², C ≤ 2500 the
                // curvature of −log L in ln a (see `PROFILE_MARGIN`).
                let tol = f64::EPSILON.sqrt() * old.params[0].ln().abs() + tolerance;
                let d = (new.params[0].ln() - old.params[0].ln()).abs();
                assert!(
                    d <= 8.0 * tol + 1e-7,
                    "n = {n}, tol {tolerance}: Δ ln a = {d}"
                );
                let dc = (new.cost - old.cost).abs();
                assert!(
                    dc <= 1250.0 * (4.0 * tol).powi(2) + 1e-9,
                    "n = {n}: Δ cost {dc}"
                );
                new_evals += new.iterations;
                old_evals += old.iterations;
            }
        }
        assert!(new_evals < old_evals, "{new_evals} vs {old_evals}");
    }
}
