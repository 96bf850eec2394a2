//! The matrix exponential of a small dense real matrix: Padé [13/13] with scaling and squaring
//! (Higham 2005), accurate to a few ulps of `‖e^A‖` whatever the eigenstructure (repeated,
//! defective or coincident eigenvalues included), which the modal form is not.

use faer::linalg::solvers::Solve;
use faer::Mat;

/// Padé [13/13] numerator coefficients `b_0 … b_13`.
const PADE13: [f64; 14] = [
    64_764_752_532_480_000.0,
    32_382_376_266_240_000.0,
    7_771_770_303_897_600.0,
    1_187_353_796_428_800.0,
    129_060_195_264_000.0,
    10_559_470_521_600.0,
    670_442_572_800.0,
    33_522_128_640.0,
    1_323_241_920.0,
    40_840_800.0,
    960_960.0,
    16_380.0,
    182.0,
    1.0,
];

/// Largest 1-norm for which [13/13] needs no scaling (Higham's `θ_13`).
const THETA13: f64 = 5.371_920_351_148_152;

/// `Σ_i c_i M_i` over matrices of one size, plus `c_id · I`.
fn combine(terms: &[(f64, &Mat<f64>)], c_id: f64, n: usize) -> Mat<f64> {
    Mat::from_fn(n, n, |i, j| {
        let diag = if i == j { c_id } else { 0.0 };
        terms.iter().map(|(c, m)| c * m[(i, j)]).sum::<f64>() + diag
    })
}

/// `e^{A t}` for a square `A`; `None` when a value is not finite (an overflowing exponential).
pub(crate) fn expm(a: &Mat<f64>, t: f64) -> Option<Mat<f64>> {
    let n = a.nrows();
    let norm = (0..n)
        .map(|j| (0..n).map(|i| (a[(i, j)] * t).abs()).sum::<f64>())
        .fold(0.0, f64::max);
    if !norm.is_finite() {
        return None;
    }
    let squarings = if norm > THETA13 {
        // At most 1100 squarings keep the scale finite for any finite norm.
        (norm / THETA13).log2().ceil().clamp(0.0, 1100.0) as i32
    } else {
        0
    };
    let scale = t / 2f64.powi(squarings);
    let a1 = Mat::from_fn(n, n, |i, j| a[(i, j)] * scale);
    let a2 = &a1 * &a1;
    let a4 = &a2 * &a2;
    let a6 = &a4 * &a2;
    let b = &PADE13;
    let u_inner = &a6 * combine(&[(b[13], &a6), (b[11], &a4), (b[9], &a2)], 0.0, n);
    let u_poly = combine(
        &[(1.0, &u_inner), (b[7], &a6), (b[5], &a4), (b[3], &a2)],
        b[1],
        n,
    );
    let u = &a1 * &u_poly;
    let v_inner = &a6 * combine(&[(b[12], &a6), (b[10], &a4), (b[8], &a2)], 0.0, n);
    let v = combine(
        &[(1.0, &v_inner), (b[6], &a6), (b[4], &a4), (b[2], &a2)],
        b[0],
        n,
    );
    let p = combine(&[(1.0, &v), (1.0, &u)], 0.0, n);
    let q = combine(&[(1.0, &v), (-1.0, &u)], 0.0, n);
    let mut r = q.partial_piv_lu().solve(&p);
    for _ in 0..squarings {
        r = &r * &r;
    }
    let finite = (0..n).all(|i| (0..n).all(|j| r[(i, j)].is_finite()));
    finite.then_some(r)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn max_abs_diff(a: &Mat<f64>, b: &[[f64; 2]; 2]) -> f64 {
        let mut d = 0.0f64;
        for i in 0..2 {
            for j in 0..2 {
                d = d.max((a[(i, j)] - b[i][j]).abs());
            }
        }
        d
    }

    #[test]
    fn jordan_block_and_rotation_in_closed_form() {
        // [[p, 1], [0, p]] t → e^{pt} [[1, t], [0, 1]]: the defective case the modal form lacks.
        for &(p, t) in &[(-1.0, 0.3), (-0.25, 40.0), (0.0, 7.0), (-30.0, 2.0)] {
            let a = Mat::from_fn(2, 2, |i, j| match (i, j) {
                (0, 1) => 1.0,
                (i, j) if i == j => p,
                _ => 0.0,
            });
            let e = expm(&a, t).unwrap();
            let x: f64 = (p * t).exp();
            let want = [[x, t * x], [0.0, x]];
            let err = max_abs_diff(&e, &want);
            eprintln!("p {p}, t {t}: error {err:e}, scale {:e}", x.max(t * x));
            // Relative to the largest entry, as long as it is not far below 1; squaring a
            // decaying exponential keeps an absolute error near ε instead.
            assert!(
                err <= 1e-14 * x.max(t * x).max(1e-2),
                "p {p}, t {t}: {err:e}"
            );
        }
        // [[0, w], [−w, 0]] t → rotation by w t.
        let w = 3.0f64;
        let a = Mat::from_fn(2, 2, |i, j| match (i, j) {
            (0, 1) => w,
            (1, 0) => -w,
            _ => 0.0,
        });
        let t = 5.0;
        let (s, c) = (w * t).sin_cos();
        let e = expm(&a, t).unwrap();
        assert!(max_abs_diff(&e, &[[c, s], [-s, c]]) < 1e-13);
    }

    #[test]
    fn overflow_is_none() {
        let a = Mat::from_fn(1, 1, |_, _| 1.0);
        assert!(expm(&a, 1e4).is_none());
        assert!(expm(&a, f64::INFINITY).is_none());
    }
}
