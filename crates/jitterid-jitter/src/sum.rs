//! The sum of two independent jitters.

use crate::kernels::pieces::{merge_pieces, shift_pieces};
use crate::rule::{build_rule_from, QuadratureRule};
use crate::{Atom, JitterError, JitterModel};
use num_complex::Complex64;
use rand::RngCore;
use serde::{Deserialize, Serialize};

/// Largest number of pieces of the sum of two continuous laws (see [`Sum`]).
const MAX_PIECES: usize = 256;

/// `τ = τ_A + τ_B` with `τ_A`, `τ_B` independent: for instance random plus deterministic jitter.
///
/// `γ = γ_A γ_B`, `M = M_A M_B`, means and variances add, a draw is the sum of two draws. The
/// density is the convolution: `Σ_j m_j p_A(τ − b_j)` over the atoms of `B` (and the same with
/// the roles exchanged), plus `∫ p_A(τ − u) p_B(u) du` by Gauss–Legendre on `B`'s pieces cut
/// where `p_A(τ − u)` has a knot. The dual-Dirac model of serial-link jitter budgets, Gaussian
/// random jitter plus `±d` deterministic jitter, is `Sum<Gaussian, TwoPoint>`.
///
/// Parameters are `A`'s then `B`'s, named `terms.0.<name>` and `terms.1.<name>`; when `B` is
/// itself a sum its terms are numbered on (`terms.2.…`), so a sum of `n` terms nests to the
/// right and is named as a flat list.
///
/// When one term is discrete (atoms only), expectation rules are the other term's own rules
/// moved to each atom, and the pieces are the other term's moved to each atom: exact and as
/// cheap as the continuous term. When both are continuous, the pieces are cut at every sum of
/// knots (at most 256 of them, merged evenly beyond) and each density value costs a quadrature
/// over `B`'s pieces.
///
/// ```
/// use jitterid_jitter::{Gaussian, JitterModel, Sum, TwoPoint};
/// let dual_dirac = Sum::new(Gaussian::new(0.01).unwrap(), TwoPoint::new(0.03).unwrap());
/// assert!((dual_dirac.variance() - (1e-4 + 9e-4)).abs() < 1e-18);
/// assert_eq!(dual_dirac.param_names(), vec!["terms.0.sigma", "terms.1.d"]);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Sum<A, B> {
    a: A,
    b: B,
}

impl<A: JitterModel, B: JitterModel> Sum<A, B> {
    /// The sum of independent `a` and `b` (each already validated).
    pub fn new(a: A, b: B) -> Self {
        Sum { a, b }
    }

    /// The first term.
    pub fn first(&self) -> &A {
        &self.a
    }

    /// The second term.
    pub fn second(&self) -> &B {
        &self.b
    }
}

/// `name` of term `offset + k` for a name `terms.k.rest` of a nested sum, else `terms.offset.name`.
pub(crate) fn term_names<J: JitterModel + ?Sized>(term: &J, offset: usize) -> Vec<String> {
    let nested = term.name() == "sum";
    term.param_names()
        .into_iter()
        .map(|n| {
            if nested {
                if let Some((k, rest)) = n
                    .strip_prefix("terms.")
                    .and_then(|r| r.split_once('.'))
                    .and_then(|(k, rest)| Some((k.parse::<usize>().ok()?, rest)))
                {
                    return format!("terms.{}.{rest}", k + offset);
                }
            }
            format!("terms.{offset}.{n}")
        })
        .collect()
}

/// Product of two moment-generating values, real when both are, so that an overflow is `+∞`
/// and not `∞·0 = NaN`.
pub(crate) fn product(x: Complex64, y: Complex64) -> Complex64 {
    if x.im == 0.0 && y.im == 0.0 {
        Complex64::new(x.re * y.re, 0.0)
    } else {
        x * y
    }
}

/// `d·g`, zero when `g` is: a derivative that overflows where the other factor of `γ` has
/// vanished contributes nothing (not `∞·0 = NaN`).
pub(crate) fn scaled(d: Complex64, g: Complex64) -> Complex64 {
    if g == Complex64::new(0.0, 0.0) {
        g
    } else {
        d * g
    }
}

impl<A: JitterModel, B: JitterModel> Sum<A, B> {
    /// `∫ p_A(τ − u) p_B(u) du` over the continuous parts.
    fn continuous_convolution(&self, tau: f64) -> f64 {
        let knots: Vec<f64> = self
            .a
            .pieces()
            .iter()
            .flat_map(|&(lo, hi)| [tau - hi, tau - lo])
            .collect();
        let mut total = 0.0;
        let mut rule = QuadratureRule::default();
        for (lo, hi) in self.b.pieces() {
            let mut cuts: Vec<f64> = knots
                .iter()
                .copied()
                .filter(|&k| k > lo && k < hi)
                .collect();
            cuts.sort_by(f64::total_cmp);
            let mut start = lo;
            for end in cuts.into_iter().chain(std::iter::once(hi)) {
                rule.nodes.clear();
                rule.weights.clear();
                rule.push_interval(start, end, 0.0, |u| self.b.pdf(u));
                total += rule.expect(|u| self.a.pdf(tau - u));
                start = end;
            }
        }
        total
    }

    /// Rule of the continuous term `c` moved to each atom of the discrete term `atoms`.
    fn rule_over_atoms<C: JitterModel + ?Sized>(
        c: &C,
        atoms: &[Atom],
        from: f64,
        breaks: &[f64],
        rate: f64,
    ) -> QuadratureRule {
        let mut rule = QuadratureRule::default();
        for atom in atoms {
            let moved: Vec<f64> = breaks.iter().map(|b| b - atom.position).collect();
            let r = c.rule_from(from - atom.position, &moved, rate);
            rule.nodes.extend(r.nodes.iter().map(|t| t + atom.position));
            rule.weights.extend(r.weights.iter().map(|w| w * atom.mass));
        }
        rule
    }
}

impl<A: JitterModel + Clone, B: JitterModel + Clone> JitterModel for Sum<A, B> {
    fn name(&self) -> &'static str {
        "sum"
    }

    fn param_names(&self) -> Vec<String> {
        let mut names = term_names(&self.a, 0);
        names.extend(term_names(&self.b, 1));
        names
    }

    fn params(&self) -> Vec<f64> {
        let mut p = self.a.params();
        p.extend(self.b.params());
        p
    }

    fn even_params(&self) -> Vec<bool> {
        // γ = γ_a·γ_b: a term's parameter enters through that term only.
        let mut e = self.a.even_params();
        e.extend(self.b.even_params());
        e
    }

    fn with_params(&self, params: &[f64]) -> Result<Self, JitterError> {
        let na = self.a.num_params();
        let expected = na + self.b.num_params();
        if params.len() != expected {
            return Err(JitterError::WrongParamCount {
                model: self.name(),
                expected,
                got: params.len(),
            });
        }
        Ok(Sum {
            a: self.a.with_params(&params[..na])?,
            b: self.b.with_params(&params[na..])?,
        })
    }

    fn num_params(&self) -> usize {
        self.a.num_params() + self.b.num_params()
    }

    fn cf(&self, f: f64) -> Complex64 {
        self.a.cf(f) * self.b.cf(f)
    }

    fn cf_gradient(&self, f: f64) -> Vec<Complex64> {
        let (ga, gb) = (self.a.cf(f), self.b.cf(f));
        let mut grad: Vec<Complex64> = self
            .a
            .cf_gradient(f)
            .into_iter()
            .map(|d| scaled(d, gb))
            .collect();
        grad.extend(self.b.cf_gradient(f).into_iter().map(|d| scaled(d, ga)));
        grad
    }

    fn mgf(&self, z: Complex64) -> Option<Complex64> {
        Some(product(self.a.mgf(z)?, self.b.mgf(z)?))
    }

    fn pdf(&self, tau: f64) -> f64 {
        let mut p: f64 = self
            .b
            .atoms()
            .iter()
            .map(|at| at.mass * self.a.pdf(tau - at.position))
            .sum();
        p += self
            .a
            .atoms()
            .iter()
            .map(|at| at.mass * self.b.pdf(tau - at.position))
            .sum::<f64>();
        if !self.a.pieces().is_empty() && !self.b.pieces().is_empty() {
            p += self.continuous_convolution(tau);
        }
        p
    }

    fn atoms(&self) -> Vec<Atom> {
        let bs = self.b.atoms();
        self.a
            .atoms()
            .iter()
            .flat_map(|x| {
                bs.iter().map(move |y| Atom {
                    position: x.position + y.position,
                    mass: x.mass * y.mass,
                })
            })
            .collect()
    }

    fn pieces(&self) -> Vec<(f64, f64)> {
        let (pa, pb) = (self.a.pieces(), self.b.pieces());
        let mut lists: Vec<Vec<(f64, f64)>> = self
            .b
            .atoms()
            .iter()
            .map(|at| shift_pieces(&pa, at.position))
            .collect();
        lists.extend(
            self.a
                .atoms()
                .iter()
                .map(|at| shift_pieces(&pb, at.position)),
        );
        if !pa.is_empty() && !pb.is_empty() {
            // The convolution is analytic between sums of knots.
            let mut knots: Vec<f64> = pa
                .iter()
                .flat_map(|&(lo, hi)| [lo, hi])
                .flat_map(|x| pb.iter().flat_map(move |&(lo, hi)| [x + lo, x + hi]))
                .collect();
            knots.sort_by(f64::total_cmp);
            knots.dedup();
            if knots.len() > MAX_PIECES + 1 {
                let step = knots.len().div_ceil(MAX_PIECES);
                let last = knots[knots.len() - 1];
                knots = knots.into_iter().step_by(step).collect();
                if knots.last() != Some(&last) {
                    knots.push(last);
                }
            }
            lists.push(knots.windows(2).map(|w| (w[0], w[1])).collect());
        }
        merge_pieces(&lists)
    }

    fn mean(&self) -> f64 {
        self.a.mean() + self.b.mean()
    }

    fn variance(&self) -> f64 {
        self.a.variance() + self.b.variance()
    }

    /// The sum of the terms' reaches, which is where the sum's draws lie: a term whose support
    /// reaches beyond its pieces and atoms (the periodic family's ends) keeps it.
    fn reach(&self) -> (f64, f64) {
        let ((a_lo, a_hi), (b_lo, b_hi)) = (self.a.reach(), self.b.reach());
        (a_lo + b_lo, a_hi + b_hi)
    }

    fn sample(&self, rng: &mut dyn RngCore) -> f64 {
        self.a.sample(rng) + self.b.sample(rng)
    }

    fn rule(&self, breaks: &[f64], rate: f64) -> QuadratureRule {
        self.rule_from(f64::NEG_INFINITY, breaks, rate)
    }

    fn rule_from(&self, from: f64, breaks: &[f64], rate: f64) -> QuadratureRule {
        if self.b.pieces().is_empty() {
            Self::rule_over_atoms(&self.a, &self.b.atoms(), from, breaks, rate)
        } else if self.a.pieces().is_empty() {
            Self::rule_over_atoms(&self.b, &self.a.atoms(), from, breaks, rate)
        } else {
            build_rule_from(self, from, breaks, rate)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::check_contract;
    use crate::{Gaussian, Periodic, TwoPoint, UniformSum};

    #[test]
    fn sums_pass_the_contract() {
        let g = Gaussian::new(0.02).unwrap();
        check_contract(&Sum::new(g, TwoPoint::new(0.05).unwrap()), 1).unwrap();
        check_contract(
            &Sum::new(TwoPoint::new(0.05).unwrap(), TwoPoint::new(0.01).unwrap()),
            2,
        )
        .unwrap();
        check_contract(&Sum::new(g, Periodic::new(0.04).unwrap()), 3).unwrap();
        check_contract(
            &Sum::new(
                UniformSum::new(0, 0.1).unwrap(),
                UniformSum::new(1, 0.05).unwrap(),
            ),
            4,
        )
        .unwrap();
    }

    #[test]
    fn two_uniforms_make_the_uniform_sum() {
        // Independent route: U[-a/2, a/2] + U[-a/2, a/2] is the uniform sum n = 1 on [-a, a].
        let u = UniformSum::new(0, 0.25).unwrap();
        let s = Sum::new(u, u);
        let tri = UniformSum::new(1, 0.5).unwrap();
        for t in [-0.6, -0.49, -0.2, 0.0, 0.13, 0.3, 0.499] {
            assert!(
                (s.pdf(t) - tri.pdf(t)).abs() < 1e-13,
                "{t}: {} vs {}",
                s.pdf(t),
                tri.pdf(t)
            );
        }
    }

    #[test]
    fn dual_dirac_density_is_two_gaussians() {
        let s = Sum::new(Gaussian::new(0.1).unwrap(), TwoPoint::new(0.3).unwrap());
        let g = Gaussian::new(0.1).unwrap();
        for t in [-0.5, -0.3, 0.0, 0.2] {
            let exact = 0.5 * (g.pdf(t - 0.3) + g.pdf(t + 0.3));
            assert!((s.pdf(t) - exact).abs() < 1e-15 * exact.max(1.0));
        }
        let k = s.with_params(&[0.2, 0.1]).unwrap();
        assert_eq!(k.params(), vec![0.2, 0.1]);
        assert!(matches!(
            s.with_params(&[0.1]),
            Err(JitterError::WrongParamCount { .. })
        ));
    }

    #[test]
    fn nested_sums_are_named_as_a_flat_list() {
        let g = Gaussian::new(0.1).unwrap();
        let s = Sum::new(
            g,
            Sum::new(TwoPoint::new(0.2).unwrap(), Periodic::new(0.1).unwrap()),
        );
        assert_eq!(
            s.param_names(),
            vec!["terms.0.sigma", "terms.1.d", "terms.2.amplitude"]
        );
    }
}
