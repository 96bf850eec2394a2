//! Zero-mean Gaussian jitter.

use crate::error::{param_count, positive};
use crate::model::cexp;
use crate::{JitterError, JitterModel};
use num_complex::Complex64;
use rand::RngCore;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Half-width of the pieces in standard deviations: `P(|τ| > 8.6σ) = erfc(8.6/√2) ≈ 8.0e-18`,
/// below [`TAIL_MASS`](crate::TAIL_MASS).
const REACH_SIGMAS: f64 = 8.6;

/// Pieces per side. Width `8.6σ/9 < 1σ`: over one `σ` the density, seen from the middle of a
/// piece, is `e^{-αt}` times a mild quadratic with `|α| ≤ 4.3` on `t ∈ [-1, 1]`, which a
/// 16-point Gauss–Legendre rule integrates to far below `1e-15`.
const PIECES_PER_SIDE: usize = 9;

/// Zero-mean Gaussian jitter `τ ~ N(0, σ²)`.
///
/// `γ(f) = e^{-2π²σ²f²}`, `M(z) = e^{σ²z²/2}`. The paper uses it as a true jitter fitted by
/// the uniform-sum family (Table 1).
///
/// ```
/// use jitterid_jitter::{Gaussian, JitterModel};
/// let j = Gaussian::new(1.0 / 6.0).unwrap();
/// assert!((j.variance() - 1.0 / 36.0).abs() < 1e-17);
/// assert!((j.cf(1.0).re - (-2.0 * std::f64::consts::PI.powi(2) / 36.0).exp()).abs() < 1e-16);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "GaussianRaw")]
pub struct Gaussian {
    sigma: f64,
}

/// Unvalidated form, so that deserialisation goes through [`Gaussian::new`].
#[derive(Deserialize)]
struct GaussianRaw {
    sigma: f64,
}

impl TryFrom<GaussianRaw> for Gaussian {
    type Error = JitterError;
    fn try_from(raw: GaussianRaw) -> Result<Self, JitterError> {
        Gaussian::new(raw.sigma)
    }
}

impl Gaussian {
    /// Gaussian jitter with standard deviation `sigma` (seconds), which must be finite and
    /// `> 0` (use [`NoJitter`](crate::NoJitter) for none).
    pub fn new(sigma: f64) -> Result<Self, JitterError> {
        Ok(Gaussian {
            sigma: positive("sigma", sigma)?,
        })
    }

    /// The standard deviation `σ`.
    pub fn sigma(&self) -> f64 {
        self.sigma
    }
}

impl JitterModel for Gaussian {
    fn name(&self) -> &'static str {
        "gaussian"
    }

    fn param_names(&self) -> Vec<String> {
        vec!["sigma".to_string()]
    }

    fn even_params(&self) -> Vec<bool> {
        // A law symmetric about 0 and scaled by its one parameter: γ is even in it.
        vec![true]
    }

    fn params(&self) -> Vec<f64> {
        vec![self.sigma]
    }

    fn with_params(&self, params: &[f64]) -> Result<Self, JitterError> {
        param_count(self.name(), 1, params)?;
        Gaussian::new(params[0])
    }

    fn cf(&self, f: f64) -> Complex64 {
        let u = 2.0 * PI * self.sigma * f;
        Complex64::new((-0.5 * u * u).exp(), 0.0)
    }

    fn cf_gradient(&self, f: f64) -> Vec<Complex64> {
        // ∂γ/∂σ = -(u²/σ) γ with u = 2πσf; when γ underflows, u² may be infinite.
        let u = 2.0 * PI * self.sigma * f;
        let g = (-0.5 * u * u).exp();
        let d = if g == 0.0 {
            0.0
        } else {
            -u * u * g / self.sigma
        };
        vec![Complex64::new(d, 0.0)]
    }

    fn mgf(&self, z: Complex64) -> Option<Complex64> {
        Some(cexp(0.5 * self.sigma * self.sigma * z * z))
    }

    fn pdf(&self, tau: f64) -> f64 {
        let x = tau / self.sigma;
        (-0.5 * x * x).exp() / (self.sigma * (2.0 * PI).sqrt())
    }

    fn pieces(&self) -> Vec<(f64, f64)> {
        let w = REACH_SIGMAS * self.sigma / PIECES_PER_SIDE as f64;
        let n = PIECES_PER_SIDE as i64;
        // Knots k·w, k = -n..=n; symmetric by construction and 0 is a knot.
        (-n..n)
            .map(|k| (k as f64 * w, (k + 1) as f64 * w))
            .collect()
    }

    fn mean(&self) -> f64 {
        0.0
    }

    fn variance(&self) -> f64 {
        self.sigma * self.sigma
    }

    fn sample(&self, rng: &mut dyn RngCore) -> f64 {
        let z: f64 = StandardNormal.sample(rng);
        self.sigma * z
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constructor_validates() {
        assert!(matches!(
            Gaussian::new(f64::NAN),
            Err(JitterError::NotFinite { name: "sigma", .. })
        ));
        assert!(matches!(
            Gaussian::new(f64::INFINITY),
            Err(JitterError::NotFinite { .. })
        ));
        assert!(matches!(
            Gaussian::new(0.0),
            Err(JitterError::NotPositive { name: "sigma", .. })
        ));
        assert!(matches!(
            Gaussian::new(-1.0),
            Err(JitterError::NotPositive { .. })
        ));
        assert!(Gaussian::new(1e-300).is_ok());
    }

    #[test]
    fn tail_outside_pieces_is_below_tail_mass() {
        // Mills-ratio bound P(|Z| > c) ≤ 2φ(c)/c.
        let c = REACH_SIGMAS;
        let bound = 2.0 * (-0.5 * c * c).exp() / (2.0 * PI).sqrt() / c;
        assert!(bound < crate::TAIL_MASS, "{bound}");
        let j = Gaussian::new(2.0).unwrap();
        assert_eq!(j.reach(), (-c * 2.0, c * 2.0));
    }

    #[test]
    fn rule_moments_are_exact() {
        let j = Gaussian::new(0.3).unwrap();
        let r = j.rule(&[], 0.0);
        let s2 = 0.09;
        // Plain summation of N positive terms: rounding ≈ √N ε, allowed 4√N ε.
        let tol = 4.0 * (r.len() as f64).sqrt() * f64::EPSILON;
        assert!((r.mass() - 1.0).abs() < tol);
        // Moments of the truncated law: the tails beyond c = 8.6 carry
        // 2φ(c)c of E[Z²] and 2φ(c)(c³ + 3c) of E[Z⁴] (up to the mass 2Q(c) < 1e-17).
        let c = REACH_SIGMAS;
        let phi = (-0.5 * c * c).exp() / (2.0 * PI).sqrt();
        let m2 = (1.0 - 2.0 * phi * c) * s2;
        let m4 = (3.0 - 2.0 * phi * (c.powi(3) + 3.0 * c)) * s2 * s2;
        assert!((r.expect(|t| t * t) / m2 - 1.0).abs() < tol);
        assert!((r.expect(|t| t.powi(4)) / m4 - 1.0).abs() < tol);
    }

    #[test]
    fn cf_at_huge_frequency_is_zero_not_nan() {
        let j = Gaussian::new(1.0).unwrap();
        assert_eq!(j.cf(f64::MAX).re, 0.0);
        let g = j.cf_gradient(f64::MAX);
        assert_eq!(g[0].re, 0.0);
    }

    #[test]
    fn serde_validates() {
        let j = Gaussian::new(0.25).unwrap();
        let s = serde_json::to_string(&j).unwrap();
        assert_eq!(serde_json::from_str::<Gaussian>(&s).unwrap(), j);
        assert!(serde_json::from_str::<Gaussian>(r#"{"sigma":-1.0}"#).is_err());
    }
}
