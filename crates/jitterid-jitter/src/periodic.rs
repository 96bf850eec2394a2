//! Periodic (sinusoidal) jitter: the arcsine law of a clock disturbed by a tone.

use crate::kernels::bessel::{i0_real, j0_complex, j0_j1};
use crate::kernels::validate::{param_count, positive};
use crate::rule::QuadratureRule;
use crate::{Atom, JitterError, JitterModel};
use num_complex::Complex64;
use rand::{Rng, RngCore};
use serde::{Deserialize, Serialize};
use std::f64::consts::{FRAC_PI_2, PI};

/// Distance from `±A`, relative to `A`, of the innermost knot of the pieces: the law's mass
/// closer to an end than this is lumped into an [`Atom`] at its own mean.
///
/// Quadrature nodes are stored as `τ`, so `A − τ` carries an absolute rounding error of about
/// `ε A`, and the density `1/(π√(A² − τ²))` evaluated at distance `d` from an end a relative
/// error of about `ε/(2d/A)`. At `d = 2^{-20} A` that is `1e-10` on pieces that carry less than
/// `1e-3` of the mass, so the pieces lose less than `1e-13` in all. (At `2^{-40}` the
/// pieces' mass is off by `2e-11`.) The lumped mass, `(1/π) acos(1 − 2^{-20}) ≈ 4.4e-4` per
/// end, has a spread of `√(4/45)·d`; at its conditional mean it changes `E[h(τ)]` by about
/// mass × variance × `h''/2 ≈ 2e-17 A² h''`, far below rounding for every `h` that is smooth
/// on the scale `2^{-20} A`.
const END_GAP: f64 = 1.0 / 1_048_576.0;

/// Ratio of successive distances to an end of the graded pieces. A piece `[A − 4d, A − d]` sees
/// the singularity at `A` at 5/3 of its half-width from its centre, where a 16-point
/// Gauss–Legendre rule converges like `3^{-32} ≈ 5e-16` relative.
const GRADING: f64 = 4.0;

/// Periodic jitter `τ = A sin φ` with `φ` uniform on `[0, 2π)`: the sampling clock is
/// modulated by a tone of amplitude `A` (seconds) whose phase at each sample is random.
///
/// Arcsine law on `[-A, A]`: density `1/(π√(A² − τ²))`, mean 0, variance `A²/2`,
/// `γ(f) = J₀(2πfA)` (not damped faster than `|f|^{-1/2}`), `M(z) = I₀(zA)`.
///
/// The density is infinite at `±A` (integrably). Expectation [rules](JitterModel::rule) do not
/// integrate it at all: they use the substitution `τ = A sin φ` that defines the law, so that
/// `E[h(τ)] = (1/π)∫_{-π/2}^{π/2} h(A sin φ) dφ` has a smooth integrand, and Gauss–Legendre in
/// `φ` converges exponentially. (A double-exponential rule, as in the `quadrature` crate,
/// also integrates the endpoint singularity, but it would give a different rule for every
/// integrand; here the change of variable removes the singularity once for every `h`.) The
/// [pieces](JitterModel::pieces), for callers that integrate the density themselves, are
/// graded geometrically towards `±A`, and the mass closest to each end is an [`Atom`]
/// (see the crate source for the error bound).
///
/// ```
/// use jitterid_jitter::{JitterModel, Periodic};
/// let j = Periodic::new(0.2).unwrap();
/// assert!((j.variance() - 0.02).abs() < 1e-17);
/// // J₀ has its first zero at 2.404825557695773: a zero of γ.
/// assert!(j.cf(2.404825557695773 / (2.0 * std::f64::consts::PI * 0.2)).re.abs() < 1e-15);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "PeriodicRaw")]
pub struct Periodic {
    amplitude: f64,
}

/// Unvalidated form, so that deserialisation goes through [`Periodic::new`].
#[derive(Deserialize)]
struct PeriodicRaw {
    amplitude: f64,
}

impl TryFrom<PeriodicRaw> for Periodic {
    type Error = JitterError;
    fn try_from(raw: PeriodicRaw) -> Result<Self, JitterError> {
        Periodic::new(raw.amplitude)
    }
}

impl Periodic {
    /// Periodic jitter of amplitude `amplitude` (seconds), finite and `> 0`.
    pub fn new(amplitude: f64) -> Result<Self, JitterError> {
        Ok(Periodic {
            amplitude: positive("amplitude", amplitude)?,
        })
    }

    /// The amplitude `A`.
    pub fn amplitude(&self) -> f64 {
        self.amplitude
    }

    /// The end atoms: mass `(1/π) acos(1 − δ)` each, at the conditional mean
    /// `±A cos φ₀/(π/2 − φ₀)`, `sin φ₀ = 1 − δ`, `δ =` [`END_GAP`].
    fn end_atom(&self) -> (f64, f64) {
        // π/2 − φ₀ = acos(1 − δ) = 2 asin(√(δ/2)), without cancellation.
        let width = 2.0 * (0.5 * END_GAP).sqrt().asin();
        let mass = width / PI;
        // cos φ₀ = sin(π/2 − φ₀).
        let position = self.amplitude * width.sin() / width;
        (position, mass)
    }

    /// The knots of the right half, `A/2` and the graded points towards `A`, increasing.
    fn right_knots(&self) -> Vec<f64> {
        let a = self.amplitude;
        let mut knots = vec![0.5 * a];
        let mut d = 0.5;
        while d / GRADING >= END_GAP {
            d /= GRADING;
            knots.push(a - d * a);
        }
        knots.push(a - END_GAP * a);
        knots
    }
}

impl JitterModel for Periodic {
    fn name(&self) -> &'static str {
        "periodic"
    }

    fn param_names(&self) -> Vec<String> {
        vec!["amplitude".to_string()]
    }

    fn even_params(&self) -> Vec<bool> {
        // A law symmetric about 0 and scaled by its one parameter: γ is even in it.
        vec![true]
    }

    fn params(&self) -> Vec<f64> {
        vec![self.amplitude]
    }

    fn with_params(&self, params: &[f64]) -> Result<Self, JitterError> {
        param_count(self.name(), 1, params)?;
        Periodic::new(params[0])
    }

    fn cf(&self, f: f64) -> Complex64 {
        Complex64::new(j0_j1(f * self.amplitude).0, 0.0)
    }

    fn cf_gradient(&self, f: f64) -> Vec<Complex64> {
        // ∂J₀(2πfA)/∂A = −2πf J₁(2πfA); J₁ is 0 (not NaN) where 2πfA overflows, and f·J₁
        // is formed first so that 2πf alone cannot overflow.
        let j1 = j0_j1(f * self.amplitude).1;
        let d = if j1 == 0.0 { 0.0 } else { -2.0 * PI * (f * j1) };
        vec![Complex64::new(d, 0.0)]
    }

    fn mgf(&self, z: Complex64) -> Option<Complex64> {
        let w = z * self.amplitude;
        if w.im == 0.0 {
            // Real path, so that an overflow is +∞ and not ∞·0 = NaN.
            return Some(Complex64::new(i0_real(w.re), 0.0));
        }
        // I₀(w) = J₀(iw).
        Some(j0_complex(Complex64::new(-w.im, w.re)))
    }

    fn pdf(&self, tau: f64) -> f64 {
        let a = self.amplitude;
        if !(tau.abs() < a) {
            return 0.0;
        }
        // A² − τ² as (A − |τ|)(A + |τ|): exact difference near the ends.
        let t = tau.abs();
        1.0 / (PI * ((a - t) * (a + t)).sqrt())
    }

    fn atoms(&self) -> Vec<Atom> {
        let (position, mass) = self.end_atom();
        vec![
            Atom {
                position: -position,
                mass,
            },
            Atom { position, mass },
        ]
    }

    fn pieces(&self) -> Vec<(f64, f64)> {
        let right = self.right_knots();
        let mut knots: Vec<f64> = right.iter().rev().map(|k| -k).collect();
        knots.extend(right);
        knots.windows(2).map(|w| (w[0], w[1])).collect()
    }

    fn mean(&self) -> f64 {
        0.0
    }

    fn variance(&self) -> f64 {
        0.5 * self.amplitude * self.amplitude
    }

    fn sample(&self, rng: &mut dyn RngCore) -> f64 {
        let phi: f64 = rng.random_range(-FRAC_PI_2..FRAC_PI_2);
        self.amplitude * phi.sin()
    }

    fn reach(&self) -> (f64, f64) {
        (-self.amplitude, self.amplitude)
    }

    fn rule(&self, breaks: &[f64], rate: f64) -> QuadratureRule {
        self.rule_from(f64::NEG_INFINITY, breaks, rate)
    }

    fn rule_from(&self, from: f64, breaks: &[f64], rate: f64) -> QuadratureRule {
        let a = self.amplitude;
        let mut rule = QuadratureRule::default();
        if from > a {
            return rule;
        }
        // E[h(τ) 1{τ ≥ from}] = (1/π)∫_{φ_from}^{π/2} h(A sin φ) dφ, cut at asin(b/A) for
        // every break b inside, and refined so that (rate·A + 2)·Δφ ≤ 6: dτ/dφ ≤ A, and
        // sin φ itself varies at rate 1 (2 leaves room for h polynomial of low degree).
        let lo = if from > -a {
            (from / a).asin()
        } else {
            -FRAC_PI_2
        };
        let mut cuts: Vec<f64> = breaks
            .iter()
            .filter(|&&b| b > -a && b < a)
            .map(|&b| (b / a).asin())
            .filter(|&p| p > lo && p < FRAC_PI_2)
            .collect();
        cuts.sort_by(f64::total_cmp);
        let speed = if rate.is_finite() && rate > 0.0 {
            rate * a + 2.0
        } else {
            2.0
        };
        // Gauss–Legendre in φ with the uniform density 1/π, then τ = A sin φ.
        let mut start = lo;
        for end in cuts.into_iter().chain(std::iter::once(FRAC_PI_2)) {
            rule.push_interval(start, end, speed, |_| 1.0 / PI);
            start = end;
        }
        rule.nodes.iter_mut().for_each(|phi| *phi = a * phi.sin());
        rule
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::check_contract;

    #[test]
    fn passes_the_contract() {
        for a in [1e-9, 0.05, 0.3, 4.0] {
            check_contract(&Periodic::new(a).unwrap(), 3).unwrap();
        }
    }

    #[test]
    fn constructor_validates() {
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(Periodic::new(bad).is_err());
        }
        assert!(serde_json::from_str::<Periodic>(r#"{"amplitude":-1}"#).is_err());
        let j: Periodic = serde_json::from_str(r#"{"amplitude":0.5}"#).unwrap();
        assert_eq!(j.amplitude(), 0.5);
    }

    #[test]
    fn pieces_and_end_atoms_integrate_like_the_substitution_rule() {
        // Two independent routes to E[h(τ)]: graded Gauss–Legendre on the density plus the
        // end atoms (the default rule of the trait), and the φ-substitution.
        let j = Periodic::new(0.7).unwrap();
        let by_pieces = crate::rule::build_rule_from(&j, f64::NEG_INFINITY, &[], 0.0);
        let by_phi = j.rule(&[], 0.0);
        // Both converge to rounding for analytic h.
        for h in [|t: f64| t * t, |t: f64| t.powi(4), |t: f64| (3.0 * t).cos()] {
            let (p, q) = (by_pieces.expect(h), by_phi.expect(h));
            assert!(
                (p - q).abs() < 1e-13,
                "{p} vs {q}, mass {}",
                by_pieces.mass()
            );
        }
        // E[τ⁴] = 3A⁴/8 in closed form.
        assert!((by_phi.expect(|t| t.powi(4)) - 3.0 * 0.7f64.powi(4) / 8.0).abs() < 1e-15);
        // A break is honoured: E[max(τ − 0.2, 0)] = (1/π)(√(A² − b²) − b acos(b/A)).
        let b: f64 = 0.2;
        let exact = ((0.49 - b * b).sqrt() - b * (b / 0.7f64).acos()) / PI;
        let r = j.rule(&[b], 0.0);
        assert!((r.expect(|t| (t - b).max(0.0)) - exact).abs() < 1e-15);
        let r = j.rule_from(b, &[], 0.0);
        assert!((r.expect(|t| t - b) - exact).abs() < 1e-15);
    }
}
