//! Validators for a family's constructor: each returns the value or a
//! [`JitterError`] that names the parameter. The tests themselves are those of
//! [`jitterid_numeric::validate`], whose error converts into a `JitterError` with `?`.
//!
//! ```
//! use jitterid_jitter::kernels::validate::{finite, param_count, positive};
//! use jitterid_jitter::JitterError;
//! assert_eq!(positive("amplitude", 0.5), Ok(0.5));
//! assert!(matches!(positive("amplitude", 0.0), Err(JitterError::NotPositive { .. })));
//! assert!(matches!(finite("offset", f64::NAN), Err(JitterError::NotFinite { .. })));
//! assert!(param_count("periodic", 1, &[0.1, 0.2]).is_err());
//! ```

use crate::JitterError;
use jitterid_numeric::validate as numeric;

/// Checks that `value` is finite; the error names the parameter.
pub fn finite(name: &'static str, value: f64) -> Result<f64, JitterError> {
    Ok(numeric::finite(name, value)?)
}

/// Checks that `value` is finite and strictly positive.
pub fn positive(name: &'static str, value: f64) -> Result<f64, JitterError> {
    Ok(numeric::positive(name, value)?)
}

/// Checks that `value` is finite and not negative.
pub fn non_negative(name: &'static str, value: f64) -> Result<f64, JitterError> {
    Ok(numeric::non_negative(name, value)?)
}

/// Checks the length of a parameter vector given to `with_params` (`model` is the family's
/// name).
pub fn param_count(
    model: &'static str,
    expected: usize,
    params: &[f64],
) -> Result<(), JitterError> {
    if params.len() == expected {
        Ok(())
    } else {
        Err(JitterError::WrongParamCount {
            model,
            expected,
            got: params.len(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_validator_names_the_parameter_and_rejects_nan() {
        for v in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            assert!(matches!(
                finite("x", v),
                Err(JitterError::NotFinite { name: "x", .. })
            ));
            assert!(matches!(
                positive("y", v),
                Err(JitterError::NotFinite { name: "y", .. })
            ));
            assert!(non_negative("z", v).is_err());
        }
        assert!(matches!(
            positive("y", -1.0),
            Err(JitterError::NotPositive { name: "y", .. })
        ));
        assert_eq!(non_negative("z", 0.0), Ok(0.0));
        assert!(matches!(
            non_negative("z", -1e-300),
            Err(JitterError::Negative { .. })
        ));
        assert_eq!(param_count("m", 2, &[1.0, 2.0]), Ok(()));
        assert!(matches!(
            param_count("m", 2, &[]),
            Err(JitterError::WrongParamCount {
                model: "m",
                expected: 2,
                got: 0
            })
        ));
    }
}
