//! A finite mixture of jitter laws.

use crate::kernels::pieces::merge_pieces;
use crate::rule::QuadratureRule;
use crate::sum::term_names;
use crate::{Atom, JitterError, JitterModel};
use num_complex::Complex64;
use rand::{Rng, RngCore};
use serde::{Deserialize, Serialize};

/// With probability `w_k`, `τ` is drawn from component `k`: for instance a clock that is
/// usually steady and sometimes disturbed.
///
/// `γ = Σ w_k γ_k`, `M = Σ w_k M_k`, density `Σ w_k p_k`, atoms and rules are the components'
/// scaled by their weights, and the pieces are the components' merged.
///
/// Parameters are the components' (named `terms.<k>.<name>`), followed, when the weights are
/// estimated, by `w_1 … w_{K−1}` (named `weights.<k>`); `w_0 = 1 − Σ_{k≥1} w_k`. With
/// [`fixed_weights`](Self::fixed_weights) they are structure, not parameters.
///
/// ```
/// use jitterid_jitter::{Gaussian, JitterModel, Mixture};
/// let g = |s| Gaussian::new(s).unwrap();
/// let m = Mixture::new(vec![g(0.01), g(0.1)], vec![0.9, 0.1]).unwrap();
/// assert!((m.variance() - (0.9e-4 + 0.1e-2)).abs() < 1e-18);
/// assert_eq!(m.param_names(), vec!["terms.0.sigma", "terms.1.sigma", "weights.1"]);
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "MixtureRaw<J>")]
#[serde(bound(deserialize = "J: JitterModel + Deserialize<'de>"))]
pub struct Mixture<J> {
    components: Vec<J>,
    weights: Vec<f64>,
    fixed_weights: bool,
}

/// Unvalidated form, so that deserialisation goes through [`Mixture::new`].
#[derive(Deserialize)]
struct MixtureRaw<J> {
    components: Vec<J>,
    weights: Vec<f64>,
    #[serde(default)]
    fixed_weights: bool,
}

impl<J: JitterModel> TryFrom<MixtureRaw<J>> for Mixture<J> {
    type Error = JitterError;
    fn try_from(raw: MixtureRaw<J>) -> Result<Self, JitterError> {
        let m = Mixture::new(raw.components, raw.weights)?;
        Ok(if raw.fixed_weights {
            m.with_fixed_weights()
        } else {
            m
        })
    }
}

/// Tolerance on `Σ w_k = 1` for given weights (rounding of a few decimal fractions).
const WEIGHT_SUM_TOL: f64 = 1e-12;

impl<J: JitterModel> Mixture<J> {
    /// A mixture of two or more `components` with `weights` (one each, in `(0, 1)`, summing to
    /// 1 within `1e-12`; they are renormalised). The weights are estimated parameters.
    ///
    /// Only `w_1 … w_{K−1}` are parameters, so the first weight is stored as
    /// `1 − Σ_{k≥1} w_k`, exactly as [`with_params`](JitterModel::with_params) rebuilds it:
    /// it may differ from the given (renormalised) `w_0` in the last bits.
    pub fn new(components: Vec<J>, weights: Vec<f64>) -> Result<Self, JitterError> {
        if components.len() < 2 {
            return Err(JitterError::OutOfRange {
                name: "terms",
                value: components.len() as f64,
                range: "two or more components",
            });
        }
        if weights.len() != components.len() {
            return Err(JitterError::WrongParamCount {
                model: "mixture",
                expected: components.len(),
                got: weights.len(),
            });
        }
        for &w in &weights {
            check_weight(w)?;
        }
        // Summed as w_0 + (w_1 + … + w_{K−1}), the association of `first_weight`: the weights
        // of a mixture built here then sum to exactly 1, so that rebuilding it from its own
        // weights (a spec table, serde) leaves them unchanged.
        let total = weights[0] + weights[1..].iter().sum::<f64>();
        if (total - 1.0).abs() > WEIGHT_SUM_TOL {
            return Err(JitterError::OutOfRange {
                name: "weights",
                value: total,
                range: "weights summing to 1",
            });
        }
        let mut weights: Vec<f64> = weights.iter().map(|w| w / total).collect();
        // w_0 is not a parameter: `with_params` derives it from the others, and so does the
        // constructor, so that `with_params(params())` rebuilds the mixture exactly (given
        // [0.3, 0.7], 1 − 0.7 is 0.30000000000000004, not the double nearest 0.3).
        weights[0] = check_weight(first_weight(&weights[1..]))?;
        Ok(Mixture {
            weights,
            components,
            fixed_weights: false,
        })
    }

    /// The same mixture with its weights known (not parameters).
    pub fn with_fixed_weights(mut self) -> Self {
        self.fixed_weights = true;
        self
    }

    /// Whether the weights are fixed.
    pub fn fixed_weights(&self) -> bool {
        self.fixed_weights
    }

    /// The components.
    pub fn components(&self) -> &[J] {
        &self.components
    }

    /// The weights.
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }
}

/// `w_0 = 1 − Σ_{k≥1} w_k`, the one formula of the first weight (constructor and
/// `with_params` alike).
fn first_weight(rest: &[f64]) -> f64 {
    1.0 - rest.iter().sum::<f64>()
}

fn check_weight(w: f64) -> Result<f64, JitterError> {
    if w > 0.0 && w < 1.0 {
        Ok(w)
    } else {
        Err(JitterError::OutOfRange {
            name: "weights",
            value: w,
            range: "(0, 1)",
        })
    }
}

impl<J: JitterModel + Clone> JitterModel for Mixture<J> {
    fn name(&self) -> &'static str {
        "mixture"
    }

    fn param_names(&self) -> Vec<String> {
        let mut names: Vec<String> = self
            .components
            .iter()
            .enumerate()
            .flat_map(|(k, c)| term_names(c, k))
            .collect();
        if !self.fixed_weights {
            names.extend((1..self.weights.len()).map(|k| format!("weights.{k}")));
        }
        names
    }

    fn params(&self) -> Vec<f64> {
        let mut p: Vec<f64> = self.components.iter().flat_map(|c| c.params()).collect();
        if !self.fixed_weights {
            p.extend_from_slice(&self.weights[1..]);
        }
        p
    }

    fn even_params(&self) -> Vec<bool> {
        // γ = Σ w_k γ_k: a component's parameter enters through that component only; the
        // weights linearly.
        let mut e: Vec<bool> = self
            .components
            .iter()
            .flat_map(|c| c.even_params())
            .collect();
        if !self.fixed_weights {
            e.extend(std::iter::repeat_n(false, self.weights.len() - 1));
        }
        e
    }

    fn num_params(&self) -> usize {
        let own: usize = self.components.iter().map(|c| c.num_params()).sum();
        own + if self.fixed_weights {
            0
        } else {
            self.weights.len() - 1
        }
    }

    fn with_params(&self, params: &[f64]) -> Result<Self, JitterError> {
        let expected = self.num_params();
        if params.len() != expected {
            return Err(JitterError::WrongParamCount {
                model: self.name(),
                expected,
                got: params.len(),
            });
        }
        let mut at = 0;
        let mut components = Vec::with_capacity(self.components.len());
        for c in &self.components {
            let n = c.num_params();
            components.push(c.with_params(&params[at..at + n])?);
            at += n;
        }
        let weights = if self.fixed_weights {
            self.weights.clone()
        } else {
            let rest = &params[at..];
            for &w in rest {
                check_weight(w)?;
            }
            let mut w = vec![check_weight(first_weight(rest))?];
            w.extend_from_slice(rest);
            w
        };
        Ok(Mixture {
            components,
            weights,
            fixed_weights: self.fixed_weights,
        })
    }

    fn cf(&self, f: f64) -> Complex64 {
        self.components
            .iter()
            .zip(&self.weights)
            .map(|(c, w)| c.cf(f) * w)
            .sum()
    }

    fn cf_gradient(&self, f: f64) -> Vec<Complex64> {
        let mut grad: Vec<Complex64> = self
            .components
            .iter()
            .zip(&self.weights)
            .flat_map(|(c, &w)| c.cf_gradient(f).into_iter().map(move |d| d * w))
            .collect();
        if !self.fixed_weights {
            // ∂γ/∂w_k = γ_k − γ_0, as w_0 = 1 − Σ w_k.
            let g0 = self.components[0].cf(f);
            grad.extend(self.components[1..].iter().map(|c| c.cf(f) - g0));
        }
        grad
    }

    fn mgf(&self, z: Complex64) -> Option<Complex64> {
        let mut total = Complex64::new(0.0, 0.0);
        for (c, w) in self.components.iter().zip(&self.weights) {
            let m = c.mgf(z)?;
            // Real terms stay real, so that an overflow is +∞ and not ∞·0 = NaN.
            total = if m.im == 0.0 && total.im == 0.0 {
                Complex64::new(total.re + w * m.re, 0.0)
            } else {
                total + m * w
            };
        }
        Some(total)
    }

    fn pdf(&self, tau: f64) -> f64 {
        self.components
            .iter()
            .zip(&self.weights)
            .map(|(c, w)| w * c.pdf(tau))
            .sum()
    }

    fn atoms(&self) -> Vec<Atom> {
        self.components
            .iter()
            .zip(&self.weights)
            .flat_map(|(c, &w)| {
                c.atoms().into_iter().map(move |a| Atom {
                    position: a.position,
                    mass: a.mass * w,
                })
            })
            .collect()
    }

    fn pieces(&self) -> Vec<(f64, f64)> {
        let lists: Vec<Vec<(f64, f64)>> = self.components.iter().map(|c| c.pieces()).collect();
        merge_pieces(&lists)
    }

    fn mean(&self) -> f64 {
        self.components
            .iter()
            .zip(&self.weights)
            .map(|(c, w)| w * c.mean())
            .sum()
    }

    fn variance(&self) -> f64 {
        // Law of total variance, about the mixture's mean (no cancellation of E τ² − μ²).
        let mu = self.mean();
        self.components
            .iter()
            .zip(&self.weights)
            .map(|(c, w)| w * (c.variance() + (c.mean() - mu).powi(2)))
            .sum()
    }

    fn sample(&self, rng: &mut dyn RngCore) -> f64 {
        let u: f64 = rng.random();
        let mut acc = 0.0;
        for (c, w) in self.components.iter().zip(&self.weights) {
            acc += w;
            if u < acc {
                return c.sample(rng);
            }
        }
        // u within rounding of 1: the last component.
        self.components[self.components.len() - 1].sample(rng)
    }

    fn reach(&self) -> (f64, f64) {
        self.components
            .iter()
            .map(|c| c.reach())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), (a, b)| {
                (lo.min(a), hi.max(b))
            })
    }

    fn rule(&self, breaks: &[f64], rate: f64) -> QuadratureRule {
        self.rule_from(f64::NEG_INFINITY, breaks, rate)
    }

    fn rule_from(&self, from: f64, breaks: &[f64], rate: f64) -> QuadratureRule {
        let mut rule = QuadratureRule::default();
        for (c, &w) in self.components.iter().zip(&self.weights) {
            let r = c.rule_from(from, breaks, rate);
            rule.nodes.extend(r.nodes);
            rule.weights.extend(r.weights.into_iter().map(|x| x * w));
        }
        rule
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::check_contract;
    use crate::{Gaussian, Shifted};

    #[test]
    fn mixtures_pass_the_contract() {
        let g = |s| Gaussian::new(s).unwrap();
        let m = Mixture::new(vec![g(0.01), g(0.05)], vec![0.7, 0.3]).unwrap();
        check_contract(&m, 1).unwrap();
        check_contract(&m.clone().with_fixed_weights(), 2).unwrap();
        let shifted = |c: f64, s| Shifted::new(g(s), c).unwrap();
        let m = Mixture::new(
            vec![shifted(-0.05, 0.01), shifted(0.0, 0.02), shifted(0.1, 0.01)],
            vec![0.25, 0.5, 0.25],
        )
        .unwrap();
        check_contract(&m, 3).unwrap();
    }

    #[test]
    fn mixture_of_different_families() {
        // Components of different families, through the registry's run-time type.
        let r = crate::registry::JitterRegistry::builtin();
        let spec = serde_json::json!({"family": "mixture", "weights": [0.4, 0.6], "terms": [
            {"family": "periodic", "amplitude": 0.1}, {"family": "two-point", "d": 0.05}]});
        let m = r.build(spec.as_object().unwrap()).unwrap();
        check_contract(&m, 4).unwrap();
        assert_eq!(
            m.param_names(),
            vec!["terms.0.amplitude", "terms.1.d", "weights.1"]
        );
    }

    #[test]
    fn with_params_of_params_is_exact_for_any_weights() {
        // [0.3, 0.7] used to rebuild w_0 as 1 − 0.7 = 0.30000000000000004 ≠ 0.3.
        let g = |s| Gaussian::new(s).unwrap();
        for weights in [
            vec![0.3, 0.7],
            vec![0.1, 0.2, 0.7],
            vec![0.7, 0.2, 0.1],
            vec![1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0],
            vec![0.123, 0.456, 0.421],
        ] {
            let k = weights.len();
            let m = Mixture::new((1..=k).map(|i| g(0.01 * i as f64)).collect(), weights).unwrap();
            let again = m.with_params(&m.params()).unwrap();
            assert_eq!(again, m);
            // Independent of the parametrisation: the stored weights sum to 1 exactly, and
            // the mixture rebuilt from them is the same.
            assert_eq!(m.weights()[0] + m.weights()[1..].iter().sum::<f64>(), 1.0);
            let rebuilt = Mixture::new(m.components().to_vec(), m.weights().to_vec()).unwrap();
            assert_eq!(rebuilt, m);
        }
        let m = Mixture::new(vec![g(0.01), g(0.05)], vec![0.3, 0.7]).unwrap();
        check_contract(&m, 5).unwrap();
    }

    #[test]
    fn weights_are_validated() {
        let g = Gaussian::new(0.1).unwrap();
        assert!(Mixture::new(vec![g], vec![1.0]).is_err());
        assert!(Mixture::new(vec![g, g], vec![0.5]).is_err());
        assert!(Mixture::new(vec![g, g], vec![0.5, 0.6]).is_err());
        assert!(Mixture::new(vec![g, g], vec![0.0, 1.0]).is_err());
        let m = Mixture::new(vec![g, g], vec![0.5, 0.5]).unwrap();
        assert!(m.with_params(&[0.1, 0.1, 1.0]).is_err());
        assert!(m.with_params(&[0.1, 0.1, f64::NAN]).is_err());
        let k = m.with_params(&[0.1, 0.2, 0.25]).unwrap();
        assert_eq!(k.weights(), &[0.75, 0.25]);
        let bad = r#"{"components":[{"sigma":0.1},{"sigma":0.2}],"weights":[0.5,0.7]}"#;
        assert!(serde_json::from_str::<Mixture<Gaussian>>(bad).is_err());
    }
}
