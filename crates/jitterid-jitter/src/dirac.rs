//! No jitter: `τ ≡ 0`.

use crate::error::param_count;
use crate::model::Atom;
use crate::{JitterError, JitterModel};
use num_complex::Complex64;
use rand::RngCore;
use serde::{Deserialize, Serialize};

/// The degenerate jitter `τ ≡ 0`: samples are taken exactly when requested.
///
/// It has no parameters, `γ ≡ 1`, and a single atom of mass 1 at 0. Every estimator given
/// `NoJitter` reduces to its jitter-free form.
///
/// ```
/// use jitterid_jitter::{JitterModel, NoJitter};
/// let j = NoJitter::new();
/// assert_eq!(j.cf(123.0).re, 1.0);
/// assert_eq!(j.rule(&[], 0.0).expect(|t| (t + 1.0).ln()), 0.0);
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct NoJitter;

impl NoJitter {
    /// The (only) model without jitter.
    pub fn new() -> Self {
        NoJitter
    }
}

impl JitterModel for NoJitter {
    fn name(&self) -> &'static str {
        "none"
    }

    fn param_names(&self) -> Vec<String> {
        Vec::new()
    }

    fn params(&self) -> Vec<f64> {
        Vec::new()
    }

    fn with_params(&self, params: &[f64]) -> Result<Self, JitterError> {
        param_count(self.name(), 0, params)?;
        Ok(NoJitter)
    }

    fn cf(&self, _f: f64) -> Complex64 {
        Complex64::new(1.0, 0.0)
    }

    fn cf_gradient(&self, _f: f64) -> Vec<Complex64> {
        Vec::new()
    }

    fn mgf(&self, _z: Complex64) -> Option<Complex64> {
        Some(Complex64::new(1.0, 0.0))
    }

    fn pdf(&self, _tau: f64) -> f64 {
        0.0
    }

    fn atoms(&self) -> Vec<Atom> {
        vec![Atom {
            position: 0.0,
            mass: 1.0,
        }]
    }

    fn pieces(&self) -> Vec<(f64, f64)> {
        Vec::new()
    }

    fn mean(&self) -> f64 {
        0.0
    }

    fn variance(&self) -> f64 {
        0.0
    }

    fn sample(&self, _rng: &mut dyn RngCore) -> f64 {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn everything_is_trivial() {
        let j = NoJitter::new();
        assert_eq!(j.num_params(), 0);
        assert_eq!(j.cf(-1e300), Complex64::new(1.0, 0.0));
        assert_eq!(j.reach(), (0.0, 0.0));
        assert_eq!(j.std_dev(), 0.0);
        let r = j.rule(&[0.0, 1.0], 1e9);
        assert_eq!((r.nodes.clone(), r.weights.clone()), (vec![0.0], vec![1.0]));
    }

    #[test]
    fn with_params_takes_no_parameter() {
        let j = NoJitter::new();
        assert_eq!(j.with_params(&[]), Ok(NoJitter));
        assert!(matches!(
            j.with_params(&[0.0]),
            Err(JitterError::WrongParamCount {
                expected: 0,
                got: 1,
                ..
            })
        ));
    }
}
