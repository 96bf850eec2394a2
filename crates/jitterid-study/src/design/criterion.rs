//! The scalar a design search minimises: a function of the predicted covariance `C`.
//!
//! D-optimality (`log det C`) is the default because it does not depend on the parameters'
//! units or scaling (a reparameterisation multiplies `det C` by a constant), so a zero's
//! location and a gain are weighed alike; A-optimality (`trace C`) and one parameter's
//! variance are for a user who knows which number matters.

use super::predict::Prediction;
use crate::error::StudyResult;
use crate::experiment::DesignCriterion;
use crate::study_err;
use faer::{Mat, Side};

/// The criterion's value at `prediction` (smaller is better); `+∞` when `C` is not positive
/// definite (D-optimality).
///
/// # Errors
///
/// A `param:NAME` criterion whose name is not among the predicted parameters (the message
/// lists them).
pub fn criterion_value(criterion: &DesignCriterion, prediction: &Prediction) -> StudyResult<f64> {
    covariance_criterion(criterion, &prediction.names, &prediction.covariance)
}

/// The criterion's value at any covariance `c` of the parameters `names` (a prediction's, or
/// a Monte Carlo's sample covariance, so that the two are judged by one formula).
///
/// # Errors
///
/// As [`criterion_value`].
pub fn covariance_criterion(
    criterion: &DesignCriterion,
    names: &[String],
    c: &[Vec<f64>],
) -> StudyResult<f64> {
    let p = c.len();
    Ok(match criterion {
        DesignCriterion::D => {
            let m = Mat::from_fn(p, p, |i, j| c[i][j]);
            match m.llt(Side::Lower) {
                Ok(l) => {
                    let l = l.L();
                    (0..p).map(|i| 2.0 * l[(i, i)].ln()).sum()
                }
                Err(_) => f64::INFINITY,
            }
        }
        DesignCriterion::A => (0..p).map(|i| c[i][i]).sum(),
        DesignCriterion::Param(name) => {
            let i = names.iter().position(|n| n == name).ok_or_else(|| {
                study_err!(
                    "criterion param:{name}: no estimated parameter of that name; expected one of {}",
                    names.join(", ")
                )
            })?;
            c[i][i]
        }
    })
}
