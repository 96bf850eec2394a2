//! The second-order term of an even jitter width in the Gauss–Newton matrix.
//!
//! A symmetric law's width `σ` enters the first moment through `σ²` only
//! ([`JitterModel::even_params`]): near a small width the residuals are `r ≈ r₀ + r₂σ²`. Their
//! Jacobian column `2r₂σ` vanishes with `σ`, while the criterion's curvature in `σ` does not:
//! `∂²V/∂σ² = (JᵀJ)_σσ + Σ rᵢ ∂²rᵢ/∂σ²`, and the second term, `2r₂·r = g_σ/σ`, is the larger
//! one when `σ` is small. Gauss–Newton drops it, so its model of the criterion in `σ` is far
//! too flat there: when the data want `σ² ≤ 0` (no detectable jitter, given the other
//! parameters) each step overshoots, the width jumps back and forth between `σ/4` and `2σ`
//! (Newton's iteration for the square root of a negative number, which is chaotic), and the
//! other parameters creep along the valley — on the JOE boundary experiment five records of
//! 128 spent 500 Levenberg–Marquardt iterations that way.
//!
//! The term is known exactly from what the normal equations already hold (`g_σ/σ`, for
//! residuals linear in `σ²`), so it is added to the matrix's diagonal where it is positive
//! (where it is not, the criterion is convex in `σ²` beyond the linear model and Gauss–Newton
//! is already right). The search's matrix is then Newton's in `σ` and Gauss–Newton's in `σ²`:
//! a width the data put at 0 reaches it at once, and an interior one converges as fast as the
//! other parameters. Only the search's matrix changes: the gradient, the stopping tests and the
//! covariance (which never reads these normal equations) are the same.

use crate::solver::NormalEquations;

/// Adds `g_i/θ_i` to `(JᵀJ)_ii` for each even width `i` at a positive value where that is
/// positive (see the [module docs](self)).
pub(crate) fn add_even_curvature(ne: &mut NormalEquations, theta: &[f64], even: &[usize]) {
    for &i in even {
        let (Some(&t), Some(&g)) = (theta.get(i), ne.gradient.get(i)) else {
            continue;
        };
        if !(t > 0.0) || i >= ne.gram.nrows() {
            continue;
        }
        let curvature = g / t;
        if curvature > 0.0 && curvature.is_finite() {
            ne.gram[(i, i)] += curvature;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;

    /// Residuals `r(σ) = a + bσ²` with `a·b > 0` (the best `σ²` is negative): Gauss–Newton's
    /// step in `σ` overshoots past 0, the corrected one lands within the quadratic-convergence
    /// region of the bound, and both are checked against a finite-difference Hessian.
    #[test]
    fn corrected_matrix_is_the_exact_curvature_of_a_quadratic_in_the_square() {
        let (a, b) = ([0.3, -0.2, 0.5], [0.7, -0.1, 0.4]);
        let cost = |s: f64| {
            0.5 * a
                .iter()
                .zip(&b)
                .map(|(a, b)| (a + b * s * s).powi(2))
                .sum::<f64>()
        };
        let sigma = 0.05;
        let r: Vec<f64> = a
            .iter()
            .zip(&b)
            .map(|(a, b)| a + b * sigma * sigma)
            .collect();
        let j: Vec<f64> = b.iter().map(|b| 2.0 * b * sigma).collect();
        let jtj: f64 = j.iter().map(|x| x * x).sum();
        let g: f64 = j.iter().zip(&r).map(|(j, r)| j * r).sum();
        let mut ne = NormalEquations {
            gram: Mat::from_fn(1, 1, |_, _| jtj),
            gradient: vec![g],
        };
        add_even_curvature(&mut ne, &[sigma], &[0]);
        let h = 1e-4;
        let hessian = (cost(sigma + h) - 2.0 * cost(sigma) + cost(sigma - h)) / (h * h);
        assert!(
            (ne.gram[(0, 0)] - hessian).abs() <= 1e-6 * hessian,
            "{} vs {hessian}",
            ne.gram[(0, 0)]
        );
        // Gauss–Newton alone jumps far past 0; Newton moves towards it without crossing.
        let gn = sigma - g / jtj;
        let newton = sigma - g / ne.gram[(0, 0)];
        assert!(gn < -sigma, "Gauss–Newton step {gn}");
        assert!(newton > 0.0 && newton < 0.1 * sigma, "Newton step {newton}");
    }

    #[test]
    fn leaves_other_parameters_and_negative_curvature_alone() {
        let gram = Mat::from_fn(2, 2, |r, c| if r == c { 2.0 } else { 0.5 });
        let mut ne = NormalEquations {
            gram: gram.clone(),
            gradient: vec![1.0, -1.0],
        };
        // Parameter 0 is not even; parameter 1 is, but g/θ < 0; an index beyond the problem.
        add_even_curvature(&mut ne, &[0.1, 0.1], &[1, 7]);
        assert_eq!(ne.gram, gram);
    }
}
