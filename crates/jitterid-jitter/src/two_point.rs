//! Symmetric two-point jitter `τ = ±d`.

use crate::error::{param_count, positive};
use crate::model::{phasor, Atom};
use crate::{JitterError, JitterModel};
use num_complex::Complex64;
use rand::{Rng, RngCore};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Jitter that is `+d` or `-d` with probability 1/2 each (for instance a sampling clock that
/// alternates between two phases at random).
///
/// A purely discrete law: two [`Atom`]s, no pieces, `pdf ≡ 0`. `γ(f) = cos(2πfd)`, which is
/// not damped at high frequency, `M(z) = cosh(zd)`, variance `d²`.
///
/// ```
/// use jitterid_jitter::{JitterModel, TwoPoint};
/// let j = TwoPoint::new(0.25).unwrap();
/// assert!((j.cf(1.0).re).abs() < 1e-16); // cos(π/2)
/// assert_eq!(j.rule(&[], 0.0).expect(|t| t * t), 0.0625);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "TwoPointRaw")]
pub struct TwoPoint {
    d: f64,
}

/// Unvalidated form, so that deserialisation goes through [`TwoPoint::new`].
#[derive(Deserialize)]
struct TwoPointRaw {
    d: f64,
}

impl TryFrom<TwoPointRaw> for TwoPoint {
    type Error = JitterError;
    fn try_from(raw: TwoPointRaw) -> Result<Self, JitterError> {
        TwoPoint::new(raw.d)
    }
}

impl TwoPoint {
    /// Two-point jitter at `±d` (seconds); `d` finite and `> 0` (for `d = 0` use
    /// [`NoJitter`](crate::NoJitter)).
    pub fn new(d: f64) -> Result<Self, JitterError> {
        Ok(TwoPoint {
            d: positive("d", d)?,
        })
    }

    /// The half-distance `d` between the two points.
    pub fn d(&self) -> f64 {
        self.d
    }
}

impl JitterModel for TwoPoint {
    fn name(&self) -> &'static str {
        "two-point"
    }

    fn param_names(&self) -> Vec<String> {
        vec!["d".to_string()]
    }

    fn even_params(&self) -> Vec<bool> {
        // A law symmetric about 0 and scaled by its one parameter: γ is even in it.
        vec![true]
    }

    fn params(&self) -> Vec<f64> {
        vec![self.d]
    }

    fn with_params(&self, params: &[f64]) -> Result<Self, JitterError> {
        param_count(self.name(), 1, params)?;
        TwoPoint::new(params[0])
    }

    fn cf(&self, f: f64) -> Complex64 {
        // e^{-i2πfd} reduced modulo one period: cos(2πfd) is its real part.
        Complex64::new(phasor(f * self.d).re, 0.0)
    }

    fn cf_gradient(&self, f: f64) -> Vec<Complex64> {
        // ∂cos(2πfd)/∂d = -2πf sin(2πfd); Im e^{-i2πfd} = -sin(2πfd).
        let s = -phasor(f * self.d).im;
        let d = if s == 0.0 { 0.0 } else { -2.0 * PI * f * s };
        vec![Complex64::new(d, 0.0)]
    }

    fn mgf(&self, z: Complex64) -> Option<Complex64> {
        let w = z * self.d;
        if w.im == 0.0 {
            // Real path, so that an overflow is +∞ and not ∞·0 = NaN.
            Some(Complex64::new(w.re.cosh(), 0.0))
        } else {
            Some(w.cosh())
        }
    }

    fn pdf(&self, _tau: f64) -> f64 {
        0.0
    }

    fn atoms(&self) -> Vec<Atom> {
        vec![
            Atom {
                position: -self.d,
                mass: 0.5,
            },
            Atom {
                position: self.d,
                mass: 0.5,
            },
        ]
    }

    fn pieces(&self) -> Vec<(f64, f64)> {
        Vec::new()
    }

    fn mean(&self) -> f64 {
        0.0
    }

    fn variance(&self) -> f64 {
        self.d * self.d
    }

    fn sample(&self, rng: &mut dyn RngCore) -> f64 {
        if rng.random::<bool>() {
            self.d
        } else {
            -self.d
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constructor_validates() {
        assert!(matches!(
            TwoPoint::new(f64::NAN),
            Err(JitterError::NotFinite { name: "d", .. })
        ));
        assert!(matches!(
            TwoPoint::new(f64::INFINITY),
            Err(JitterError::NotFinite { .. })
        ));
        assert!(matches!(
            TwoPoint::new(0.0),
            Err(JitterError::NotPositive { name: "d", .. })
        ));
        assert!(matches!(
            TwoPoint::new(-1.0),
            Err(JitterError::NotPositive { .. })
        ));
    }

    #[test]
    fn cf_is_cosine_and_never_nan() {
        let j = TwoPoint::new(0.1).unwrap();
        for f in [0.0, 0.3, 2.5, 1e7 + 0.3, -4.0] {
            let exact = (2.0 * PI * f * 0.1).cos();
            assert!((j.cf(f).re - exact).abs() < 1e-9, "f = {f}");
        }
        for f in [1e300, f64::MAX, -f64::MAX] {
            assert!(j.cf(f).re.is_finite());
            let g = j.cf_gradient(f);
            assert!(g[0].re.is_finite());
        }
    }

    #[test]
    fn mgf_is_cosh() {
        let j = TwoPoint::new(2.0).unwrap();
        assert_eq!(j.mgf(Complex64::new(1.0, 0.0)).unwrap().re, 2f64.cosh());
        assert_eq!(
            j.mgf(Complex64::new(1e3, 0.0)).unwrap(),
            Complex64::new(f64::INFINITY, 0.0)
        );
    }
}
