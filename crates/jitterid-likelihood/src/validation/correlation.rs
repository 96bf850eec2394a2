//! Residual correlation tests: the autocorrelation of standardised residuals and their
//! cross-correlation with the input, for lags `0..=M`, against 99 % bounds `±2.576/√N`.

use jitterid_estimate::EstimateError;

/// The two-sided 99 % point of the standard normal distribution.
pub const Z_99: f64 = 2.576;

/// The per-lag false-alarm probability of the bounds `±Z_99/√N`.
pub const LAG_ALPHA: f64 = 0.01;

/// The probability with which a white residual fails a whole test (at most; the verdict's
/// rule, see [`allowed_outside`]).
pub const TEST_ALPHA: f64 = 0.01;

/// The largest number of lags compared by default.
pub const DEFAULT_MAX_LAG: usize = 25;

/// The default number of lags: `min(25, N/4)`, at least 1.
pub fn default_max_lag(n: usize) -> usize {
    DEFAULT_MAX_LAG.min(n / 4).max(1)
}

/// A correlation sequence against its bounds, and the verdict.
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
    /// `outside ≤ allowed`.
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

/// `Σ_k a_{k+τ} b_k / (‖a‖ ‖b‖)` for `τ = 0..=max_lag` of centred sequences.
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
        passed: outside <= allowed,
    }
}

/// The autocorrelation of residuals `e` for lags `0..=max_lag` and the whiteness verdict
/// over lags `1..=max_lag`.
///
/// Errors: a non-finite residual, fewer than `2·max_lag` residuals, or residuals without
/// variation.
pub fn whiteness(e: &[f64], max_lag: usize) -> Result<CorrelationTest, EstimateError> {
    check(e, "residuals", max_lag)?;
    let test = correlate(e, e, max_lag, true);
    spread(test, "residuals", e.len())
}

/// The cross-correlation `corr(e_{k+τ}, u_k)` of residuals and input samples `u_k = u(t_k)`
/// for `τ = 0..=max_lag` (a residual that still depends on past inputs: a dynamics misfit),
/// and its verdict over all those lags.
///
/// Errors: sequences of different lengths, non-finite values, fewer than `2·max_lag`
/// samples, or a constant sequence.
pub fn cross_correlation(
    e: &[f64],
    u: &[f64],
    max_lag: usize,
) -> Result<CorrelationTest, EstimateError> {
    if u.len() != e.len() {
        return Err(EstimateError::DataLength {
            expected: e.len(),
            got: u.len(),
        });
    }
    check(e, "residuals", max_lag)?;
    check(u, "input samples", max_lag)?;
    let test = correlate(e, u, max_lag, false);
    spread(test, "input samples or residuals", e.len())
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
        let t = cross_correlation(&e, &u, 3).unwrap();
        let me = e.iter().sum::<f64>() / 40.0;
        let mu = u.iter().sum::<f64>() / 40.0;
        let se = e.iter().map(|x| (x - me).powi(2)).sum::<f64>().sqrt();
        let su = u.iter().map(|x| (x - mu).powi(2)).sum::<f64>().sqrt();
        let naive: f64 = (0..38).map(|k| (e[k + 2] - me) * (u[k] - mu)).sum::<f64>() / (se * su);
        assert!((t.values[2] - naive).abs() < 1e-12);
        assert_eq!(t.lags, vec![0, 1, 2, 3]);
        assert!((whiteness(&e, 3).unwrap().values[0] - 1.0).abs() < 1e-12);
        assert!(matches!(
            whiteness(&e[..5], 3),
            Err(EstimateError::TooFewData { .. })
        ));
        assert!(matches!(
            whiteness(&[1.0; 40], 3),
            Err(EstimateError::TooFewData { .. })
        ));
        assert!(matches!(
            cross_correlation(&e, &u[..39], 3),
            Err(EstimateError::DataLength { .. })
        ));
        let mut bad = e.clone();
        bad[4] = f64::NAN;
        assert!(matches!(
            whiteness(&bad, 3),
            Err(EstimateError::NonFiniteData { index: 4, .. })
        ));
    }
}
