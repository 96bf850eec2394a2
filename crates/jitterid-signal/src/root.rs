//! The roots of a [`Zpk`](crate::Zpk) model's numerator and denominator: a real root, a
//! complex-conjugate pair, or a quadratic factor whose two roots may be either.
//!
//! Why a quadratic factor: two real roots `p, q` parametrised as themselves have a singular
//! Jacobian where they coincide (`∂(s−p)(s−q)/∂p = ∂/∂q` at `p = q`), so a search that brings
//! them together stops there with no covariance, and it cannot go on into the complex pair the
//! data may prefer. The factor `s² + a1·s + a0` has the same two roots, a Jacobian of full rank
//! everywhere, and passes through coincidence from two real roots into a pair, as a `tf`
//! denominator does.

use crate::error::{finite, SignalError};
use num_complex::Complex64;
use serde_json::{json, Value};

/// A real root of a polynomial, a complex-conjugate pair `re ± i·im` with `im > 0`, or the two
/// roots of a monic quadratic factor `s² + a1·s + a0`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Root {
    /// A real root.
    Real(f64),
    /// The pair `re ± i·im`.
    Pair {
        /// Real part.
        re: f64,
        /// Imaginary part (> 0).
        im: f64,
    },
    /// The two roots of `s² + a1·s + a0`: real (distinct or repeated) when `a1² ≥ 4·a0`,
    /// otherwise a complex-conjugate pair. Parameters `a1`, `a0`.
    Quadratic {
        /// The coefficient of `s`: minus the sum of the two roots.
        a1: f64,
        /// The constant coefficient: the product of the two roots.
        a0: f64,
    },
}

impl Root {
    /// The factor of the repeated real root `x` (a double root), `(s − x)²`.
    pub fn double(x: f64) -> Self {
        Root::Quadratic {
            a1: -2.0 * x,
            a0: x * x,
        }
    }

    pub(crate) fn validate(&self, name: &'static str) -> Result<(), SignalError> {
        match *self {
            Root::Real(x) => finite(name, x).map(|_| ()),
            Root::Pair { re, im } => {
                finite(name, re)?;
                finite(name, im)?;
                if im > 0.0 {
                    Ok(())
                } else {
                    Err(SignalError::BadPair { name, value: im })
                }
            }
            Root::Quadratic { a1, a0 } => {
                finite(name, a1)?;
                finite(name, a0).map(|_| ())
            }
        }
    }

    /// How many roots (and parameters) it stands for: 1 or 2.
    pub fn count(&self) -> usize {
        match self {
            Root::Real(_) => 1,
            Root::Pair { .. } | Root::Quadratic { .. } => 2,
        }
    }

    /// Monic factor `(s − x)`, `(s² − 2re·s + re² + im²)` or `(s² + a1·s + a0)`, and its
    /// derivatives with respect to the root's parameters.
    pub(crate) fn factor(&self) -> (Vec<f64>, Vec<Vec<f64>>) {
        match *self {
            Root::Real(x) => (vec![1.0, -x], vec![vec![0.0, -1.0]]),
            Root::Pair { re, im } => (
                vec![1.0, -2.0 * re, re * re + im * im],
                vec![vec![0.0, -2.0, 2.0 * re], vec![0.0, 0.0, 2.0 * im]],
            ),
            Root::Quadratic { a1, a0 } => (
                vec![1.0, a1, a0],
                vec![vec![0.0, 1.0, 0.0], vec![0.0, 0.0, 1.0]],
            ),
        }
    }

    /// The roots themselves (a pair and a quadratic with complex roots give `re + i·im` first).
    pub fn values(&self) -> Vec<Complex64> {
        match *self {
            Root::Real(x) => vec![Complex64::new(x, 0.0)],
            Root::Pair { re, im } => vec![Complex64::new(re, im), Complex64::new(re, -im)],
            Root::Quadratic { a1, a0 } => {
                let (h, disc) = (-0.5 * a1, 0.25 * a1 * a1 - a0);
                if disc < 0.0 {
                    let im = (-disc).sqrt();
                    vec![Complex64::new(h, im), Complex64::new(h, -im)]
                } else {
                    // The larger root by the sum, the other by the product: the textbook
                    // `h ± √disc` would lose the small root to cancellation.
                    let big = h + h.signum() * disc.sqrt();
                    let small = if big == 0.0 { 0.0 } else { a0 / big };
                    vec![Complex64::new(big, 0.0), Complex64::new(small, 0.0)]
                }
            }
        }
    }

    /// The largest modulus of its roots.
    pub fn modulus(&self) -> f64 {
        self.values().iter().map(|v| v.norm()).fold(0.0, f64::max)
    }

    /// As a spec table writes it: a number for a real root, `[re, im]` for a pair,
    /// `{a1, a0}` for a quadratic factor ([`from_json`](Self::from_json) reads it back).
    pub fn to_json(&self) -> Value {
        match *self {
            Root::Real(x) => json!(x),
            Root::Pair { re, im } => json!([re, im]),
            Root::Quadratic { a1, a0 } => json!({"a1": a1, "a0": a0}),
        }
    }

    /// Reads [`to_json`](Self::to_json)'s forms; the error says what was found instead. Values
    /// are not validated here (finite, `im > 0`): the model's constructor does that.
    pub fn from_json(v: &Value) -> Result<Self, String> {
        let number = |x: &Value| {
            x.as_f64()
                .ok_or_else(|| format!("expected a number, found {x}"))
        };
        match v {
            Value::Array(a) if a.len() == 2 => Ok(Root::Pair {
                re: number(&a[0])?,
                im: number(&a[1])?,
            }),
            Value::Object(o) => {
                let key = |k: &str| {
                    o.get(k)
                        .ok_or_else(|| format!("a quadratic factor needs `{k}`, found {v}"))
                        .and_then(number)
                };
                if let Some(extra) = o.keys().find(|k| !["a1", "a0"].contains(&k.as_str())) {
                    return Err(format!(
                        "a quadratic factor has only `a1` and `a0`, found `{extra}`"
                    ));
                }
                Ok(Root::Quadratic {
                    a1: key("a1")?,
                    a0: key("a0")?,
                })
            }
            Value::Number(_) => number(v).map(Root::Real),
            other => Err(format!(
                "expected a number (a real root), [re, im] (a pair) or {{a1, a0}} (the roots of s² + a1·s + a0), found {other}"
            )),
        }
    }
}

/// `roots` with each real root that occurs twice (the same nonzero value, anywhere in the
/// list) replaced by one [`Root::Quadratic`] at the first one's place: a double pole written
/// as two equal real poles is estimated through its quadratic factor (see the module docs).
/// A root at 0 is left alone: it may be a structural integrator.
pub(crate) fn group_repeated(roots: Vec<Root>) -> Vec<Root> {
    let mut out: Vec<Root> = Vec::with_capacity(roots.len());
    let mut taken = vec![false; roots.len()];
    for i in 0..roots.len() {
        if taken[i] {
            continue;
        }
        if let Root::Real(x) = roots[i] {
            let twin = (i + 1..roots.len()).find(|&j| !taken[j] && roots[j] == Root::Real(x));
            if let (Some(j), true) = (twin, x != 0.0) {
                taken[j] = true;
                out.push(Root::double(x));
                continue;
            }
        }
        out.push(roots[i]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadratic_roots_multiply_back_to_the_factor() {
        for (a1, a0) in [
            (1.0, 0.25),
            (3.0, 2.0),
            (0.5, 1.0),
            (1e4, 1e-3),
            (-1.0, -6.0),
        ] {
            let v = Root::Quadratic { a1, a0 }.values();
            let (sum, prod) = (v[0] + v[1], v[0] * v[1]);
            assert!(
                (sum.re + a1).abs() <= 1e-12 * a1.abs().max(1.0),
                "{a1} {a0}: {v:?}"
            );
            assert!(
                (prod.re - a0).abs() <= 1e-12 * a0.abs().max(1e-300),
                "{a1} {a0}: {v:?}"
            );
            assert!(sum.im.abs() < 1e-12 && prod.im.abs() < 1e-12);
        }
        // The small root of a stiff factor keeps its digits.
        let v = Root::Quadratic { a1: 1e8, a0: 1.0 }.values();
        assert!((v[1].re + 1e-8).abs() < 1e-22, "{v:?}");
    }

    #[test]
    fn json_round_trips_every_form() {
        for r in [
            Root::Real(-0.5),
            Root::Pair { re: -0.25, im: 0.3 },
            Root::Quadratic { a1: 1.0, a0: 0.25 },
        ] {
            assert_eq!(Root::from_json(&r.to_json()), Ok(r));
        }
        assert!(Root::from_json(&json!({"a1": 1.0}))
            .unwrap_err()
            .contains("`a0`"));
        assert!(Root::from_json(&json!({"a1": 1.0, "a0": 2.0, "b": 1}))
            .unwrap_err()
            .contains("`b`"));
        assert!(Root::from_json(&json!("x")).is_err());
    }

    #[test]
    fn equal_real_roots_become_one_quadratic_factor() {
        let g = group_repeated(vec![
            Root::Real(-0.5),
            Root::Real(-2.0),
            Root::Real(-0.5),
            Root::Real(0.0),
            Root::Real(0.0),
        ]);
        assert_eq!(
            g,
            [
                Root::Quadratic { a1: 1.0, a0: 0.25 },
                Root::Real(-2.0),
                Root::Real(0.0),
                Root::Real(0.0)
            ]
        );
    }
}
