//! The Monte Carlo check of a design: realisations of the designed experiment on jittered
//! data, fitted by the estimator the design was predicted for, and summarised as the
//! prediction is (each parameter's standard deviation, the criterion of the sample
//! covariance), each with its Monte Carlo standard error, so that a prediction, or two
//! designs, can be compared beyond the Monte Carlo's own error.

use super::candidate::Design;
use super::criterion::covariance_criterion;
use super::plan::Plan;
use crate::error::StudyResult;
use crate::experiment::{DesignCriterion, Method};
use crate::montecarlo::montecarlo_realizations;
use crate::study_err;
use std::time::Instant;

/// What a Monte Carlo of one design measured.
#[derive(Debug, Clone)]
pub struct MonteCarloCheck {
    /// The estimated parameters' names.
    pub names: Vec<String>,
    /// Realisations run.
    pub runs: u64,
    /// Realisations whose fit converged with every estimate finite: the ones summarised.
    pub used: usize,
    /// The sample covariance of the estimates.
    pub covariance: Vec<Vec<f64>>,
    /// Each estimate's sample standard deviation.
    pub std: Vec<f64>,
    /// The standard error of each standard deviation, `s √((κ − 1)/(4R))` with `κ` the sample
    /// kurtosis (the delta method on the variance, whose error is `√((m₄ − m₂²)/R)`): a
    /// heavy-tailed estimate's spread is known less well than a Gaussian's.
    pub std_se: Vec<f64>,
    /// The criterion of the sample covariance (`log det` for D-optimality).
    pub criterion: f64,
    /// Its jackknife standard error over the realisations.
    pub criterion_se: f64,
    /// Wall time of the realisations (s).
    pub seconds: f64,
}

/// The sample covariance of the rows `x` (each a realisation's estimates).
fn sample_covariance(x: &[&Vec<f64>]) -> Vec<Vec<f64>> {
    let r = x.len() as f64;
    let p = x.first().map_or(0, |v| v.len());
    let mean: Vec<f64> = (0..p)
        .map(|i| x.iter().map(|v| v[i]).sum::<f64>() / r)
        .collect();
    (0..p)
        .map(|i| {
            (0..p)
                .map(|j| {
                    x.iter()
                        .map(|v| (v[i] - mean[i]) * (v[j] - mean[j]))
                        .sum::<f64>()
                        / (r - 1.0)
                })
                .collect()
        })
        .collect()
}

/// Runs `runs` realisations of `design` under `plan`'s prior (master seed `seed`: run `r`'s
/// input is draw `r` of a prediction with the same seed), each fitted by the `[design]`
/// estimator, on all cores, and summarises them under `criterion`.
///
/// The plan must be the true one: a check on the jitter-blind plan would simulate data
/// without jitter.
///
/// # Errors
///
/// The design's experiment is invalid; the study cannot run; fewer than `p + 2` realisations
/// converged (no covariance to judge); a criterion that names no estimated parameter.
pub fn monte_carlo(
    plan: &Plan,
    design: &Design,
    criterion: &DesignCriterion,
    runs: u64,
    seed: u64,
) -> StudyResult<MonteCarloCheck> {
    if plan.is_jitter_blind() {
        return Err(study_err!(
            "a Monte Carlo check runs on the true prior, not on the jitter-blind one"
        ));
    }
    let mut exp = plan.experiment(design)?;
    let estimator = plan.spec.estimator.as_str();
    exp.estimate.method = Method::parse(estimator)
        .ok_or_else(|| study_err!("[design] estimator: no method {estimator}"))?;
    let t = Instant::now();
    let s = montecarlo_realizations(&exp, runs, seed, None)?;
    let seconds = t.elapsed().as_secs_f64();
    let rows: Vec<Vec<f64>> = s
        .runs
        .iter()
        .filter(|r| r.converged)
        .filter_map(|r| r.values.iter().copied().collect::<Option<Vec<f64>>>())
        .collect();
    let p = s.names.len();
    if rows.len() < p + 2 {
        return Err(study_err!(
            "{}: only {} of {runs} realisations converged at the design (mean dwell {}, interval {} s, {} samples): too few for a covariance of {p} parameters",
            exp.file,
            rows.len(),
            design.mean_dwell.map_or("fixed".into(), |m| format!("{m} s")),
            design.interval,
            design.samples
        ));
    }
    let all: Vec<&Vec<f64>> = rows.iter().collect();
    let covariance = sample_covariance(&all);
    let r = rows.len() as f64;
    let std: Vec<f64> = (0..p).map(|i| covariance[i][i].sqrt()).collect();
    let std_se = (0..p)
        .map(|i| {
            let mean = rows.iter().map(|v| v[i]).sum::<f64>() / r;
            let m2 = rows.iter().map(|v| (v[i] - mean).powi(2)).sum::<f64>() / r;
            let m4 = rows.iter().map(|v| (v[i] - mean).powi(4)).sum::<f64>() / r;
            std[i] * ((m4 / (m2 * m2) - 1.0) / (4.0 * r)).sqrt()
        })
        .collect();
    let criterion_value = covariance_criterion(criterion, &s.names, &covariance)?;
    // Jackknife: the criterion with each realisation left out in turn.
    let leave_out: Vec<f64> = (0..rows.len())
        .map(|k| {
            let rest: Vec<&Vec<f64>> = rows
                .iter()
                .enumerate()
                .filter(|(j, _)| *j != k)
                .map(|(_, v)| v)
                .collect();
            covariance_criterion(criterion, &s.names, &sample_covariance(&rest))
        })
        .collect::<StudyResult<_>>()?;
    let jack_mean = leave_out.iter().sum::<f64>() / r;
    let criterion_se = ((r - 1.0) / r
        * leave_out
            .iter()
            .map(|v| (v - jack_mean).powi(2))
            .sum::<f64>())
    .sqrt();
    Ok(MonteCarloCheck {
        names: s.names,
        runs,
        used: rows.len(),
        covariance,
        std,
        std_se,
        criterion: criterion_value,
        criterion_se,
        seconds,
    })
}
