//! Log-spaced frequency grids for frequency responses.

use jitterid_estimate::EstimateError;

/// `n` frequencies from `lo` to `hi` (both included), equally spaced on a log scale.
///
/// Errors ([`EstimateError::BadArgument`]): `lo` not finite and > 0, `hi` not finite and
/// > `lo`, or `n < 2`.
///
/// ```
/// let f = jitterid_likelihood::validation::log_spaced(0.1, 10.0, 3).unwrap();
/// assert!((f[1] - 1.0).abs() < 1e-12);
/// ```
pub fn log_spaced(lo: f64, hi: f64, n: usize) -> Result<Vec<f64>, EstimateError> {
    let bad = |name: &'static str, value: f64, reason: &'static str| {
        Err(EstimateError::BadArgument {
            name,
            value,
            reason,
        })
    };
    if !(lo.is_finite() && lo > 0.0) {
        return bad("lo", lo, "must be finite and > 0");
    }
    if !(hi.is_finite() && hi > lo) {
        return bad("hi", hi, "must be finite and > lo");
    }
    if n < 2 {
        return bad("n", n as f64, "must be at least 2");
    }
    let ratio = hi / lo;
    Ok((0..n)
        .map(|i| {
            if i + 1 == n {
                hi
            } else {
                lo * ratio.powf(i as f64 / (n - 1) as f64)
            }
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ends_and_ratio_and_bad_arguments() {
        let f = log_spaced(0.01, 100.0, 5).unwrap();
        assert_eq!((f[0], f[4]), (0.01, 100.0));
        for w in f.windows(2) {
            assert!((w[1] / w[0] - 10.0).abs() < 1e-12);
        }
        for (lo, hi, n) in [
            (0.0, 1.0, 3),
            (1.0, 1.0, 3),
            (1.0, f64::NAN, 3),
            (1.0, 2.0, 1),
        ] {
            assert!(matches!(
                log_spaced(lo, hi, n),
                Err(EstimateError::BadArgument { .. })
            ));
        }
    }
}
