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
    /// The summarised realisations: each run's index and estimates, in run order (what
    /// [`criterion_difference`] pairs by run).
    pub estimates: Vec<(u64, Vec<f64>)>,
}

/// The rows `v` without row `k`.
fn leave_one_out<'v>(v: &[&'v Vec<f64>], k: usize) -> Vec<&'v Vec<f64>> {
    v.iter()
        .enumerate()
        .filter(|(j, _)| *j != k)
        .map(|(_, x)| *x)
        .collect()
}

/// The difference of the criterion between two Monte Carlo checks of the same study (the same
/// seed and runs, two designs), `other − this`, over the runs summarised in both, with its
/// jackknife standard error over those runs, each run left out of both at once. Run `r` of
/// both designs shares its jitter and noise streams, so the two criteria are correlated and
/// the paired error is the honest one: treating the studies as independent overstates it.
/// `None` with fewer than `p + 3` common runs.
///
/// # Errors
///
/// A criterion that names no estimated parameter.
pub fn criterion_difference(
    this: &MonteCarloCheck,
    other: &MonteCarloCheck,
    criterion: &DesignCriterion,
) -> StudyResult<Option<(f64, f64, usize)>> {
    let mut a: Vec<&Vec<f64>> = Vec::new();
    let mut b: Vec<&Vec<f64>> = Vec::new();
    let mut j = 0;
    for (run, x) in &this.estimates {
        while j < other.estimates.len() && other.estimates[j].0 < *run {
            j += 1;
        }
        if let Some((r, y)) = other.estimates.get(j) {
            if r == run {
                a.push(x);
                b.push(y);
            }
        }
    }
    let n = a.len();
    if n < this.names.len() + 3 {
        return Ok(None);
    }
    let diff = |a: &[&Vec<f64>], b: &[&Vec<f64>]| -> StudyResult<f64> {
        Ok(
            covariance_criterion(criterion, &other.names, &sample_covariance(b))?
                - covariance_criterion(criterion, &this.names, &sample_covariance(a))?,
        )
    };
    let whole = diff(&a, &b)?;
    let leave_out: Vec<f64> = (0..n)
        .map(|k| diff(&leave_one_out(&a, k), &leave_one_out(&b, k)))
        .collect::<StudyResult<_>>()?;
    let r = n as f64;
    let mean = leave_out.iter().sum::<f64>() / r;
    let se = ((r - 1.0) / r * leave_out.iter().map(|v| (v - mean).powi(2)).sum::<f64>()).sqrt();
    Ok(Some((whole, se, n)))
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
    let estimates: Vec<(u64, Vec<f64>)> = s
        .runs
        .iter()
        .filter(|r| r.converged)
        .filter_map(|r| {
            let v = r.values.iter().copied().collect::<Option<Vec<f64>>>()?;
            Some((r.run, v))
        })
        .collect();
    let rows: Vec<&Vec<f64>> = estimates.iter().map(|(_, v)| v).collect();
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
    let covariance = sample_covariance(&rows);
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
            covariance_criterion(
                criterion,
                &s.names,
                &sample_covariance(&leave_one_out(&rows, k)),
            )
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
        estimates,
    })
}

#[cfg(test)]
mod tests {
    use super::{criterion_difference, sample_covariance, MonteCarloCheck};
    use crate::design::covariance_criterion;
    use crate::experiment::DesignCriterion;

    /// A check holding `rows` as runs `runs` (only the fields the difference reads).
    fn check(runs: &[u64], rows: &[Vec<f64>]) -> MonteCarloCheck {
        MonteCarloCheck {
            names: vec!["a".into(), "b".into()],
            runs: 0,
            used: rows.len(),
            covariance: vec![],
            std: vec![],
            std_se: vec![],
            criterion: 0.0,
            criterion_se: 0.0,
            seconds: 0.0,
            estimates: runs.iter().copied().zip(rows.iter().cloned()).collect(),
        }
    }

    /// Rows of a fixed, scrambled sequence (no random draws: deterministic).
    fn rows(n: usize) -> Vec<Vec<f64>> {
        (0..n)
            .map(|i| {
                let x = ((i * 7919) % 101) as f64 / 101.0;
                let y = ((i * 104_729) % 97) as f64 / 97.0;
                vec![x, x * 0.3 + y]
            })
            .collect()
    }

    /// A design whose every estimate is twice the other's, run by run, has `log det` larger
    /// by exactly `p ln 4`, and every leave-one-out pair says the same, so the paired error is
    /// 0; runs present in one check only are left out; too few common runs give `None`.
    #[test]
    fn a_paired_difference_pairs_runs_by_index() {
        let a = rows(40);
        let b: Vec<Vec<f64>> = a
            .iter()
            .map(|r| r.iter().map(|x| 2.0 * x).collect())
            .collect();
        let runs: Vec<u64> = (0..40).collect();
        let d = DesignCriterion::D;
        let (diff, se, n) = criterion_difference(&check(&runs, &a), &check(&runs, &b), &d)
            .unwrap()
            .unwrap();
        assert!((diff - 2.0 * 4f64.ln()).abs() < 1e-12, "{diff}");
        assert!(se < 1e-12, "{se}");
        assert_eq!(n, 40);
        // Run 5 missing from the second check: the first's run 5 is left out too, so the
        // pairs still match exactly.
        let keep: Vec<u64> = runs.iter().copied().filter(|&r| r != 5).collect();
        let b_kept: Vec<Vec<f64>> = keep.iter().map(|&r| b[r as usize].clone()).collect();
        let (diff, se, n) = criterion_difference(&check(&runs, &a), &check(&keep, &b_kept), &d)
            .unwrap()
            .unwrap();
        assert!((diff - 2.0 * 4f64.ln()).abs() < 1e-12 && se < 1e-12 && n == 39);
        // The difference itself is the criterion of each sample covariance, differenced.
        let c: Vec<Vec<f64>> = rows(41)[1..].to_vec();
        let (diff, se, _) = criterion_difference(&check(&runs, &a), &check(&runs, &c), &d)
            .unwrap()
            .unwrap();
        let names = ["a".to_string(), "b".to_string()];
        let crit = |r: &[Vec<f64>]| {
            let refs: Vec<&Vec<f64>> = r.iter().collect();
            covariance_criterion(&d, &names, &sample_covariance(&refs)).unwrap()
        };
        assert!((diff - (crit(&c) - crit(&a))).abs() < 1e-12);
        assert!(se > 0.0);
        assert!(
            criterion_difference(&check(&runs[..4], &a[..4]), &check(&runs[..4], &b[..4]), &d)
                .unwrap()
                .is_none()
        );
    }
}
