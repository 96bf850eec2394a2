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
//! Only the finalists are refitted because an exact fit costs several BCLS fits; the screen
//! picks the order within a family reliably.

use super::{structure_of, Candidate, Structure};
use crate::fit::{ml_estimate, MlOptions};
use crate::ExactMl;
use jitterid_estimate::Record;
use jitterid_jitter::registry::JitterRegistry;
use jitterid_jitter::{AnyJitter, JitterModel};
use jitterid_signal::{AnySignal, Signal};
use rayon::prelude::*;

/// Index of the best screened candidate of every family, in the order the families first
/// appear: the converged one of lowest BCLS BIC, else (no converged fit in the family) the
/// fitted one of lowest BIC that did not stop at the stability boundary; candidates with a pole
/// beyond the sampling's reach are never finalists; families without such a candidate have no
/// finalist.
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
                    c.family == *family
                        && c.fitted.is_some()
                        && c.bcls_criterion.is_finite()
                        // An undamped mode makes the exact likelihood's quadrature follow
                        // `|p|/|Re p|` oscillations per sample: a refit that would spend the
                        // whole time limit on a candidate that is no model of the record.
                        && c.failure_kind != Some(super::FailureKind::StabilityBoundary)
                        // A pole the samples do not determine: the refit would tabulate the
                        // response at its time scale around every switch, for nothing.
                        && c.failure_kind != Some(super::FailureKind::PoleBeyondSampling)
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
fn exact_fit(record: &Record, family: &str, (signal, jitter): (AnySignal, AnyJitter)) -> ExactFit {
    let m = signal.expected_values(record.grid(), &jitter);
    let y = record.y();
    let n = y.len() as f64;
    let rms = (y.iter().zip(&m).map(|(y, m)| (y - m).powi(2)).sum::<f64>() / n).sqrt();
    let structure = structure_of(family, signal, jitter);
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

/// The likelihood fits to run: every [`finalists`] entry from its own BCLS estimate, and, for
/// every other jittered family, its candidate at the screen winner's order from the winner's
/// system with the family's jitter at the winner's standard deviation. Families of equal
/// spread have nearly the same first moment, so that is a start near the family's best fit
/// even where the family's own BCLS fits ended in a wrong local minimum of the jitter's scale
/// (periodic `J₀` makes the BCLS cost oscillate in the scale). A family whose own finalist is
/// at the winner's order with a jitter of nearly the winner's spread gets no extra start: its
/// own start is already there.
pub(super) fn starts(
    candidates: &[Candidate],
    registry: &JitterRegistry,
) -> Vec<(usize, (AnySignal, AnyJitter))> {
    let chosen = finalists(candidates);
    let mut out: Vec<_> = chosen
        .iter()
        .filter_map(|&i| candidates[i].fitted.clone().map(|f| (i, f)))
        .collect();
    let winner = chosen.iter().copied().min_by(|&a, &b| {
        let (ca, cb) = (&candidates[a], &candidates[b]);
        (!ca.bcls_converged)
            .cmp(&!cb.bcls_converged)
            .then(ca.bcls_criterion.total_cmp(&cb.bcls_criterion))
    });
    let Some(w) = winner else { return out };
    let Some((model, jitter)) = candidates[w].fitted.clone() else {
        return out;
    };
    let std = jitter.std_dev();
    if !(std.is_finite() && std > 0.0) {
        return out;
    }
    for (i, c) in candidates.iter().enumerate() {
        let same_order = (c.poles, c.zeros, &c.channels)
            == (
                candidates[w].poles,
                candidates[w].zeros,
                &candidates[w].channels,
            );
        if !same_order || c.family == candidates[w].family || c.family == "none" {
            continue;
        }
        // A finalist at the winner's order whose BCLS jitter has the winner's spread already
        // starts where this start would: a second fit from there finds the same optimum.
        let near = |f: &(AnySignal, AnyJitter)| (f.1.std_dev() - std).abs() <= SAME_SPREAD * std;
        if chosen.contains(&i) && c.fitted.as_ref().is_some_and(near) {
            continue;
        }
        if let Ok(j) = registry.from_std_dev(&c.family, std, &serde_json::Map::new()) {
            out.push((i, (model.clone(), j)));
        }
    }
    out
}

/// Relative difference of jitter standard deviations below which a family's own BCLS fit is
/// taken to start its likelihood fit where the winner's system would (the extra start is then
/// skipped). A wrong BCLS basin of an oscillating `γ` lies near another zero of it, at a scale
/// at least twice the right one: consecutive zeros of `J₀` (periodic) are at 2.405, 5.520, …
/// (ratio 2.3), of `cos` (two-point) at π/2, 3π/2, … (ratio 3), of the uniform sum's
/// `sinc^{n+1}` at π, 2π, … (ratio 2); a law whose `γ` has no zeros (Gaussian) has no such
/// basins at all. Right-basin fits of different families differ in spread, each matching the
/// first moment with its own `γ`: 12.7 % (Gaussian against periodic) on the select benchmark's
/// record, 12–18 % between the Gaussian and the periodic or two-point laws when `γ` is matched
/// where it has fallen to `e^{−1}`. 25 % keeps those together and stays below the factor between
/// basins; `docs/method.md` ("Selection").
const SAME_SPREAD: f64 = 0.25;

/// An exact fit, the structure at its estimate and its BIC, or why it failed.
type ExactFit = Result<(jitterid_estimate::Fit, Structure, f64), String>;

/// Refits the [`finalists`] of `candidates` by exact maximum likelihood (in parallel) and
/// records the outcome on each: a converged fit makes the candidate ranked by the likelihood's
/// BIC, with the likelihood's estimates; otherwise it keeps its screen's rank and says why.
/// A candidate fitted from two [`starts`] keeps the converged fit of higher likelihood.
pub(super) fn refine_finalists(
    record: &Record,
    registry: &JitterRegistry,
    candidates: &mut [Candidate],
) {
    let jobs = starts(candidates, registry);
    let budget = jitterid_numeric::budget::current();
    let fits: Vec<_> = jobs
        .par_iter()
        .map(|(i, start)| {
            jitterid_numeric::budget::run_with(budget.clone(), || {
                exact_fit(record, &candidates[*i].family, start.clone())
            })
        })
        .collect();
    // Converged before not converged before failed, then the lower BIC.
    let key = |r: &ExactFit| match r {
        Ok((fit, _, bic)) => (u8::from(!fit.converged), *bic),
        Err(_) => (2, f64::INFINITY),
    };
    let mut best: Vec<(usize, ExactFit)> = Vec::new();
    for ((i, _), result) in jobs.into_iter().zip(fits) {
        match best.iter_mut().find(|(j, _)| *j == i) {
            None => best.push((i, result)),
            Some((_, kept)) => {
                let (a, b) = (key(&result), key(kept));
                if a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)).is_lt() {
                    *kept = result;
                }
            }
        }
    }
    for (i, result) in best {
        let c = &mut candidates[i];
        match result {
            Ok((fit, structure, bic)) => {
                c.likelihood_criterion = Some(bic);
                if fit.converged {
                    c.ranked_by_likelihood = true;
                    c.criterion = bic;
                    c.converged = true;
                    c.failure = None;
                    c.failure_kind = None;
                    c.parameters = fit.names.iter().cloned().zip(fit.params).collect();
                    c.fitted = Some((structure.signal, structure.jitter));
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
