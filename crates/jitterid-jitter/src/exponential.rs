//! One-sided exponential delay.

use crate::error::{param_count, positive};
use crate::{JitterError, JitterModel};
use num_complex::Complex64;
use rand::RngCore;
use rand_distr::{Distribution, Exp1};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Length of the support covered by pieces, in means: `P(τ > 40μ) = e^{-40} ≈ 4.2e-18`, below
/// [`TAIL_MASS`](crate::TAIL_MASS).
const REACH_MEANS: f64 = 40.0;

/// Pieces of width `2μ`: on each, the density is `e^{-t}` with `t` spanning 2, which a
/// 16-point Gauss–Legendre rule integrates to machine precision.
const PIECES: usize = 20;

/// Exponentially distributed delay `τ ≥ 0` with mean `μ`: `p(τ) = e^{-τ/μ}/μ`.
///
/// A one-sided jitter (a sensor that can only be late), so `γ(f) = 1/(1 + i2πfμ)` is complex.
/// `M(z) = 1/(1 - μz)` for `Re z < 1/μ`, mean `μ`, variance `μ²`.
///
/// ```
/// use jitterid_jitter::{ExponentialDelay, JitterModel};
/// let j = ExponentialDelay::new(0.01).unwrap();
/// assert_eq!(j.mean(), 0.01);
/// let g = j.cf(10.0);
/// assert!(g.im < 0.0 && (g - j.cf(-10.0).conj()).norm() == 0.0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "ExponentialDelayRaw")]
pub struct ExponentialDelay {
    mean: f64,
}

/// Unvalidated form, so that deserialisation goes through [`ExponentialDelay::new`].
#[derive(Deserialize)]
struct ExponentialDelayRaw {
    mean: f64,
}

impl TryFrom<ExponentialDelayRaw> for ExponentialDelay {
    type Error = JitterError;
    fn try_from(raw: ExponentialDelayRaw) -> Result<Self, JitterError> {
        ExponentialDelay::new(raw.mean)
    }
}

impl ExponentialDelay {
    /// Exponential delay with mean `mean` (seconds), finite and `> 0`.
    pub fn new(mean: f64) -> Result<Self, JitterError> {
        Ok(ExponentialDelay {
            mean: positive("mean", mean)?,
        })
    }

    /// `(γ, 1 - γ)` at `u = 2πfμ`, where `γ = 1/(1 + iu)`, without cancellation or overflow.
    fn gamma_and_complement(u: f64) -> (Complex64, Complex64) {
        if u.abs() <= 1.0 {
            let d = 1.0 + u * u;
            (Complex64::new(1.0, -u) / d, Complex64::new(u * u, u) / d)
        } else {
            // γ = r(r - i)/(1 + r²) and 1 - γ = (1 + ir)/(1 + r²) with r = 1/u.
            let r = 1.0 / u;
            let d = 1.0 + r * r;
            (Complex64::new(r * r, -r) / d, Complex64::new(1.0, r) / d)
        }
    }
}

impl JitterModel for ExponentialDelay {
    fn name(&self) -> &'static str {
        "exponential-delay"
    }

    fn param_names(&self) -> Vec<String> {
        vec!["mean".to_string()]
    }

    fn params(&self) -> Vec<f64> {
        vec![self.mean]
    }

    fn with_params(&self, params: &[f64]) -> Result<Self, JitterError> {
        param_count(self.name(), 1, params)?;
        ExponentialDelay::new(params[0])
    }

    fn cf(&self, f: f64) -> Complex64 {
        Self::gamma_and_complement(2.0 * PI * f * self.mean).0
    }

    fn cf_gradient(&self, f: f64) -> Vec<Complex64> {
        // ∂γ/∂μ = -iu/(μ(1+iu)²) = -γ(1-γ)/μ.
        let (g, c) = Self::gamma_and_complement(2.0 * PI * f * self.mean);
        vec![-(g * c) / self.mean]
    }

    fn mgf(&self, z: Complex64) -> Option<Complex64> {
        if z.re * self.mean < 1.0 {
            Some((1.0 - self.mean * z).inv())
        } else {
            None
        }
    }

    fn pdf(&self, tau: f64) -> f64 {
        if tau < 0.0 {
            0.0
        } else {
            (-tau / self.mean).exp() / self.mean
        }
    }

    fn pieces(&self) -> Vec<(f64, f64)> {
        let w = REACH_MEANS * self.mean / PIECES as f64;
        (0..PIECES)
            .map(|k| (k as f64 * w, (k + 1) as f64 * w))
            .collect()
    }

    fn mean(&self) -> f64 {
        self.mean
    }

    fn variance(&self) -> f64 {
        self.mean * self.mean
    }

    fn sample(&self, rng: &mut dyn RngCore) -> f64 {
        let e: f64 = Exp1.sample(rng);
        self.mean * e
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constructor_validates() {
        assert!(matches!(
            ExponentialDelay::new(f64::NAN),
            Err(JitterError::NotFinite { name: "mean", .. })
        ));
        assert!(matches!(
            ExponentialDelay::new(f64::INFINITY),
            Err(JitterError::NotFinite { .. })
        ));
        assert!(matches!(
            ExponentialDelay::new(0.0),
            Err(JitterError::NotPositive { name: "mean", .. })
        ));
        assert!(matches!(
            ExponentialDelay::new(-0.1),
            Err(JitterError::NotPositive { .. })
        ));
    }

    #[test]
    fn cf_is_hermitian_and_matches_closed_form() {
        let j = ExponentialDelay::new(0.3).unwrap();
        for f in [1e-12, 0.01, 0.5, 0.53, 1.0, 7.0, 1e3, 1e12, 1e300, f64::MAX] {
            let (g, gm) = (j.cf(f), j.cf(-f));
            assert_eq!(gm, g.conj(), "f = {f}");
            let u = 2.0 * PI * f * 0.3;
            if u < 1e150 {
                let exact = Complex64::new(1.0, u).inv();
                assert!((g - exact).norm() <= 1e-15 * exact.norm(), "f = {f}");
            }
            assert!(g.norm() <= 1.0);
        }
    }

    #[test]
    fn gradient_keeps_precision_at_low_frequency() {
        let j = ExponentialDelay::new(2.0).unwrap();
        let g = j.cf_gradient(1e-10);
        // ∂γ/∂μ = -iu/(μ(1+iu)²) ≈ -i2πf for tiny u.
        let u = 2.0 * PI * 1e-10 * 2.0;
        let exact = Complex64::new(0.0, -u) / (2.0 * Complex64::new(1.0, u).powi(2));
        assert!((g[0] - exact).norm() < 1e-15 * exact.norm());
    }

    #[test]
    fn mgf_domain() {
        let j = ExponentialDelay::new(0.5).unwrap();
        assert!(j.mgf(Complex64::new(1.99, 5.0)).is_some());
        assert!(j.mgf(Complex64::new(2.0, 0.0)).is_none());
        assert_eq!(
            j.mgf(Complex64::new(-2.0, 0.0)),
            Some(Complex64::new(0.5, 0.0))
        );
    }
}
