//! The predicted covariance of a planned experiment: how precise an estimator will be, before
//! any data exist.
//!
//! The prior model is the experiment's truth (system, jitter, noise). At the truth the
//! expected data are the first moments `m_k`, and an estimator's asymptotic covariance depends
//! on the data only through the model: for BCLS it is the sandwich `H⁻¹ Jᵀ Σ_r J H⁻¹` that a fit
//! reports ([`sandwich_covariance`], the same code), evaluated on the noise-free record
//! `y_k = m_k`; for exact ML it is the inverse exact Fisher information ([`exact_fisher`], the
//! Cramér–Rao bound that ML attains asymptotically). The jitter enters both through `m_k` and
//! its sensitivities (the damping `γ`) and through the sample variances
//! `λ_k = σ_v² + E[s(t_k+τ)²] − m_k²`, the noise the jitter adds after every input switch.
//!
//! A random input makes the covariance a random matrix; what a Monte Carlo study measures is
//! its mean over the input's realisations, so the prediction averages the covariance over
//! `draws` realisations, drawn from the same streams as Monte Carlo runs `0..draws` of the same
//! seed.

use super::realization::{input_is_random, realized_signal};
use crate::error::StudyResult;
use crate::experiment::{DesignEstimator, Experiment, Method};
use crate::fit::{structure, Structure};
use crate::study_err;
use jitterid::estimate::ml::{exact_fisher, likelihood_param_names, FisherOptions};
use jitterid::estimate::montecarlo::run as mc_run;
use jitterid::estimate::support::{reach_beyond, sandwich_covariance};
use jitterid::estimate::{Bcls, FrequencyData, Record};
use jitterid::signal::Signal;
use jitterid::window::DirichletWindow;

/// The predicted precision of one design for one estimator.
#[derive(Debug, Clone)]
pub struct Prediction {
    /// The estimator predicted for.
    pub estimator: DesignEstimator,
    /// The estimated parameters' names, in the estimator's order.
    pub names: Vec<String>,
    /// Their true values (the point the covariance is evaluated at).
    pub truth: Vec<f64>,
    /// The covariance, averaged over the input draws.
    pub covariance: Vec<Vec<f64>>,
    /// The standard deviations, `√diag`.
    pub std: Vec<f64>,
    /// Input realisations averaged over (1 for a fixed input).
    pub draws: usize,
    /// The standard error of each averaged variance over the draws (0 for one draw): how much
    /// the prediction itself would move with other draws.
    pub variance_se: Vec<f64>,
    /// The model at the truth, driven by draw 0's input: what derived quantities are
    /// functions of.
    pub(crate) model: Structure,
}

impl Prediction {
    /// The model at the truth (draw 0's input): the point the prediction linearises about.
    pub fn model(&self) -> &Structure {
        &self.model
    }

    /// The standard deviation of the parameter called `name`.
    pub fn std_of(&self, name: &str) -> Option<f64> {
        let i = self.names.iter().position(|n| n == name)?;
        self.std.get(i).copied()
    }
}

/// The model structure at the experiment's truth for `estimator`: what a fit of it estimates,
/// with the true jitter; BCLS is given the true noise level (the noise-free record holds none
/// to estimate), ML keeps `σ_v` among its parameters when the experiment estimates it.
fn truth_structure(
    exp: &Experiment,
    signal: jitterid::signal::AnySignal,
    estimator: DesignEstimator,
) -> StudyResult<Structure> {
    if exp.jitter.family_differs {
        return Err(study_err!(
            "{}: [jitter] fit_family: a design is predicted at the true model, and a fitted family that differs from the true one has no true parameters; leave fit_family out",
            exp.file
        ));
    }
    let mut s = structure(exp, signal, Method::BCLS)?;
    s.jitter = exp.jitter.truth.clone();
    if estimator == DesignEstimator::Bcls && s.noise_std.is_none() {
        s = s
            .with_noise_std(exp.noise.std)
            .map_err(|e| study_err!("{}: [noise] std: {e}", exp.file))?;
    }
    if s.num_params() == 0 {
        return Err(study_err!(
            "{}: nothing is estimated ([system], [jitter] and [noise] estimate are all false): there is no precision to predict",
            exp.file
        ));
    }
    if let Some((lo, hi, duration)) = reach_beyond(&s.jitter, &exp.grid) {
        return Err(study_err!(
            "{}: the jitter's reach [{lo}, {hi}] s is wider than the record ({duration} s)",
            exp.file
        ));
    }
    Ok(s)
}

/// The model at the experiment's truth for `estimator`, driven by input draw 0 of master seed
/// `seed` (the model a prediction's derived quantities are functions of), without predicting.
///
/// # Errors
///
/// Those of [`predict`] that come before the information matrix.
pub(crate) fn prior_model(
    exp: &Experiment,
    estimator: DesignEstimator,
    seed: u64,
) -> StudyResult<Structure> {
    let mut outs = mc_run(seed, 0..1, |_, rng| {
        let signal = realized_signal(exp, rng)?;
        truth_structure(exp, signal, estimator)
    });
    outs.pop()
        .ok_or_else(|| study_err!("{}: no input draw", exp.file))?
}

/// One draw's covariance and names.
fn one_draw(
    exp: &Experiment,
    s: &Structure,
    estimator: DesignEstimator,
) -> StudyResult<(Vec<String>, Vec<Vec<f64>>)> {
    match estimator {
        DesignEstimator::Bcls => {
            let grid = &exp.grid;
            let m = s.signal.expected_values(grid, &s.jitter);
            let record = Record::new(*grid, m)
                .map_err(|e| study_err!("{}: the expected record: {e}", exp.file))?;
            let freqs = exp
                .estimate
                .frequencies
                .resolve(&record)
                .map_err(|e| study_err!("{}: [estimate] frequencies: {e}", exp.file))?;
            let data = FrequencyData::new(record, DirichletWindow, freqs)
                .map_err(|e| study_err!("{}: {e}", exp.file))?;
            let cov = sandwich_covariance(&data, s, &Bcls).ok_or_else(|| singular(exp))?;
            Ok((s.param_names(), cov))
        }
        DesignEstimator::Ml => {
            let info = exact_fisher(s, &exp.grid, exp.noise.std, &FisherOptions::default())
                .map_err(|e| study_err!("{}: exact Fisher information: {e}", exp.file))?;
            let cov = info.crb().ok_or_else(|| singular(exp))?;
            Ok((likelihood_param_names(s), cov))
        }
    }
}

fn singular(exp: &Experiment) -> crate::StudyError {
    study_err!(
        "{}: the information matrix is singular at this design: the input does not excite every estimated parameter (or the record is too short)",
        exp.file
    )
}

/// The predicted covariance of `estimator` on the experiment as it stands (its grid, input
/// and truth), averaged over `draws` input realisations of master seed `seed` when the input
/// is random (draw `r` is the input of Monte Carlo run `r`; a fixed input is one draw).
///
/// # Errors
///
/// `draws` outside `[1, MAX_DRAWS]`; a fitted jitter family that differs from the true one;
/// nothing estimated; a jitter reach wider than the record; an input draw or model that
/// cannot be built; an information matrix that is singular at any draw (the input leaves a
/// parameter unexcited); for ML, the errors of [`exact_fisher`] (coloured noise, `σ_v = 0`).
pub fn predict(
    exp: &Experiment,
    estimator: DesignEstimator,
    draws: usize,
    seed: u64,
) -> StudyResult<Prediction> {
    let max = crate::experiment::MAX_DRAWS;
    if !(1..=max).contains(&draws) {
        return Err(study_err!(
            "draws: expected a number of input realisations in [1, {max}], found {draws}"
        ));
    }
    let draws = if input_is_random(exp) { draws } else { 1 };
    let outs = mc_run(seed, 0..draws as u64, |_, rng| {
        let signal = realized_signal(exp, rng)?;
        let s = truth_structure(exp, signal, estimator)?;
        let (names, cov) = one_draw(exp, &s, estimator)?;
        Ok::<_, crate::StudyError>((s, names, cov))
    });
    let mut model = None;
    let mut names = Vec::new();
    let mut covs = Vec::with_capacity(draws);
    for out in outs {
        let (s, n, c) = out?;
        if model.is_none() {
            model = Some(s);
            names = n;
        }
        covs.push(c);
    }
    let model = model.ok_or_else(|| study_err!("{}: no input draw", exp.file))?;
    let p = names.len();
    let k = covs.len() as f64;
    let covariance: Vec<Vec<f64>> = (0..p)
        .map(|i| {
            (0..p)
                .map(|j| covs.iter().map(|c| c[i][j]).sum::<f64>() / k)
                .collect()
        })
        .collect();
    let std = (0..p).map(|i| covariance[i][i].max(0.0).sqrt()).collect();
    let variance_se = (0..p)
        .map(|i| {
            if covs.len() < 2 {
                return 0.0;
            }
            let mean = covariance[i][i];
            let ss: f64 = covs.iter().map(|c| (c[i][i] - mean).powi(2)).sum();
            (ss / (k - 1.0) / k).sqrt()
        })
        .collect();
    let mut truth = model.params();
    // ML's σ_v, when estimated, is the last of its parameters.
    truth.resize(p, exp.noise.std);
    Ok(Prediction {
        estimator,
        names,
        truth,
        covariance,
        std,
        draws,
        variance_se,
        model,
    })
}
