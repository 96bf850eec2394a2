//! The final stage of [`select`](super::select): the best candidate of each family, refitted by
//! exact maximum likelihood and ranked by that likelihood's BIC.
//!
//! Why the likelihood decides the family: BCLS fits the first moment `μ_Y(f)`, in which the
//! jitter appears only through `γ(f)`. Two families of the same standard deviation have nearly
//! the same `γ` at low frequencies (both `1 − 2π²σ²f² + …`), and where they differ (near
//! Nyquist) the input has little power, so a wrong family with the system's free parameters
//! absorbing the rest can match the first moment as well as the true one. The exact
//! likelihood `p(y_k) = ∫ φ_{σ_v}(y_k − s(t_k + τ)) p(τ) dτ` sees the law of `s(t_k + τ)`
//! itself: a bounded arcsine law and a Gaussian of the same variance give samples spread
//! differently wherever the signal moves, which is at every input switch.
//!
//! Only the finalists are refitted because one exact fit costs about as much as the whole
//! BCLS screen of a candidate; the screen picks the order within a family reliably.

use super::{Candidate, Structure};
use crate::ml::{ml_estimate, ExactMl, MlOptions};
use crate::{ModelStructure, Record};
use jitterid_signal::{Input, LtiResponse, Signal};
use rayon::prelude::*;

/// Index of the best screened candidate of every family, in the order the families first
/// appear: the converged one of lowest BCLS BIC, else (no converged fit in the family) the
/// fitted one of lowest BIC; families without any fitted candidate have no finalist.
pub(super) fn finalists(candidates: &[Candidate]) -> Vec<usize> {
    let mut families: Vec<&str> = Vec::new();
    for c in candidates {
        if !families.contains(&c.family.as_str()) {
            families.push(&c.family);
        }
    }
    families
        .iter()
        .filter_map(|family| {
            (0..candidates.len())
                .filter(|&i| {
                    let c = &candidates[i];
                    c.family == *family && c.fitted.is_some() && c.bcls_criterion.is_finite()
                })
                .min_by(|&a, &b| {
                    let (ca, cb) = (&candidates[a], &candidates[b]);
                    (!ca.bcls_converged)
                        .cmp(&!cb.bcls_converged)
                        .then(ca.bcls_criterion.total_cmp(&cb.bcls_criterion))
                })
        })
        .collect()
}

/// The exact maximum-likelihood fit of a screened candidate, started at its BCLS estimate with
/// `σ_v` started at the RMS of the time-domain residuals `y_k − m_k`: that start includes the
/// jitter's share of the spread, so every sample has a representable likelihood even where the
/// BCLS estimate of a bounded law's reach is a little short, and the search shrinks it.
/// Returns the fit, the structure at the estimate and the BIC.
fn exact_fit(
    record: &Record,
    input: &Input,
    candidate: &Candidate,
) -> Result<(crate::Fit, Structure, f64), String> {
    let (model, jitter) = candidate
        .fitted
        .clone()
        .ok_or_else(|| "no screened fit".to_string())?;
    let signal = LtiResponse::new(model, input.clone());
    let m = signal.expected_values(record.grid(), &jitter);
    let y = record.y();
    let n = y.len() as f64;
    let rms = (y.iter().zip(&m).map(|(y, m)| (y - m).powi(2)).sum::<f64>() / n).sqrt();
    let structure: Structure = if candidate.family == "none" {
        ModelStructure::oe(signal, jitter)
    } else {
        ModelStructure::joe(signal, jitter)
    };
    let options = MlOptions {
        noise_std_start: (rms.is_finite() && rms > 0.0).then_some(rms),
        ..MlOptions::default()
    };
    let fit = ml_estimate(&structure, record, &ExactMl::default(), &options)
        .map_err(|e| format!("exact likelihood: {e}"))?;
    if !fit.cost.is_finite() {
        return Err(format!("exact likelihood: −log L = {}", fit.cost));
    }
    let k = fit.params.len() as f64;
    let bic = 2.0 * fit.cost + k * n.ln();
    // The likelihood's parameters are the structure's followed by σ_v.
    let at = structure
        .with_params(&fit.params[..fit.params.len() - 1])
        .map_err(|e| format!("exact likelihood: {e}"))?;
    Ok((fit, at, bic))
}

/// Refits the [`finalists`] of `candidates` by exact maximum likelihood (in parallel) and
/// records the outcome on each: a converged fit makes the candidate ranked by the likelihood's
/// BIC, with the likelihood's estimates; otherwise it keeps its screen's rank and says why.
pub(super) fn refine_finalists(record: &Record, input: &Input, candidates: &mut [Candidate]) {
    let chosen = finalists(candidates);
    let fits: Vec<_> = chosen
        .par_iter()
        .map(|&i| exact_fit(record, input, &candidates[i]))
        .collect();
    for (i, result) in chosen.into_iter().zip(fits) {
        let c = &mut candidates[i];
        match result {
            Ok((fit, structure, bic)) => {
                c.likelihood_criterion = Some(bic);
                if fit.converged {
                    c.ranked_by_likelihood = true;
                    c.criterion = bic;
                    c.converged = true;
                    c.failure = None;
                    c.parameters = fit.names.iter().cloned().zip(fit.params).collect();
                    c.fitted = Some((structure.signal.model().clone(), structure.jitter));
                } else {
                    c.likelihood_failure = Some(format!(
                        "exact likelihood did not converge: {}",
                        fit.termination
                    ));
                }
            }
            Err(e) => c.likelihood_failure = Some(e),
        }
    }
}
