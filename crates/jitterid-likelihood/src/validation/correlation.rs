//! Residual correlation tests: the autocorrelation of standardised residuals and their
//! cross-correlation with the input, for lags `0..=M`, per lag against 99 % bounds
//! `±2.576/√N`, and as a whole by a portmanteau statistic with a χ² p-value, whose verdict at
//! a stated level is the test's ([`super::portmanteau`]).

use super::portmanteau::{check_level, chi2_p_value, input_statistic, ljung_box, project_out};
use jitterid_estimate::EstimateError;

/// The two-sided 99 % point of the standard normal distribution.
pub const Z_99: f64 = 2.576;

/// The per-lag false-alarm probability of the bounds `±Z_99/√N`.
pub const LAG_ALPHA: f64 = 0.01;

/// The probability with which a white residual breaks the per-lag rule of a whole test (at
/// most; see [`allowed_outside`]).
pub const TEST_ALPHA: f64 = 0.01;

/// The largest number of lags compared by default.
pub const DEFAULT_MAX_LAG: usize = 25;

/// The default number of lags: `min(25, N/4)`, at least 1.
pub fn default_max_lag(n: usize) -> usize {
    DEFAULT_MAX_LAG.min(n / 4).max(1)
}

/// A correlation sequence against its per-lag bounds, its portmanteau statistic, and the
/// verdict.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CorrelationTest {
    /// Lags `0..=M` (in samples).
    pub lags: Vec<usize>,
    /// Normalised correlations at those lags.
    pub values: Vec<f64>,
    /// `Z_99/√N`: a white residual stays inside `±bound` at each tested lag with probability
    /// 0.99.
    pub bound: f64,
    /// How many tested lags lie outside the bounds (lag 0 of an autocorrelation, which is 1
    /// by construction, is not tested).
    pub outside: usize,
    /// How many outside lags chance allows ([`allowed_outside`] of the tested lags).
    pub allowed: usize,
    /// `outside ≤ allowed`: the per-lag rule, which counts lags outside the bounds and ignores
    /// by how much (a lag at 3 bounds passes); shown beside the verdict, not the verdict.
    pub lags_passed: bool,
    /// The portmanteau statistic: `"ljung-box"` (autocorrelation) or `"ljung-s"`
    /// (cross-correlation with the input, `N rᵀ R_u⁻¹ r`).
    pub test: &'static str,
    /// Its value.
    pub statistic: f64,
    /// Its χ² degrees of freedom.
    pub dof: usize,
    /// `P(χ²(dof) > statistic)`.
    pub p_value: f64,
    /// The level of the verdict.
    pub level: f64,
    /// The verdict: `p_value ≥ level` (a true model fails in a fraction `level` of records).
    pub passed: bool,
}

/// The most lags out of `tested` that may lie outside 99 % bounds before a test fails: the
/// smallest `k` with `P(Binomial(tested, 0.01) > k) ≤ 0.01`. Independent lags of a white
/// residual then fail the test in at most 1 % of records (for 25 lags `k = 2`, and the test
/// fails in 0.2 % of records).
pub fn allowed_outside(tested: usize) -> usize {
    // P(X = j) by recurrence; the tail is 1 − Σ_{j ≤ k} P(X = j).
    let n = tested as f64;
    let mut p = (1.0 - LAG_ALPHA).powf(n);
    let mut cdf = p;
    let mut k = 0;
    // The margin keeps a tail equal to the level (one lag: exactly 0.01) from failing by rounding.
    while 1.0 - cdf > TEST_ALPHA * (1.0 + 1e-9) && k < tested {
        p *= (n - k as f64) / (k as f64 + 1.0) * LAG_ALPHA / (1.0 - LAG_ALPHA);
        k += 1;
        cdf += p;
    }
    k
}

fn check(x: &[f64], what: &'static str, max_lag: usize) -> Result<(), EstimateError> {
    if let Some((index, &value)) = x.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(EstimateError::NonFiniteData { index, value });
    }
    if x.len() < 2 * max_lag.max(1) {
        return Err(EstimateError::TooFewData {
            what,
            available: x.len(),
            params: 2 * max_lag.max(1),
        });
    }
    Ok(())
}

fn centred(x: &[f64]) -> (Vec<f64>, f64) {
    let mean = x.iter().sum::<f64>() / x.len() as f64;
    let c: Vec<f64> = x.iter().map(|v| v - mean).collect();
    let norm = c.iter().map(|v| v * v).sum::<f64>().sqrt();
    (c, norm)
}

/// `Σ_k a_{k+τ} b_k / (‖a‖ ‖b‖)` for `τ = 0..=max_lag` of centred sequences, against the
/// per-lag bounds; the portmanteau fields are filled by the caller.
fn correlate(a: &[f64], b: &[f64], max_lag: usize, skip_lag0: bool) -> CorrelationTest {
    let (a, na) = centred(a);
    let (b, nb) = centred(b);
    let n = a.len();
    let values: Vec<f64> = (0..=max_lag)
        .map(|tau| {
            let s: f64 = a[tau..].iter().zip(&b[..n - tau]).map(|(x, y)| x * y).sum();
            s / (na * nb)
        })
        .collect();
    let bound = Z_99 / (n as f64).sqrt();
    let first = usize::from(skip_lag0);
    let outside = values[first..].iter().filter(|v| v.abs() > bound).count();
    let allowed = allowed_outside(max_lag + 1 - first);
    CorrelationTest {
        lags: (0..=max_lag).collect(),
        values,
        bound,
        outside,
        allowed,
        lags_passed: outside <= allowed,
        test: "",
        statistic: f64::NAN,
        dof: 0,
        p_value: f64::NAN,
        level: f64::NAN,
        passed: false,
    }
}

/// The test with its portmanteau statistic and the verdict at `level`.
fn with_statistic(
    mut test: CorrelationTest,
    name: &'static str,
    statistic: f64,
    dof: usize,
    level: f64,
) -> CorrelationTest {
    let p = chi2_p_value(statistic, dof);
    test.test = name;
    test.statistic = statistic;
    test.dof = dof;
    test.p_value = p;
    test.level = level;
    // A statistic that could not be computed is not a pass.
    test.passed = p >= level;
    test
}

/// The autocorrelation of residuals `e` for lags `0..=max_lag` and the whiteness verdict
/// over lags `1..=max_lag`: the Ljung–Box statistic, χ² with `max_lag − fitted_noise`
/// degrees of freedom, where `fitted_noise` counts the estimated parameters of the noise model
/// that whitened the residuals (the system's parameters do not constrain the residuals'
/// autocorrelation, the noise model's do; Box, Jenkins & Reinsel, §11.3).
///
/// Errors: a level outside `(0, 1)`, no degree of freedom left (`fitted_noise ≥ max_lag`), a
/// non-finite residual, fewer than `2·max_lag` residuals, or residuals without variation.
pub fn whiteness(
    e: &[f64],
    max_lag: usize,
    fitted_noise: usize,
    level: f64,
) -> Result<CorrelationTest, EstimateError> {
    check_level(level)?;
    check(e, "residuals", max_lag)?;
    if fitted_noise >= max_lag {
        return Err(EstimateError::TooFewData {
            what: "autocorrelation lags",
            available: max_lag,
            params: fitted_noise + 1,
        });
    }
    let test = spread(correlate(e, e, max_lag, true), "residuals", e.len())?;
    let q = ljung_box(&test.values, e.len());
    Ok(with_statistic(
        test,
        "ljung-box",
        q,
        max_lag - fitted_noise,
        level,
    ))
}

/// The cross-correlation `corr(e_{k+τ}, u_k)` of residuals and input samples `u_k = u(t_k)`
/// for `τ = 0..=max_lag` (a residual that still depends on past inputs: a dynamics misfit),
/// and its verdict over all those lags by Ljung's statistic ([`input_statistic`]), whose
/// degrees of freedom are the lags left free by the directions `removed` from the residuals
/// (an orthonormal basis from [`super::residual_projection`], which holds the constant at
/// least; `e` is projected off it here, which changes nothing for residuals already projected).
///
/// Errors: a level outside `(0, 1)`, sequences of different lengths, non-finite values, fewer
/// than `2·max_lag` samples, or a constant sequence.
pub fn cross_correlation(
    e: &[f64],
    u: &[f64],
    max_lag: usize,
    removed: &[Vec<f64>],
    level: f64,
) -> Result<CorrelationTest, EstimateError> {
    check_level(level)?;
    if u.len() != e.len() {
        return Err(EstimateError::DataLength {
            expected: e.len(),
            got: u.len(),
        });
    }
    check(e, "residuals", max_lag)?;
    check(u, "input samples", max_lag)?;
    let test = spread(
        correlate(e, u, max_lag, false),
        "input samples or residuals",
        e.len(),
    )?;
    let (s, dof) = input_statistic(&project_out(e, removed), u, max_lag, removed);
    Ok(with_statistic(test, "ljung-s", s, dof, level))
}

fn spread(
    test: CorrelationTest,
    what: &'static str,
    n: usize,
) -> Result<CorrelationTest, EstimateError> {
    if test.values.iter().all(|v| v.is_finite()) {
        Ok(test)
    } else {
        Err(EstimateError::TooFewData {
            what: if what == "residuals" {
                "distinct residuals"
            } else {
                "distinct input samples or residuals"
            },
            available: usize::from(n > 0),
            params: 2,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::residual_projection;
    use super::*;

    #[test]
    fn allowed_outside_is_the_binomial_quantile() {
        // 25 lags: P(X ≥ 2) = 0.0258 > 0.01, P(X ≥ 3) = 0.0020 ≤ 0.01.
        assert_eq!(allowed_outside(25), 2);
        // 1 lag: P(X ≥ 1) = 0.01 ≤ 0.01.
        assert_eq!(allowed_outside(1), 0);
        assert_eq!(allowed_outside(0), 0);
    }

    #[test]
    fn correlations_match_a_naive_sum_and_bad_input_is_named() {
        let e: Vec<f64> = (0..40).map(|k| ((k * 7919) % 13) as f64 - 6.0).collect();
        let u: Vec<f64> = (0..40).map(|k| ((k * 104_729) % 5) as f64).collect();
        let t = cross_correlation(&e, &u, 3, &residual_projection(&[], 40), 0.01).unwrap();
        let me = e.iter().sum::<f64>() / 40.0;
        let mu = u.iter().sum::<f64>() / 40.0;
        let se = e.iter().map(|x| (x - me).powi(2)).sum::<f64>().sqrt();
        let su = u.iter().map(|x| (x - mu).powi(2)).sum::<f64>().sqrt();
        let naive: f64 = (0..38).map(|k| (e[k + 2] - me) * (u[k] - mu)).sum::<f64>() / (se * su);
        assert!((t.values[2] - naive).abs() < 1e-12);
        assert_eq!(t.lags, vec![0, 1, 2, 3]);
        assert!((whiteness(&e, 3, 0, 0.01).unwrap().values[0] - 1.0).abs() < 1e-12);
        assert!(matches!(
            whiteness(&e, 3, 3, 0.01),
            Err(EstimateError::TooFewData { .. })
        ));
        assert!(matches!(
            whiteness(&e, 3, 0, 1.0),
            Err(EstimateError::BadLevel { .. })
        ));
        assert!(matches!(
            whiteness(&e[..5], 3, 0, 0.01),
            Err(EstimateError::TooFewData { .. })
        ));
        assert!(matches!(
            whiteness(&[1.0; 40], 3, 0, 0.01),
            Err(EstimateError::TooFewData { .. })
        ));
        assert!(matches!(
            cross_correlation(&e, &u[..39], 3, &[], 0.01),
            Err(EstimateError::DataLength { .. })
        ));
        let mut bad = e.clone();
        bad[4] = f64::NAN;
        assert!(matches!(
            whiteness(&bad, 3, 0, 0.01),
            Err(EstimateError::NonFiniteData { index: 4, .. })
        ));
    }
}
