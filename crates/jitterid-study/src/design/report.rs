//! What `jitterid design` reports: the designed experiment and the file's own, each with its
//! predicted standard deviations, as values and as the command's JSON.

use super::blind::JitterBlind;
use super::candidate::Design;
use super::criterion::criterion_value;
use super::derived::{derived_std, Derived};
use super::derived_choice::{check_defined, requested_stds, DerivedRequest};
use super::plan::Plan;
use super::predict::{predict, prior_model, Prediction};
use super::search::optimise;
use crate::error::StudyResult;
use crate::experiment::{DesignCriterion, DesignEstimator, PriorSpread};
use jitterid::jitter::JitterModel;
use serde::Serialize;

/// One predicted standard deviation.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PredictedStd {
    /// The parameter's name.
    pub name: String,
    /// Its predicted standard deviation (`null` where the baseline could not be predicted).
    pub std: Option<f64>,
}

/// A design and its predicted standard deviations.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PredictedDesign {
    /// The design.
    pub design: Design,
    /// The predicted standard deviation of each estimated parameter.
    pub predicted: Vec<PredictedStd>,
    /// Derived quantities' predicted standard deviations (see [`derived_stds`]).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub derived: Vec<PredictedStd>,
    /// The jitter's standard deviation at this design's interval (s), under `[design]
    /// jitter_exponent` (absent otherwise, and where the design could not be predicted).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub jitter_std: Option<f64>,
}

/// The JSON of `jitterid design --json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DesignJson {
    /// The criterion (`d`, `a`, `param:NAME`).
    pub criterion: String,
    /// The designed experiment.
    pub design: Design,
    /// Its predicted standard deviations.
    pub predicted: Vec<PredictedStd>,
    /// Derived quantities' predicted standard deviations (see [`derived_stds`]).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub derived: Vec<PredictedStd>,
    /// The jitter's standard deviation at the designed interval (s), under `[design]
    /// jitter_exponent` (absent otherwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub jitter_std: Option<f64>,
    /// The experiment file's own design, for comparison.
    pub baseline: PredictedDesign,
    /// The jitter-blind design (`--jitter-blind`), when asked for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub jitter_blind: Option<BlindJson>,
    /// A robust design's prior and the averaged criterion of the designed and the baseline
    /// design (absent for a design at the prior's point).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub robust: Option<RobustJson>,
}

/// A robust design in the JSON: the prior's spread and the criterion averaged over its draws,
/// for the designed and the baseline design (`null` where the baseline could not be
/// predicted). `predicted` and `derived` stay those at the prior's point.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RobustJson {
    /// `[design] prior_spread`.
    pub prior_spread: f64,
    /// `[design] prior_jitter_spread`.
    pub prior_jitter_spread: f64,
    /// `[design] prior_draws`.
    pub prior_draws: usize,
    /// The designed experiment's averaged criterion.
    pub criterion_designed: f64,
    /// The baseline's averaged criterion.
    pub criterion_baseline: Option<f64>,
}

/// The jitter-blind design in the JSON: its predicted standard deviations under the true
/// prior (`predicted`, what a user of it gets) and under the jitter-blind one
/// (`predicted_blind`, what they expect), with the criterion's value under each.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BlindJson {
    /// The design.
    pub design: Design,
    /// Under the true prior.
    pub predicted: Vec<PredictedStd>,
    /// The criterion under the true prior (compare with the designed experiment's).
    pub criterion_value: f64,
    /// Under the jitter-blind prior.
    pub predicted_blind: Vec<PredictedStd>,
    /// The criterion under the jitter-blind prior.
    pub criterion_value_blind: f64,
    /// The jitter's standard deviation at this design's interval under the true prior (s),
    /// under `[design] jitter_exponent` (absent otherwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub jitter_std: Option<f64>,
}

/// The outcome of a design search, with what the text report adds to the JSON.
#[derive(Debug, Clone)]
pub struct DesignReport {
    /// The criterion.
    pub criterion: DesignCriterion,
    /// The estimator predicted for.
    pub estimator: DesignEstimator,
    /// Input draws per prediction (1 for a fixed input).
    pub draws: usize,
    /// The designed experiment.
    pub design: Design,
    /// Its prediction.
    pub prediction: Prediction,
    /// Its criterion value.
    pub value: f64,
    /// The baseline design.
    pub baseline: Design,
    /// The baseline's prediction and criterion value, or why it has none (a singular
    /// information matrix at the file's own design).
    pub baseline_prediction: Result<(Prediction, f64), String>,
    /// Designs evaluated by the search.
    pub evaluations: usize,
    /// The jitter-blind design, when asked for ([`jitter_blind`](super::jitter_blind)).
    pub jitter_blind: Option<JitterBlind>,
    /// A robust design's prior spread (`value` and the baseline's are then averaged over its
    /// draws).
    pub prior: Option<PriorSpread>,
    /// The derived quantities asked for (`[design] derived`), `None` for [`derived_stds`]'s.
    pub derived: Option<Vec<DerivedRequest>>,
    /// `[design] jitter_exponent`: when not 0, the jitter depends on the interval and the
    /// report gives its standard deviation at each design ([`DesignReport::jitter_std_of`]).
    pub jitter_exponent: f64,
}

/// The derived quantities a design report gives beside the parameters, by the delta method:
/// the static gain where the model has one, and the jitter's σ where it is estimated (a known
/// jitter's is exactly 0 and is left out).
pub fn derived_stds(p: &Prediction) -> Vec<PredictedStd> {
    [Derived::StaticGain, Derived::JitterStd]
        .into_iter()
        .filter_map(|q| {
            let s = derived_std(p, q).ok()?;
            (q != Derived::JitterStd || s > 0.0).then(|| PredictedStd {
                name: q.name(),
                std: Some(s),
            })
        })
        .collect()
}

/// The predicted standard deviation of every parameter of `p`, named.
fn stds(p: &Prediction) -> Vec<PredictedStd> {
    p.names
        .iter()
        .zip(&p.std)
        .map(|(n, s)| PredictedStd {
            name: n.clone(),
            std: Some(*s),
        })
        .collect()
}

impl DesignReport {
    /// The derived quantities' predicted standard deviations at `p` (any of the report's
    /// predictions): those asked for ([`requested_stds`]) or by default [`derived_stds`].
    pub fn derived_of(&self, p: &Prediction) -> Vec<PredictedStd> {
        match &self.derived {
            Some(requests) => requested_stds(p, requests),
            None => derived_stds(p),
        }
    }

    /// The jitter's standard deviation of prediction `p` (its model's, at its design's
    /// interval) when the jitter depends on the interval (`[design] jitter_exponent`), `None`
    /// otherwise.
    pub fn jitter_std_of(&self, p: &Prediction) -> Option<f64> {
        (self.jitter_exponent != 0.0).then(|| p.model().jitter.std_dev())
    }

    /// The jitter's standard deviation at the baseline's interval ([`Self::jitter_std_of`] of
    /// the baseline's prediction), `None` also where the baseline could not be predicted.
    pub fn baseline_jitter_std(&self) -> Option<f64> {
        self.baseline_prediction
            .as_ref()
            .ok()
            .and_then(|(p, _)| self.jitter_std_of(p))
    }

    /// The command's JSON.
    pub fn json(&self) -> DesignJson {
        let baseline_derived = match &self.baseline_prediction {
            Ok((p, _)) => self.derived_of(p),
            Err(_) => Vec::new(),
        };
        let baseline = match &self.baseline_prediction {
            Ok((p, _)) => stds(p),
            Err(_) => self
                .prediction
                .names
                .iter()
                .map(|n| PredictedStd {
                    name: n.clone(),
                    std: None,
                })
                .collect(),
        };
        DesignJson {
            criterion: self.criterion.to_string(),
            design: self.design.clone(),
            predicted: stds(&self.prediction),
            derived: self.derived_of(&self.prediction),
            jitter_std: self.jitter_std_of(&self.prediction),
            baseline: PredictedDesign {
                design: self.baseline.clone(),
                predicted: baseline,
                derived: baseline_derived,
                jitter_std: self.baseline_jitter_std(),
            },
            jitter_blind: self.jitter_blind.as_ref().map(|b| BlindJson {
                design: b.design.clone(),
                predicted: stds(&b.prediction),
                criterion_value: b.value,
                predicted_blind: stds(&b.blind_prediction),
                criterion_value_blind: b.blind_value,
                jitter_std: self.jitter_std_of(&b.prediction),
            }),
            robust: self.prior.map(|p| RobustJson {
                prior_spread: p.system,
                prior_jitter_spread: p.jitter,
                prior_draws: p.draws,
                criterion_designed: self.value,
                criterion_baseline: self.baseline_prediction.as_ref().ok().map(|(_, v)| *v),
            }),
        }
    }
}

/// Designs the plan's experiment under `criterion` (the `[design]` section's when `None`) and
/// predicts the baseline's precision beside it.
///
/// # Errors
///
/// Those of [`optimise`]: an unknown parameter in the criterion, a range without a feasible
/// design; a derived quantity asked for (`[design] derived`) that the prior model does not
/// define (checked before the search).
pub fn design(plan: &Plan, criterion: Option<&DesignCriterion>) -> StudyResult<DesignReport> {
    let spec = &plan.spec;
    let criterion = criterion.unwrap_or(&spec.criterion).clone();
    if let Some(requests) = &spec.derived {
        let model = prior_model(&plan.baseline, spec.estimator, spec.seed)?;
        check_defined(&plan.baseline.file, requests, &model)?;
    }
    let optimum = optimise(plan, &criterion)?;
    let baseline = plan.baseline_design();
    let baseline_prediction = predict(&plan.baseline, spec.estimator, spec.draws, spec.seed)
        .and_then(|p| criterion_value(&criterion, &p).map(|v| (p, v)))
        .and_then(|(p, v)| {
            let v = plan.robust_value(&baseline, &criterion, v)?;
            Ok((p, v))
        })
        .map_err(|e| e.to_string());
    Ok(DesignReport {
        criterion,
        estimator: spec.estimator,
        draws: optimum.prediction.draws,
        design: optimum.design,
        value: optimum.value,
        prediction: optimum.prediction,
        baseline,
        baseline_prediction,
        evaluations: optimum.evaluations,
        jitter_blind: None,
        prior: spec.prior,
        derived: spec.derived.clone(),
        jitter_exponent: spec.jitter_exponent,
    })
}
