//! Zero-mean Laplace (double-exponential) jitter.

use crate::error::{param_count, positive};
use crate::{JitterError, JitterModel};
use num_complex::Complex64;
use rand::{Rng, RngCore};
use rand_distr::{Distribution, Exp1};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Half-width of the pieces in units of `b`: `P(|τ| > 40b) = e^{-40} ≈ 4.2e-18`, below
/// [`TAIL_MASS`](crate::TAIL_MASS).
const REACH_SCALES: f64 = 40.0;

/// Pieces per side, of width `2b`: on each, the density is `e^{-t}` with `t` spanning 2, which
/// a 16-point Gauss–Legendre rule integrates to machine precision.
const PIECES_PER_SIDE: usize = 20;

/// Zero-mean Laplace jitter with scale `b`: `p(τ) = e^{-|τ|/b} / (2b)`.
///
/// `γ(f) = 1/(1 + (2πfb)²)`, `M(z) = 1/(1 - b²z²)` for `|Re z| < 1/b`, variance `2b²`.
/// The density has a kink at 0, which is a knot of its pieces.
///
/// ```
/// use jitterid_jitter::{JitterModel, Laplace};
/// let j = Laplace::new(0.1).unwrap();
/// assert!((j.variance() - 0.02).abs() < 1e-17);
/// assert!(j.mgf(20.0.into()).is_none()); // beyond the abscissa of convergence 1/b = 10
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "LaplaceRaw")]
pub struct Laplace {
    b: f64,
}

/// Unvalidated form, so that deserialisation goes through [`Laplace::new`].
#[derive(Deserialize)]
struct LaplaceRaw {
    b: f64,
}

impl TryFrom<LaplaceRaw> for Laplace {
    type Error = JitterError;
    fn try_from(raw: LaplaceRaw) -> Result<Self, JitterError> {
        Laplace::new(raw.b)
    }
}

impl Laplace {
    /// Laplace jitter with scale `b` (seconds), finite and `> 0`.
    pub fn new(b: f64) -> Result<Self, JitterError> {
        Ok(Laplace {
            b: positive("b", b)?,
        })
    }

    /// The scale `b`.
    pub fn b(&self) -> f64 {
        self.b
    }

    /// `(γ, 1 - γ)` at `u = 2πfb`, each without cancellation or overflow.
    fn gamma_and_complement(u: f64) -> (f64, f64) {
        if u.abs() <= 1.0 {
            let u2 = u * u;
            (1.0 / (1.0 + u2), u2 / (1.0 + u2))
        } else {
            // In r = 1/u, so that u² cannot overflow.
            let r2 = (1.0 / u).powi(2);
            (r2 / (1.0 + r2), 1.0 / (1.0 + r2))
        }
    }
}

impl JitterModel for Laplace {
    fn name(&self) -> &'static str {
        "laplace"
    }

    fn param_names(&self) -> Vec<String> {
        vec!["b".to_string()]
    }

    fn even_params(&self) -> Vec<bool> {
        // A law symmetric about 0 and scaled by its one parameter: γ is even in it.
        vec![true]
    }

    fn params(&self) -> Vec<f64> {
        vec![self.b]
    }

    fn with_params(&self, params: &[f64]) -> Result<Self, JitterError> {
        param_count(self.name(), 1, params)?;
        Laplace::new(params[0])
    }

    fn cf(&self, f: f64) -> Complex64 {
        Complex64::new(Self::gamma_and_complement(2.0 * PI * f * self.b).0, 0.0)
    }

    fn cf_gradient(&self, f: f64) -> Vec<Complex64> {
        // ∂γ/∂b = -2u²/(b(1+u²)²) = -2γ(1-γ)/b.
        let (g, c) = Self::gamma_and_complement(2.0 * PI * f * self.b);
        vec![Complex64::new(-2.0 * g * c / self.b, 0.0)]
    }

    fn mgf(&self, z: Complex64) -> Option<Complex64> {
        if z.re.abs() * self.b < 1.0 {
            let bz = self.b * z;
            Some((1.0 - bz * bz).inv())
        } else {
            None
        }
    }

    fn pdf(&self, tau: f64) -> f64 {
        (-tau.abs() / self.b).exp() / (2.0 * self.b)
    }

    fn pieces(&self) -> Vec<(f64, f64)> {
        let w = REACH_SCALES * self.b / PIECES_PER_SIDE as f64;
        let n = PIECES_PER_SIDE as i64;
        (-n..n)
            .map(|k| (k as f64 * w, (k + 1) as f64 * w))
            .collect()
    }

    fn mean(&self) -> f64 {
        0.0
    }

    fn variance(&self) -> f64 {
        2.0 * self.b * self.b
    }

    fn sample(&self, rng: &mut dyn RngCore) -> f64 {
        // An exponential magnitude with a fair random sign.
        let e: f64 = Exp1.sample(rng);
        if rng.random::<bool>() {
            self.b * e
        } else {
            -self.b * e
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constructor_validates() {
        assert!(matches!(
            Laplace::new(f64::NAN),
            Err(JitterError::NotFinite { name: "b", .. })
        ));
        assert!(matches!(
            Laplace::new(f64::NEG_INFINITY),
            Err(JitterError::NotFinite { .. })
        ));
        assert!(matches!(
            Laplace::new(0.0),
            Err(JitterError::NotPositive { name: "b", .. })
        ));
        assert!(matches!(
            Laplace::new(-2.0),
            Err(JitterError::NotPositive { .. })
        ));
    }

    #[test]
    fn tail_and_knot() {
        assert!((-REACH_SCALES).exp() < crate::TAIL_MASS);
        let j = Laplace::new(0.5).unwrap();
        assert!(j.pieces().iter().any(|&(_, hi)| hi == 0.0));
        assert_eq!(j.reach(), (-20.0, 20.0));
    }

    #[test]
    fn cf_is_accurate_at_small_and_huge_frequency() {
        let j = Laplace::new(1.0).unwrap();
        let u = 2.0 * PI * 1e-9;
        // 1 - γ = u² / (1 + u²) must keep full relative precision.
        let g = j.cf_gradient(1e-9);
        let exact = -2.0 * u * u / (1.0 + u * u).powi(2);
        assert!((g[0].re - exact).abs() < 1e-15 * exact.abs());
        assert_eq!(j.cf(f64::MAX).re, 0.0);
        let g = j.cf_gradient(f64::MAX);
        assert_eq!(g[0].re, 0.0);
    }

    #[test]
    fn rule_moments_are_exact() {
        let j = Laplace::new(0.2).unwrap();
        let r = j.rule(&[], 0.0);
        // Plain summation of N positive terms: rounding ≈ √N ε, allowed 4√N ε.
        let tol = 4.0 * (r.len() as f64).sqrt() * f64::EPSILON;
        assert!((r.mass() - 1.0).abs() < tol);
        // E[|τ/b|⁴] = 24, less the tails beyond c = 40: e^{-c}(c⁴ + 4c³ + 12c² + 24c + 24).
        let c = REACH_SCALES;
        let tail = (-c).exp() * (c.powi(4) + 4.0 * c.powi(3) + 12.0 * c * c + 24.0 * c + 24.0);
        let m4 = (24.0 - tail) * 0.2f64.powi(4);
        assert!((r.expect(|t| t.powi(4)) / m4 - 1.0).abs() < tol);
    }
}
