//! Portmanteau statistics of the residual tests, with χ² p-values: Ljung–Box on the
//! autocorrelation, and Ljung's `S` on the cross-correlation with a non-white input, with the
//! directions the fitted parameters explain removed first.
//!
//! A fitted model's residuals are `ε̂ = ε − W Δθ` to first order, `W` the gradients of the
//! (standardised or whitened) expected samples with respect to the free parameters that move
//! them. How large `W Δθ` is depends on the estimator, not on the structure: BCLS weighs all
//! frequencies alike and leaves a `Δθ` whose trace in settled stretches (where `λ_k ≈ σ_v²`) is
//! a slowly varying fraction of a noise standard deviation, which a test of the residuals reads
//! as colour. Removing the span of `W` (and of the constant, the residuals' mean) leaves
//! `(I − P)ε` whatever the estimator, the residuals of the efficient weighted fit: the tests
//! then judge the structure, and their null distributions are known ([`residual_projection`]).

use faer::Mat;
use jitterid_estimate::EstimateError;
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// The default level of the tests' verdicts: a true model fails each test in 1 % of records.
pub const DEFAULT_LEVEL: f64 = 0.01;

/// Singular values below this fraction of the largest count as zero (a gradient that repeats
/// another, a lag the removed directions already explain).
const RANK_TOL: f64 = 1e-9;

/// The upper tail `P(χ²(dof) > statistic)`; 1 for no degree of freedom (nothing was tested).
pub fn chi2_p_value(statistic: f64, dof: usize) -> f64 {
    if dof == 0 {
        return 1.0;
    }
    // `new` refuses only a non-positive or NaN dof; `dof ≥ 1` here.
    ChiSquared::new(dof as f64).map_or(f64::NAN, |d| d.sf(statistic.max(0.0)))
}

/// Checks a test level: in `(0, 1)`.
pub fn check_level(level: f64) -> Result<f64, EstimateError> {
    if level > 0.0 && level < 1.0 {
        Ok(level)
    } else {
        Err(EstimateError::BadLevel { value: level })
    }
}

/// The Ljung–Box statistic `Q = N(N+2) Σ_{k=1}^{M} r_k²/(N−k)` of autocorrelations
/// `r_0 … r_M` of `n` residuals (`r_0` is not used).
pub fn ljung_box(r: &[f64], n: usize) -> f64 {
    let n = n as f64;
    n * (n + 2.0)
        * r.iter()
            .enumerate()
            .skip(1)
            .map(|(k, v)| v * v / (n - k as f64))
            .sum::<f64>()
}

/// An orthonormal basis (as columns of length `n`) of the span of the constant and of
/// `columns`, the directions removed from residuals by [`project_out`]. Columns that are not
/// finite are left out (a gradient that could not be taken removes nothing).
pub fn residual_projection(columns: &[Vec<f64>], n: usize) -> Vec<Vec<f64>> {
    let used: Vec<&Vec<f64>> = columns
        .iter()
        .filter(|c| c.len() == n && c.iter().all(|v| v.is_finite()))
        .collect();
    let a = Mat::from_fn(
        n,
        used.len() + 1,
        |i, j| if j == 0 { 1.0 } else { used[j - 1][i] },
    );
    let Ok(svd) = a.thin_svd() else {
        // Cannot happen for finite input; the constant alone still centres the residuals.
        let c = 1.0 / (n as f64).sqrt();
        return vec![vec![c; n]];
    };
    let s = svd.S().column_vector();
    let u = svd.U();
    let smax = (0..s.nrows()).map(|i| s[i]).fold(0.0, f64::max);
    (0..s.nrows())
        .filter(|&i| s[i] > RANK_TOL * smax)
        .map(|i| (0..n).map(|r| u[(r, i)]).collect())
        .collect()
}

/// `e − Q Qᵀ e` for an orthonormal basis `Q` ([`residual_projection`]).
pub fn project_out(e: &[f64], basis: &[Vec<f64>]) -> Vec<f64> {
    let mut out = e.to_vec();
    for q in basis {
        let c: f64 = q.iter().zip(e).map(|(a, b)| a * b).sum();
        for (o, qi) in out.iter_mut().zip(q) {
            *o -= c * qi;
        }
    }
    out
}

/// Ljung's cross-correlation statistic and its degrees of freedom for residuals `e` already
/// projected off `basis`, and input samples `u`, over lags `0..=max_lag` (residual at `k + τ`,
/// input at `k`).
///
/// With `c = Uᵀe` the lagged sums of the centred input `U` (column `τ` is `u` delayed by `τ`),
/// and white residuals `e = (I − QQᵀ)ε` of variance `σ²`, `c` is normal with covariance
/// `σ² Uᵀ(I − QQᵀ)U`; `S = cᵀ [σ̂² Uᵀ(I − QQᵀ)U]⁺ c` is χ² with the rank of that matrix as its
/// degrees of freedom. Without removed directions this is `N rᵀ R_u⁻¹ r` (Ljung, *System
/// Identification*, 2nd ed., §16.6), with the input's lagged Gram matrix in place of the
/// Toeplitz estimate `N R_u`: a non-white input's correlated lags are not counted twice.
pub fn input_statistic(e: &[f64], u: &[f64], max_lag: usize, basis: &[Vec<f64>]) -> (f64, usize) {
    let n = e.len();
    let m = max_lag + 1;
    let mean = u.iter().sum::<f64>() / n as f64;
    let lagged = |j: usize, tau: usize| if j >= tau { u[j - tau] - mean } else { 0.0 };
    // (I − QQᵀ)U, column by column.
    let mut pu = Mat::from_fn(n, m, lagged);
    for q in basis {
        for tau in 0..m {
            let c: f64 = (0..n).map(|j| q[j] * pu[(j, tau)]).sum();
            for j in 0..n {
                pu[(j, tau)] -= c * q[j];
            }
        }
    }
    // Both `c` and the covariance are taken from the projected columns: `Uᵀe = ((I−P)U)ᵀe` for
    // `e` in the projection's range, and the singular vectors of `(I − P)U` give the
    // pseudo-inverse of `Uᵀ(I − P)U` without forming it.
    let dof_sigma = n.saturating_sub(basis.len()).max(1);
    let sigma2 = e.iter().map(|v| v * v).sum::<f64>() / dof_sigma as f64;
    let Ok(svd) = pu.thin_svd() else {
        return (f64::NAN, m);
    };
    let s = svd.S().column_vector();
    let left = svd.U();
    let smax = (0..s.nrows()).map(|i| s[i]).fold(0.0, f64::max);
    let mut stat = 0.0;
    let mut rank = 0;
    for i in (0..s.nrows()).filter(|&i| s[i] > RANK_TOL * smax) {
        // Component of `c` along the i-th right singular vector is s_i (u_iᵀ e); divided by
        // the covariance's eigenvalue σ² s_i², it contributes (u_iᵀ e)²/σ².
        let proj: f64 = (0..n).map(|j| left[(j, i)] * e[j]).sum();
        stat += proj * proj / sigma2;
        rank += 1;
    }
    (stat, rank)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{rngs::StdRng, Rng, SeedableRng};

    /// Table values of the χ² upper tail (Abramowitz & Stegun, Table 26.8): the 99 % points
    /// of χ²(1), χ²(10) and χ²(25) are 6.635, 23.209 and 44.314; the median of χ²(2) is
    /// 2 ln 2 (its tail is `exp(−x/2)`).
    #[test]
    fn chi2_tail_matches_tables() {
        assert!((chi2_p_value(6.6349, 1) - 0.01).abs() < 1e-5);
        assert!((chi2_p_value(23.2093, 10) - 0.01).abs() < 1e-5);
        assert!((chi2_p_value(44.3141, 25) - 0.01).abs() < 1e-5);
        for x in [0.1, 1.0, 7.5] {
            assert!((chi2_p_value(x, 2) - (-x / 2.0).exp()).abs() < 1e-12);
        }
        assert_eq!(chi2_p_value(3.0, 0), 1.0);
    }

    #[test]
    fn levels_outside_the_open_interval_are_refused() {
        for bad in [0.0, 1.0, -0.1, 1.5, f64::NAN] {
            assert!(matches!(
                check_level(bad),
                Err(EstimateError::BadLevel { .. })
            ));
        }
        assert_eq!(check_level(0.05).unwrap(), 0.05);
    }

    fn normals(n: usize, rng: &mut StdRng) -> Vec<f64> {
        // Box–Muller from the uniform generator.
        (0..n)
            .map(|_| {
                let (a, b): (f64, f64) = (rng.random(), rng.random());
                (-2.0 * (1.0 - a).ln()).sqrt() * (2.0 * std::f64::consts::PI * b).cos()
            })
            .collect()
    }

    /// The statistic against a naive sum over lags, and the projection leaves residuals
    /// orthogonal to the removed directions and to the constant.
    #[test]
    fn ljung_box_and_projection_match_naive_computations() {
        let r = [1.0, 0.2, -0.1, 0.05];
        let n = 50usize;
        let naive = 50.0 * 52.0 * (0.04 / 49.0 + 0.01 / 48.0 + 0.0025 / 47.0);
        assert!((ljung_box(&r, n) - naive).abs() < 1e-12);
        let mut rng = StdRng::seed_from_u64(7);
        let e = normals(n, &mut rng);
        let w: Vec<f64> = (0..n).map(|k| (k as f64 * 0.3).sin()).collect();
        // A repeated column adds nothing to the span.
        let q = residual_projection(&[w.clone(), w.iter().map(|v| 2.0 * v).collect()], n);
        assert_eq!(q.len(), 2);
        let p = project_out(&e, &q);
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
        assert!(dot(&p, &w).abs() < 1e-10);
        assert!(p.iter().sum::<f64>().abs() < 1e-10);
    }

    /// Only the mean removed: `S` equals `cᵀ G⁻¹ c / σ̂²` with the Gram matrix `G` of the
    /// centred lagged input and `c` the lagged sums, both summed by naive loops and solved by
    /// an LU decomposition (another route than the singular values of the statistic).
    #[test]
    fn input_statistic_matches_the_gram_matrix_route() {
        use faer::linalg::solvers::Solve;
        let (n, lags) = (300, 5);
        let mut rng = StdRng::seed_from_u64(11);
        let e = normals(n, &mut rng);
        let w = normals(n, &mut rng);
        let mut u = vec![0.0; n];
        for k in 1..n {
            u[k] = 0.8 * u[k - 1] + w[k];
        }
        let q = residual_projection(&[], n);
        let e = project_out(&e, &q);
        let (s, dof) = input_statistic(&e, &u, lags, &q);
        assert_eq!(dof, lags + 1);
        let mu = u.iter().sum::<f64>() / n as f64;
        let x = |tau: usize, j: usize| if j >= tau { u[j - tau] - mu } else { 0.0 };
        let col_mean = |tau: usize| (0..n).map(|j| x(tau, j)).sum::<f64>() / n as f64;
        let g = Mat::from_fn(lags + 1, lags + 1, |a, b| {
            let (ma, mb) = (col_mean(a), col_mean(b));
            (0..n).map(|j| (x(a, j) - ma) * (x(b, j) - mb)).sum::<f64>()
        });
        let c = Mat::from_fn(lags + 1, 1, |a, _| {
            (0..n).map(|j| x(a, j) * e[j]).sum::<f64>()
        });
        let sol = g.partial_piv_lu().solve(&c);
        let sigma2 = e.iter().map(|v| v * v).sum::<f64>() / (n - 1) as f64;
        let naive = (0..=lags).map(|a| c[(a, 0)] * sol[(a, 0)]).sum::<f64>() / sigma2;
        assert!((s - naive).abs() < 1e-9 * naive, "{s} {naive}");
    }

    /// The size of both statistics on many cheap null draws: white residuals, an AR(1) input
    /// (strongly non-white, where the per-lag sum `N Σ r²` would be far too large) and three
    /// fitted directions removed; rejections at the 5 % level must lie within 3 Monte Carlo
    /// standard errors of 5 % (`√(0.05·0.95/2000) = 0.49 %`).
    #[test]
    fn statistics_have_the_nominal_size_on_null_draws() {
        let (n, lags, draws, level) = (200, 10, 2000, 0.05);
        let mut rng = StdRng::seed_from_u64(2024);
        let (mut rej_lb, mut rej_s) = (0, 0);
        for _ in 0..draws {
            let w = normals(n, &mut rng);
            let mut u = vec![0.0; n];
            for k in 1..n {
                u[k] = 0.9 * u[k - 1] + w[k];
            }
            // Directions a fit would remove: filtered inputs, as an OE model's gradients are.
            let g1: Vec<f64> = (0..n).map(|k| if k > 0 { u[k - 1] } else { 0.0 }).collect();
            let mut g2 = vec![0.0; n];
            for k in 1..n {
                g2[k] = 0.5 * g2[k - 1] + u[k - 1];
            }
            let q = residual_projection(&[g1, g2], n);
            let e = project_out(&normals(n, &mut rng), &q);
            let (s, dof) = input_statistic(&e, &u, lags, &q);
            if chi2_p_value(s, dof) < level {
                rej_s += 1;
            }
            let norm: f64 = e.iter().map(|v| v * v).sum();
            let r: Vec<f64> = (0..=lags)
                .map(|t| (t..n).map(|k| e[k] * e[k - t]).sum::<f64>() / norm)
                .collect();
            if chi2_p_value(ljung_box(&r, n), lags) < level {
                rej_lb += 1;
            }
        }
        let se = (level * (1.0 - level) / draws as f64).sqrt();
        for (what, rej) in [("Ljung-Box", rej_lb), ("S", rej_s)] {
            let rate = rej as f64 / draws as f64;
            assert!((rate - level).abs() < 3.0 * se, "{what}: {rate}");
        }
    }
}
