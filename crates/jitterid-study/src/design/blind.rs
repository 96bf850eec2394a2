//! The jitter-blind design: the same optimisation on the prior with its jitter replaced by
//! none (`γ ≡ 1`, no jitter noise), and what that design is worth on jittered data.
//!
//! This is the design a user gets from the usual advice for identification experiments, which
//! knows nothing of the jitter; evaluated under the true (jittered) prior beside the
//! jitter-aware optimum, it measures what ignoring the jitter costs.

use super::candidate::Design;
use super::criterion::criterion_value;
use super::plan::Plan;
use super::predict::Prediction;
use super::search::optimise;
use crate::error::StudyResult;
use crate::experiment::{DesignCriterion, Experiment};
use crate::study_err;
use jitterid::jitter::registry::{SpecTable, FAMILY_KEY};
use serde_json::Value;

/// `exp` with its jitter replaced by none, neither in the truth nor in the model, nor
/// estimated: the prior a jitter-blind design is computed on.
///
/// # Errors
///
/// The registry has no family `none` (a registry built without the built-in families).
pub(crate) fn without_jitter(mut exp: Experiment) -> StudyResult<Experiment> {
    let mut spec = SpecTable::new();
    spec.insert(FAMILY_KEY.into(), Value::from("none"));
    let none = exp
        .registries
        .jitter
        .build(&spec)
        .map_err(|e| study_err!("{}: [jitter] the jitter-blind prior: {e}", exp.file))?;
    exp.jitter.truth = none.clone();
    exp.jitter.model = none;
    exp.jitter.estimate = false;
    exp.jitter.n_range = None;
    exp.jitter.family_differs = false;
    Ok(exp)
}

/// The jitter-blind design and its worth under the true prior.
#[derive(Debug, Clone)]
pub struct JitterBlind {
    /// The design that is optimal when the jitter is ignored.
    pub design: Design,
    /// What the jitter-blind prior predicts for it (the precision its user expects).
    pub blind_prediction: Prediction,
    /// Its criterion value under the jitter-blind prior.
    pub blind_value: f64,
    /// Its predicted precision under the true, jittered prior (what the user gets).
    pub prediction: Prediction,
    /// Its criterion value under the true prior, comparable with the jitter-aware optimum's.
    pub value: f64,
}

/// The predicted precision of any `design` under `plan`'s prior, and its `criterion` value
/// (for a robust design, averaged over the prior's draws: [`Plan::robust_value`]).
///
/// # Errors
///
/// The design's experiment is invalid; its prediction fails (a singular information matrix);
/// the criterion names no estimated parameter.
pub fn evaluate(
    plan: &Plan,
    design: &Design,
    criterion: &DesignCriterion,
) -> StudyResult<(Prediction, f64)> {
    let p = plan.predict(design)?;
    let v = criterion_value(criterion, &p)?;
    let v = plan.robust_value(design, criterion, v)?;
    Ok((p, v))
}

/// The design that minimises `criterion` when the jitter is ignored, evaluated under the true
/// prior of `plan`.
///
/// # Errors
///
/// Those of [`optimise`] on the jitter-blind plan, and of [`evaluate`] under the true one (a
/// criterion naming a jitter parameter, which the jitter-blind prior does not estimate, is
/// refused by the search).
pub fn jitter_blind(plan: &Plan, criterion: &DesignCriterion) -> StudyResult<JitterBlind> {
    let blind = plan.jitter_blind()?;
    let opt = optimise(&blind, criterion)?;
    let (prediction, value) = evaluate(plan, &opt.design, criterion)?;
    Ok(JitterBlind {
        design: opt.design,
        blind_prediction: opt.prediction,
        blind_value: opt.value,
        prediction,
        value,
    })
}
