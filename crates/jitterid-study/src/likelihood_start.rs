//! The start of a likelihood fit of an estimated system, and the check of where it ended.
//!
//! The exact and quasi likelihoods of a record have local optima that the first moment's
//! least-squares cost does not have: from a start 20 % off the truth, exact ML once stopped at
//! lightly damped poles with a likelihood far below the optimum and reported "converged
//! (small gradient)", which is true of a local optimum. BCLS is consistent from a wide basin
//! and cheap beside the likelihood, so a likelihood fit of an estimated system:
//!
//! 1. fits BCLS first, from the given start, with its sandwich covariance `C_B`;
//! 2. starts the likelihood from the BCLS estimate ([`LikelihoodStart::Bcls`], the default),
//!    or from the given start when the user asks for it ([`LikelihoodStart::Given`], `fit
//!    --init experiment-only`), in which case a second likelihood fit from the BCLS estimate
//!    runs too, and the fit is not converged when that one reaches a higher likelihood;
//! 3. checks that the likelihood estimate is one BCLS could have given on the same record: on
//!    the parameters the two share, `H = δᵀ C_B⁻¹ δ` with `δ = θ̂_ML − θ̂_BCLS`. At the optimum
//!    the truth's neighbourhood holds, `δ` is the difference of two consistent estimates, of
//!    covariance `C_B − C_ML` (ML efficient), and `H` is at most the Hausman statistic, of
//!    χ²(p) law; a fit with `H` beyond the χ²(p) quantile at [`CHECK_LEVEL`] is not reported
//!    as converged, and the report says why and gives both fit percents.
//!
//! The check works on parameters rather than on fit percent: BCLS minimises the squared error
//! of the expected samples, so a correct likelihood estimate nearly always fits slightly less
//! well than BCLS (by some `p/N` of the residual), and only a difference beyond the two
//! estimators' sampling difference says that the likelihood stopped elsewhere.

use crate::experiment::{LikelihoodStart, Method};
use crate::fit::{structure, Fit, FitCall, Structure};
use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use jitterid::estimate::validation::compare;
use jitterid::estimate::Record;
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// The level of the check: a correct likelihood fit is reported as not converged in at most
/// this fraction of records (fewer, since `H` is below the Hausman statistic).
pub const CHECK_LEVEL: f64 = 1e-3;

/// Log-likelihood units by which a fit from the given start may fall short of the fit from the
/// BCLS estimate and still be the same optimum: far above the solvers' tolerance, far below
/// any difference a likelihood-ratio test would see (its 50 % point is 0.23 units).
pub const LIKELIHOOD_TOLERANCE: f64 = 1e-3;

/// Fits `s` with the likelihood of `call` as [`LikelihoodStart`] says, then checks the end.
pub(crate) fn fit(call: &FitCall<'_>, s: &Structure) -> Result<Fit, String> {
    let bcls = bcls_estimate(call, s);
    let bcls_start = bcls.as_ref().and_then(|b| start_at(s, &b.fitted));
    let mut f;
    let mut other = None;
    match call.exp.estimate.likelihood_start {
        LikelihoodStart::Bcls => f = call.once(bcls_start.as_ref().unwrap_or(s))?,
        LikelihoodStart::Given => {
            f = call.once(s)?;
            // The check's fit needs no covariance.
            let check = FitCall {
                covariance: false,
                ..*call
            };
            other = bcls_start.and_then(|start| check.once(&start).ok());
        }
    }
    if let Some(reason) = other.as_ref().and_then(|o| worse_than(&f, o)) {
        not_converged(&mut f, &reason);
    } else if let Some(reason) = bcls.as_ref().and_then(|b| elsewhere(call.record, &f, b)) {
        not_converged(&mut f, &reason);
    }
    Ok(f)
}

/// The converged BCLS fit from `s`'s start (with its covariance), `None` when it fails.
fn bcls_estimate(call: &FitCall<'_>, s: &Structure) -> Option<Fit> {
    let mut b = structure(call.exp, s.signal.clone(), Method::BCLS).ok()?;
    // The given start's jitter, which may differ from the experiment's (a perturbed start).
    b.jitter = s.jitter.clone();
    let bcls = FitCall {
        method: Method::BCLS,
        covariance: true,
        ..*call
    };
    let f = bcls.once(&b).ok()?;
    f.converged.then_some(f)
}

/// `s` with the system and jitter parameters of the BCLS fit `b` (the noise shape, which BCLS
/// does not fit, keeps `s`'s start).
fn start_at(s: &Structure, b: &Structure) -> Option<Structure> {
    let (ns, nj, _) = s.blocks();
    let (bs, bj, _) = b.blocks();
    if (ns, nj) != (bs, bj) {
        return None;
    }
    let mut theta = s.params();
    let shared = b.params();
    theta[..ns + nj].copy_from_slice(shared.get(..ns + nj)?);
    s.with_params(&theta).ok()
}

/// Why `f` (from the given start) is not the likelihood's optimum when `o` (from the BCLS
/// estimate) reached a higher likelihood.
fn worse_than(f: &Fit, o: &Fit) -> Option<String> {
    (f.converged && o.converged && o.cost < f.cost - LIKELIHOOD_TOLERANCE).then(|| {
        format!(
            "stopped at a worse optimum: −log L = {:.6e}, but the likelihood fit started at the BCLS estimate reaches {:.6e} (start there: leave out --init experiment-only)",
            f.cost, o.cost
        )
    })
}

/// Why the converged likelihood fit `f` lies where BCLS (`b`) could not have put it, or `None`.
fn elsewhere(record: &Record, f: &Fit, b: &Fit) -> Option<String> {
    if !f.converged {
        return None;
    }
    let h = hausman_bound(f, b)?;
    let p = b.estimated.len();
    let limit = ChiSquared::new(p as f64)
        .ok()?
        .inverse_cdf(1.0 - CHECK_LEVEL);
    if h <= limit {
        return None;
    }
    let percent = |x: &Fit| {
        compare(&x.fitted, record.grid(), record.y())
            .ok()
            .map(|c| c.fit_percent)
    };
    let (pf, pb) = (percent(f), percent(b));
    let show = |v: Option<f64>| v.map_or("–".to_string(), |v| format!("{v:.1} %"));
    Some(format!(
        "stopped at another optimum: the estimate is {:.3} BCLS standard errors (χ²({p}) statistic {h:.1} > {limit:.1}) from the BCLS estimate, fit {} against BCLS's {}; likely a local optimum of the likelihood",
        h.sqrt(),
        show(pf),
        show(pb),
    ))
}

/// `δᵀ C_B⁻¹ δ` over the parameters the fits share (by name), `None` without a positive
/// definite BCLS covariance.
fn hausman_bound(f: &Fit, b: &Fit) -> Option<f64> {
    let cov = b.estimator_covariance.as_ref()?;
    let estimate = |x: &Fit, name: &str| {
        let i = x.estimated.iter().position(|n| n == name)?;
        x.fitted.params().get(i).copied().filter(|v| v.is_finite())
    };
    let p = b.estimated.len();
    let mut delta = Mat::<f64>::zeros(p, 1);
    for (i, name) in b.estimated.iter().enumerate() {
        delta[(i, 0)] = estimate(f, name)? - estimate(b, name)?;
    }
    let c = Mat::<f64>::from_fn(p, p, |i, j| cov[i][j]);
    let llt = c.llt(Side::Lower).ok()?;
    let x = llt.solve(&delta);
    let h: f64 = (0..p).map(|i| delta[(i, 0)] * x[(i, 0)]).sum();
    h.is_finite().then_some(h)
}

/// Marks `f` as not converged, keeping the solver's own reason after the check's.
fn not_converged(f: &mut Fit, reason: &str) {
    f.converged = false;
    f.termination = format!("{reason}; the solver said: {}", f.termination);
}

#[cfg(test)]
mod tests {
    use super::*;
    use jitterid::estimate::AnyNoise;
    use jitterid::jitter::registry::JitterRegistry;
    use jitterid::signal::registry::SignalRegistry;
    use jitterid::signal::{Input, PiecewiseConstant};
    use serde_json::json;

    /// `k/(s − p)` with Gaussian jitter, the system estimated: parameters `[gain, pole0]`.
    fn structure(theta: [f64; 2]) -> Structure {
        let spec = json!({"kind": "zpk", "gain": theta[0], "poles": [theta[1]]});
        let input = Input::Piecewise(PiecewiseConstant::new(vec![0.0, 50.0], vec![1.0]).unwrap());
        let signal = SignalRegistry::builtin()
            .build(spec.as_object().unwrap(), Some(&input))
            .unwrap();
        let jitter = JitterRegistry::builtin()
            .build(
                json!({"family": "gaussian", "sigma": 0.1})
                    .as_object()
                    .unwrap(),
            )
            .unwrap();
        Structure::bj(signal, jitter, AnyNoise::default()).with_estimated(true, false, false)
    }

    fn fit_at(theta: [f64; 2], covariance: Option<Vec<Vec<f64>>>) -> Fit {
        let fitted = structure(theta);
        Fit {
            method: Method::BCLS,
            converged: true,
            cost: 0.0,
            iterations: 1,
            termination: "small gradient".into(),
            noise_std: 0.1,
            params: Vec::new(),
            covariance: None,
            estimated: fitted.param_names(),
            fitted,
            estimator_covariance: covariance,
        }
    }

    const COV: [[f64; 2]; 2] = [[0.04, 0.006], [0.006, 0.01]];

    #[test]
    fn the_statistic_is_the_covariance_weighted_distance() {
        let b = fit_at([2.0, -1.0], Some(COV.iter().map(|r| r.to_vec()).collect()));
        let f = fit_at([2.3, -1.2], None);
        // δᵀ C⁻¹ δ by the explicit 2 × 2 inverse.
        let (d0, d1) = (0.3, -0.2);
        let det = COV[0][0] * COV[1][1] - COV[0][1] * COV[1][0];
        let want = (d0 * d0 * COV[1][1] - 2.0 * d0 * d1 * COV[0][1] + d1 * d1 * COV[0][0]) / det;
        let h = hausman_bound(&f, &b).unwrap();
        assert!((h - want).abs() < 1e-10 * want, "{h} against {want}");
    }

    #[test]
    fn a_fit_far_from_bcls_is_not_converged_and_a_near_one_is() {
        let record = Record::new(
            jitterid::signal::SampleGrid::new(0.0, 1.0, 40).unwrap(),
            (0..40).map(|k| (f64::from(k) * 0.3).sin()).collect(),
        )
        .unwrap();
        let b = fit_at([2.0, -1.0], Some(COV.iter().map(|r| r.to_vec()).collect()));
        // 1.5 standard errors on the gain: χ²(2) = 2.25 < 13.8.
        assert!(elsewhere(&record, &fit_at([2.3, -1.0], None), &b).is_none());
        // 10 standard errors: 100 > 13.8.
        let reason = elsewhere(&record, &fit_at([4.0, -1.0], None), &b).unwrap();
        assert!(
            reason.contains("another optimum") && reason.contains("χ²(2)"),
            "{reason}"
        );
    }
}
