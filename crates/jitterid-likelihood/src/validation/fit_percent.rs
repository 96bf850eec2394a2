//! The normalised fit `100 (1 − ‖y − m‖ / ‖y − mean(y)‖)` of expected samples `m_k` to data.

use jitterid_estimate::EstimateError;

/// `100 (1 − ‖y − m‖ / ‖y − ȳ‖)`, the share of the data's variation about its mean that the
/// model's expected samples `m_k = E[s(t_k + τ)]` explain: 100 for a perfect model, 0 for
/// one no better than the mean, negative for a worse one.
///
/// Errors: `m` of another length, a non-finite sample, or fewer than two distinct data values
/// (the denominator is zero).
///
/// ```
/// use jitterid_likelihood::validation::fit_percent;
/// let y = [0.0, 1.0, 2.0, 3.0];
/// assert_eq!(fit_percent(&y, &y).unwrap(), 100.0);
/// assert_eq!(fit_percent(&y, &[1.5; 4]).unwrap(), 0.0);
/// ```
pub fn fit_percent(y: &[f64], m: &[f64]) -> Result<f64, EstimateError> {
    if m.len() != y.len() {
        return Err(EstimateError::DataLength {
            expected: y.len(),
            got: m.len(),
        });
    }
    for (index, &value) in y.iter().chain(m).enumerate() {
        if !value.is_finite() {
            return Err(EstimateError::NonFiniteData {
                index: index % y.len().max(1),
                value,
            });
        }
    }
    let mean = y.iter().sum::<f64>() / y.len().max(1) as f64;
    let spread = y.iter().map(|v| (v - mean).powi(2)).sum::<f64>().sqrt();
    if !(spread > 0.0) {
        return Err(EstimateError::TooFewData {
            what: "distinct data values",
            available: usize::from(!y.is_empty()),
            params: 2,
        });
    }
    let miss = y
        .iter()
        .zip(m)
        .map(|(a, b)| (a - b).powi(2))
        .sum::<f64>()
        .sqrt();
    Ok(100.0 * (1.0 - miss / spread))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_definition_and_names_bad_input() {
        // ‖y − ȳ‖ = √5 (ȳ = 1.5), ‖y − m‖ = 1: 100 (1 − 1/√5).
        let y = [0.0, 1.0, 2.0, 3.0];
        let m = [0.0, 1.0, 2.0, 2.0];
        let want = 100.0 * (1.0 - 1.0 / 5f64.sqrt());
        assert!((fit_percent(&y, &m).unwrap() - want).abs() < 1e-12);
        assert!(matches!(
            fit_percent(&y, &m[..3]),
            Err(EstimateError::DataLength {
                expected: 4,
                got: 3
            })
        ));
        assert!(matches!(
            fit_percent(&[2.0; 4], &m),
            Err(EstimateError::TooFewData { .. })
        ));
        assert!(matches!(
            fit_percent(&y, &[0.0, f64::NAN, 0.0, 0.0]),
            Err(EstimateError::NonFiniteData { index: 1, .. })
        ));
    }
}
