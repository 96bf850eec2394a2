//! Quadrature rules for expectations over the jitter, `E[h(τ)] ≈ Σ w_i h(τ_i)`.
//!
//! A rule is built from the model's smooth pieces ([`JitterModel::pieces`]) and atoms
//! ([`JitterModel::atoms`]), cut at caller-given breakpoints where `h` is not smooth, and each
//! sub-interval refined until the fastest rate of `h` times its width is small. On every
//! sub-interval a 16-point Gauss–Legendre rule is used, with the density folded into the
//! weights. For `h` analytic on each sub-interval this converges to near machine precision.
//!
//! [`JitterModel::pieces`]: crate::JitterModel::pieces
//! [`JitterModel::atoms`]: crate::JitterModel::atoms

use crate::JitterModel;

pub use crate::kernels::gauss::{gauss_legendre, gl16, GL_ORDER};
use crate::kernels::gauss::{panels, subdivisions};
/// Re-exported from the kernels' home, [`jitterid_numeric::gauss`].
pub use crate::kernels::gauss::{MAX_RATE_WIDTH, MAX_SUBDIVISIONS};

/// A quadrature rule for expectations over the jitter: `E[h(τ)] ≈ Σ weights[i] · h(nodes[i])`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct QuadratureRule {
    /// Abscissae `τ_i`, in increasing order within each piece.
    pub nodes: Vec<f64>,
    /// Weights: probability mass carried by each node (density times Gauss–Legendre weight,
    /// or the mass of an atom).
    pub weights: Vec<f64>,
}

impl QuadratureRule {
    /// `Σ w_i h(τ_i)`.
    pub fn expect(&self, mut h: impl FnMut(f64) -> f64) -> f64 {
        self.nodes
            .iter()
            .zip(&self.weights)
            .map(|(&t, &w)| w * h(t))
            .sum()
    }

    /// Total mass of the rule (close to 1 for a full rule).
    pub fn mass(&self) -> f64 {
        self.weights.iter().sum()
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether the rule has no node.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Appends Gauss–Legendre nodes for `∫_lo^hi density(τ) h(τ) dτ`, split so that
    /// `rate × width ≤ 6` on each sub-interval.
    pub fn push_interval(&mut self, lo: f64, hi: f64, rate: f64, density: impl Fn(f64) -> f64) {
        if lo.is_nan() || hi.is_nan() || hi <= lo {
            return;
        }
        let (x, w) = gl16();
        for (mid, half) in panels(lo, hi, subdivisions(rate, hi - lo)) {
            for (xi, wi) in x.iter().zip(w) {
                let t = mid + half * xi;
                let d = density(t);
                if d != 0.0 {
                    self.nodes.push(t);
                    self.weights.push(half * wi * d);
                }
            }
        }
    }
}

/// Builds the rule of `model` for integrands smooth between `breaks` whose fastest rate
/// (largest `|z|` in a factor `e^{zτ}`, or `2π f` of an oscillation) is `rate`.
pub(crate) fn build_rule<J: JitterModel + ?Sized>(
    model: &J,
    breaks: &[f64],
    rate: f64,
) -> QuadratureRule {
    build_rule_from(model, f64::NEG_INFINITY, breaks, rate)
}

/// [`build_rule`] restricted to `τ ≥ from` (an atom exactly at `from` is kept).
pub(crate) fn build_rule_from<J: JitterModel + ?Sized>(
    model: &J,
    from: f64,
    breaks: &[f64],
    rate: f64,
) -> QuadratureRule {
    let mut rule = QuadratureRule::default();
    for (lo, hi) in model.pieces() {
        if hi <= from {
            continue;
        }
        let lo = lo.max(from);
        let mut cuts: Vec<f64> = breaks
            .iter()
            .copied()
            .filter(|&b| b > lo && b < hi)
            .collect();
        cuts.sort_by(f64::total_cmp);
        let mut a = lo;
        for b in cuts.into_iter().chain(std::iter::once(hi)) {
            rule.push_interval(a, b, rate, |t| model.pdf(t));
            a = b;
        }
    }
    for atom in model.atoms().into_iter().filter(|a| a.position >= from) {
        rule.nodes.push(atom.position);
        rule.weights.push(atom.mass);
    }
    rule
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refined_interval_integrates_fast_exponential() {
        // ∫_0^1 e^{-500 t} dt = (1 - e^{-500}) / 500.
        let mut r = QuadratureRule::default();
        r.push_interval(0.0, 1.0, 500.0, |_| 1.0);
        let s = r.expect(|t| (-500.0 * t).exp());
        assert!((s - 1.0 / 500.0).abs() < 1e-16, "{s}");
    }
}
