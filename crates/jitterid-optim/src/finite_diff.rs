//! The one home of the crate's finite differences: central differences of vector- and
//! scalar-valued functions of a parameter vector (one-sided next to the edge of the model's
//! domain) and the Hessian of an objective from differences of its gradient.
//!
//! The steps are relative, `h = rel · max(|θ_j|, 10⁻³)`, so that parameters near zero still get
//! a step above rounding. The first-moment criteria and the likelihood criteria use different
//! relative steps ([`MOMENT_FD_STEP`], [`LIKELIHOOD_FD_STEP`]); each was tuned against its own
//! analytic gradients, and the reproduced figures depend on them.

use crate::Objective;
use faer::Mat;

/// Relative step of the central differences of the first moment `m_k` in the jitter's and the
/// noise shape's parameters.
pub const MOMENT_FD_STEP: f64 = 1e-6;

/// Relative step of the central differences of the likelihood criteria and the second
/// moments (`≈ ε^{1/3}`).
pub const LIKELIHOOD_FD_STEP: f64 = 6e-6;

/// The step `rel · max(|v|, 10⁻³)` of a central difference in a parameter of value `v`.
pub fn fd_step(rel: f64, v: f64) -> f64 {
    rel * v.abs().max(1e-3)
}

/// Central difference of `f` in coordinate `j` of `theta`, one-sided where a side is outside
/// the model's domain (`f` returns `None`), `None` if neither side is. `diff(a, b, h)` forms
/// the quotient `(a − b)/h` of two values.
pub fn central_difference<T>(
    theta: &[f64],
    j: usize,
    rel: f64,
    f: impl Fn(&[f64]) -> Option<T>,
    diff: impl Fn(&T, &T, f64) -> Vec<f64>,
) -> Option<Vec<f64>> {
    let h = fd_step(rel, theta[j]);
    let mut plus = theta.to_vec();
    plus[j] += h;
    let mut minus = theta.to_vec();
    minus[j] -= h;
    match (f(&plus), f(&minus)) {
        (Some(a), Some(b)) => Some(diff(&a, &b, 2.0 * h)),
        (Some(a), None) => Some(diff(&a, &f(theta)?, h)),
        (None, Some(b)) => Some(diff(&f(theta)?, &b, h)),
        (None, None) => None,
    }
}

/// [`central_difference`] of a vector-valued `f`, element by element.
pub fn central_difference_vec(
    theta: &[f64],
    j: usize,
    rel: f64,
    f: impl Fn(&[f64]) -> Option<Vec<f64>>,
) -> Option<Vec<f64>> {
    central_difference(theta, j, rel, f, |a, b, h| {
        a.iter().zip(b).map(|(a, b)| (a - b) / h).collect()
    })
}

/// Central difference of a scalar `f` in coordinate `j`, where `+∞` (or NaN) marks a point
/// outside the domain: one-sided next to such a point (from `f0 = f(θ)`), NaN if both sides
/// are outside.
pub fn partial(f: impl Fn(&[f64]) -> f64, theta: &[f64], j: usize, f0: f64, rel: f64) -> f64 {
    let h = fd_step(rel, theta[j]);
    let mut p = theta.to_vec();
    p[j] = theta[j] + h;
    let fp = f(&p);
    p[j] = theta[j] - h;
    let fm = f(&p);
    match (fp.is_finite(), fm.is_finite()) {
        (true, true) => (fp - fm) / (2.0 * h),
        (true, false) if f0.is_finite() => (fp - f0) / h,
        (false, true) if f0.is_finite() => (f0 - fm) / h,
        _ => f64::NAN,
    }
}

/// The Hessian of `objective` at `theta` by central differences of its gradient (step
/// `10⁻⁴ · max(|θ_i|, 10⁻⁴)`, one-sided next to an infeasible point), symmetrised; `None` if a
/// gradient is not finite on both sides.
pub fn hessian<O: Objective + ?Sized>(objective: &O, theta: &[f64]) -> Option<Mat<f64>> {
    let p = theta.len();
    let mut h = Mat::<f64>::zeros(p, p);
    for i in 0..p {
        let step = 1e-4 * theta[i].abs().max(1e-4);
        let mut up = theta.to_vec();
        up[i] += step;
        let mut dn = theta.to_vec();
        dn[i] -= step;
        let (fu, gu) = objective.cost_gradient(&up);
        let (fd, gd) = objective.cost_gradient(&dn);
        let lo_ok = fd.is_finite() && gd.iter().all(|v| v.is_finite());
        let hi_ok = fu.is_finite() && gu.iter().all(|v| v.is_finite());
        let col: Vec<f64> = match (hi_ok, lo_ok) {
            (true, true) => gu
                .iter()
                .zip(&gd)
                .map(|(a, b)| (a - b) / (2.0 * step))
                .collect(),
            (true, false) | (false, true) => {
                let (f0, g0) = objective.cost_gradient(theta);
                if !f0.is_finite() || g0.iter().any(|v| !v.is_finite()) {
                    return None;
                }
                if hi_ok {
                    gu.iter().zip(&g0).map(|(a, b)| (a - b) / step).collect()
                } else {
                    g0.iter().zip(&gd).map(|(a, b)| (a - b) / step).collect()
                }
            }
            (false, false) => return None,
        };
        for (j, c) in col.iter().enumerate() {
            h[(j, i)] = *c;
        }
    }
    Some(Mat::from_fn(p, p, |i, j| 0.5 * (h[(i, j)] + h[(j, i)])))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn central_difference_matches_the_derivative_and_falls_back_one_sided() {
        // f(θ) = [θ₀², sin θ₁]; the domain stops at θ₀ = 1 (f undefined above it).
        let f = |p: &[f64]| (p[0] <= 1.0).then(|| vec![p[0] * p[0], p[1].sin()]);
        let d = central_difference_vec(&[0.5, 0.3], 1, MOMENT_FD_STEP, f).unwrap();
        // Central difference: error O(h²) ≈ 1e-12 relative; rounding ε/h ≈ 2e-10 absolute.
        assert!((d[1] - 0.3f64.cos()).abs() < 1e-8);
        let d = central_difference_vec(&[1.0, 0.3], 0, MOMENT_FD_STEP, f).unwrap();
        // One-sided at the edge: truncation error h·f''/2 = 1e-6.
        assert!((d[0] - 2.0).abs() < 2e-6, "{}", d[0]);
        assert!(central_difference_vec(&[0.5], 0, 1e-6, |_| None::<Vec<f64>>).is_none());
    }

    #[test]
    fn partial_is_one_sided_next_to_an_infinite_cost() {
        let f = |p: &[f64]| {
            if p[0] < 2.0 {
                p[0].powi(3)
            } else {
                f64::INFINITY
            }
        };
        let g = partial(f, &[1.0], 0, 1.0, LIKELIHOOD_FD_STEP);
        assert!((g - 3.0).abs() < 1e-8);
        let g = partial(f, &[2.0 - 1e-9], 0, f(&[2.0 - 1e-9]), LIKELIHOOD_FD_STEP);
        // Backward difference: truncation h·f''/2 ≈ 6e-6 · 2 · 12 / 2.
        assert!((g - 12.0).abs() < 1e-3, "{g}");
        assert!(partial(|_| f64::INFINITY, &[1.0], 0, 1.0, 1e-6).is_nan());
    }
}
