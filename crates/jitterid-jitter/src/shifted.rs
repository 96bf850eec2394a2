//! A jitter family moved by a constant offset.

use crate::error::finite;
use crate::model::{cexp, phasor, Atom};
use crate::{JitterError, JitterModel};
use num_complex::Complex64;
use rand::RngCore;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// `τ = c + τ'`: the jitter `τ'` of an inner family plus a constant offset `c` (seconds, any
/// sign), for instance a fixed sensor latency on top of a random one.
///
/// Parameters are `[offset, inner parameters…]`, named `"offset"` followed by the inner names.
/// `γ(f) = e^{-i2πfc} γ'(f)`, `M(z) = e^{zc} M'(z)`; the density, atoms and pieces are those of
/// the inner family moved by `c`.
///
/// Nodes of its quadrature rules are `c + τ'`, so an offset much larger than the inner spread
/// costs relative precision in `τ - c` (about `ε|c|/σ'`).
///
/// ```
/// use jitterid_jitter::{Gaussian, JitterModel, Shifted};
/// let j = Shifted::new(Gaussian::new(0.01).unwrap(), 0.05).unwrap();
/// assert_eq!(j.params(), vec![0.05, 0.01]);
/// assert_eq!(j.param_names(), vec!["offset", "sigma"]);
/// assert_eq!(j.mean(), 0.05);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "ShiftedRaw<J>")]
#[serde(bound(deserialize = "J: JitterModel + Deserialize<'de>"))]
pub struct Shifted<J> {
    inner: J,
    offset: f64,
}

/// Unvalidated form, so that deserialisation goes through [`Shifted::new`].
#[derive(Deserialize)]
struct ShiftedRaw<J> {
    inner: J,
    offset: f64,
}

impl<J: JitterModel> TryFrom<ShiftedRaw<J>> for Shifted<J> {
    type Error = JitterError;
    fn try_from(raw: ShiftedRaw<J>) -> Result<Self, JitterError> {
        Shifted::new(raw.inner, raw.offset)
    }
}

impl<J: JitterModel> Shifted<J> {
    /// `inner` moved by `offset` seconds; `offset` must be finite.
    pub fn new(inner: J, offset: f64) -> Result<Self, JitterError> {
        Ok(Shifted {
            inner,
            offset: finite("offset", offset)?,
        })
    }

    /// The inner family.
    pub fn inner(&self) -> &J {
        &self.inner
    }

    /// The constant offset `c`.
    pub fn offset(&self) -> f64 {
        self.offset
    }
}

impl<J: JitterModel> JitterModel for Shifted<J> {
    fn name(&self) -> &'static str {
        "shifted"
    }

    fn even_params(&self) -> Vec<bool> {
        // γ = e^{-i2πf·offset}·γ_inner: the offset enters linearly in the phase.
        let mut e = vec![false];
        e.extend(self.inner.even_params());
        e
    }

    fn param_names(&self) -> Vec<String> {
        let mut names = vec!["offset".to_string()];
        names.extend(self.inner.param_names());
        names
    }

    fn params(&self) -> Vec<f64> {
        let mut p = vec![self.offset];
        p.extend(self.inner.params());
        p
    }

    fn with_params(&self, params: &[f64]) -> Result<Self, JitterError> {
        let expected = 1 + self.inner.num_params();
        if params.len() != expected {
            return Err(JitterError::WrongParamCount {
                model: self.name(),
                expected,
                got: params.len(),
            });
        }
        Shifted::new(self.inner.with_params(&params[1..])?, params[0])
    }

    fn cf(&self, f: f64) -> Complex64 {
        phasor(f * self.offset) * self.inner.cf(f)
    }

    fn cf_gradient(&self, f: f64) -> Vec<Complex64> {
        let e = phasor(f * self.offset);
        let g = e * self.inner.cf(f);
        // ∂γ/∂c = -i2πf γ = 2πf (Im γ - i Re γ), by components so that a zero component
        // never meets 2πf = ∞ (which would give NaN; the true derivative is then ±∞ or 0).
        let w = 2.0 * PI * f;
        let mul = |x: f64| if x == 0.0 { 0.0 } else { w * x };
        let mut grad = vec![Complex64::new(mul(g.im), -mul(g.re))];
        grad.extend(self.inner.cf_gradient(f).into_iter().map(|d| d * e));
        grad
    }

    fn mgf(&self, z: Complex64) -> Option<Complex64> {
        let m = self.inner.mgf(z)?;
        let e = cexp(z * self.offset);
        if e.im == 0.0 && m.im == 0.0 {
            // Real product, so that an overflow is +∞ and not ∞·0 = NaN.
            Some(Complex64::new(e.re * m.re, 0.0))
        } else {
            Some(e * m)
        }
    }

    fn pdf(&self, tau: f64) -> f64 {
        self.inner.pdf(tau - self.offset)
    }

    fn atoms(&self) -> Vec<Atom> {
        self.inner
            .atoms()
            .into_iter()
            .map(|a| Atom {
                position: a.position + self.offset,
                mass: a.mass,
            })
            .collect()
    }

    fn pieces(&self) -> Vec<(f64, f64)> {
        self.inner
            .pieces()
            .into_iter()
            .map(|(lo, hi)| (lo + self.offset, hi + self.offset))
            .collect()
    }

    /// The inner family's reach, moved: a family whose support reaches beyond its pieces and
    /// atoms (the periodic family's ends) keeps it.
    fn reach(&self) -> (f64, f64) {
        let (lo, hi) = self.inner.reach();
        (lo + self.offset, hi + self.offset)
    }

    fn mean(&self) -> f64 {
        self.offset + self.inner.mean()
    }

    fn variance(&self) -> f64 {
        self.inner.variance()
    }

    fn sample(&self, rng: &mut dyn RngCore) -> f64 {
        self.offset + self.inner.sample(rng)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ExponentialDelay, Laplace, NoJitter, TwoPoint, UniformSum};

    #[test]
    fn constructor_validates() {
        let g = Laplace::new(1.0).unwrap();
        assert!(matches!(
            Shifted::new(g, f64::NAN),
            Err(JitterError::NotFinite { name: "offset", .. })
        ));
        assert!(matches!(
            Shifted::new(g, f64::INFINITY),
            Err(JitterError::NotFinite { .. })
        ));
        assert!(Shifted::new(g, 0.0).is_ok());
        assert!(Shifted::new(g, -3.0).is_ok());
    }

    #[test]
    fn with_params_splits_the_vector() {
        let j = Shifted::new(UniformSum::new(3, 0.5).unwrap(), 0.1).unwrap();
        let k = j.with_params(&[-0.2, 0.7]).unwrap();
        assert_eq!(k.offset(), -0.2);
        assert_eq!(k.inner(), &UniformSum::new(3, 0.7).unwrap());
        assert!(matches!(
            j.with_params(&[0.1]),
            Err(JitterError::WrongParamCount {
                model: "shifted",
                expected: 2,
                got: 1
            })
        ));
        assert!(matches!(
            j.with_params(&[0.1, -1.0]),
            Err(JitterError::NotPositive { name: "a", .. })
        ));
    }

    #[test]
    fn shifting_a_dirac_gives_a_pure_delay() {
        let j = Shifted::new(NoJitter::new(), 0.25).unwrap();
        assert!((j.cf(1.0) - Complex64::new(0.0, -1.0)).norm() < 1e-16);
        assert_eq!(j.reach(), (0.25, 0.25));
        assert_eq!(j.atoms()[0].position, 0.25);
    }

    #[test]
    fn shifted_moments_and_nesting() {
        let j = Shifted::new(
            Shifted::new(ExponentialDelay::new(0.5).unwrap(), 1.0).unwrap(),
            -0.5,
        )
        .unwrap();
        assert_eq!(j.mean(), 1.0);
        assert_eq!(j.variance(), 0.25);
        assert_eq!(j.params(), vec![-0.5, 1.0, 0.5]);
        assert_eq!(j.reach().0, 0.5);
        let t = Shifted::new(TwoPoint::new(1.0).unwrap(), 2.0).unwrap();
        let pos: Vec<f64> = t.atoms().iter().map(|a| a.position).collect();
        assert_eq!(pos, vec![1.0, 3.0]);
    }

    #[test]
    fn serde_round_trip_validates() {
        let j = Shifted::new(Laplace::new(0.5).unwrap(), 0.125).unwrap();
        let s = serde_json::to_string(&j).unwrap();
        assert_eq!(serde_json::from_str::<Shifted<Laplace>>(&s).unwrap(), j);
        let bad = r#"{"inner":{"b":-0.5},"offset":0.0}"#;
        assert!(serde_json::from_str::<Shifted<Laplace>>(bad).is_err());
    }
}
