//! The exponential of a small dense real matrix, by scaling and squaring of its Taylor series.
//!
//! `e^{X} = (e^{X/2^s})^{2^s}` with `s` the least integer that brings `‖X/2^s‖₁ ≤ 1/2`, and
//! `e^{Y}` for `‖Y‖₁ ≤ 1/2` by its Taylor polynomial of degree [`DEGREE`], whose truncation
//! error is below `Σ_{k>15} 2^{−k}/k! < 1e-18` relative to `‖e^Y‖ ≥ e^{−1/2}`. Matrices here are
//! the generators of confluent responses (a few tens of rows at most), so the `O(d³)` products
//! are cheap and no linear solve (as a Padé approximant needs) is involved.

/// Degree of the Taylor polynomial on the scaled matrix.
const DEGREE: usize = 15;

/// `‖X‖₁` above which the matrix is halved before the series.
const THETA: f64 = 0.5;

/// `C = A·B` for `d × d` row-major matrices.
pub(crate) fn mat_mul(a: &[f64], b: &[f64], d: usize, c: &mut [f64]) {
    c.iter_mut().for_each(|x| *x = 0.0);
    for i in 0..d {
        for k in 0..d {
            let aik = a[i * d + k];
            if aik == 0.0 {
                continue;
            }
            for j in 0..d {
                c[i * d + j] += aik * b[k * d + j];
            }
        }
    }
}

/// `y = A·x` for a `d × d` row-major matrix.
pub(crate) fn mat_vec(a: &[f64], x: &[f64], y: &mut [f64]) {
    let d = x.len();
    for (i, yi) in y.iter_mut().enumerate() {
        *yi = a[i * d..(i + 1) * d]
            .iter()
            .zip(x)
            .map(|(a, x)| a * x)
            .sum();
    }
}

/// `yᵀ = xᵀ·A` for a `d × d` row-major matrix.
pub(crate) fn vec_mat(x: &[f64], a: &[f64], y: &mut [f64]) {
    let d = x.len();
    y.iter_mut().for_each(|v| *v = 0.0);
    for (i, &xi) in x.iter().enumerate() {
        for (j, yj) in y.iter_mut().enumerate() {
            *yj += xi * a[i * d + j];
        }
    }
}

/// `e^{A t}` for a `d × d` row-major `A` (`d ≥ 1`) and a finite `t`.
pub(crate) fn expm(a: &[f64], d: usize, t: f64) -> Vec<f64> {
    let norm = (0..d)
        .map(|j| (0..d).map(|i| a[i * d + j].abs()).sum::<f64>())
        .fold(0.0, f64::max)
        * t.abs();
    let squarings = if norm > THETA {
        (norm / THETA).log2().ceil() as i32
    } else {
        0
    };
    let scale = t * 2f64.powi(-squarings);
    let y: Vec<f64> = a.iter().map(|x| x * scale).collect();
    // Horner: I + Y(I + Y/2(I + Y/3(… (I + Y/DEGREE)))).
    let mut e = identity(d);
    let mut tmp = vec![0.0; d * d];
    for k in (1..=DEGREE).rev() {
        mat_mul(&y, &e, d, &mut tmp);
        let inv = 1.0 / k as f64;
        for (i, (ei, ti)) in e.iter_mut().zip(&tmp).enumerate() {
            *ei = ti * inv + if i % (d + 1) == 0 { 1.0 } else { 0.0 };
        }
    }
    for _ in 0..squarings {
        mat_mul(&e, &e, d, &mut tmp);
        std::mem::swap(&mut e, &mut tmp);
    }
    e
}

/// The `d × d` identity.
pub(crate) fn identity(d: usize) -> Vec<f64> {
    let mut e = vec![0.0; d * d];
    for i in 0..d {
        e[i * d + i] = 1.0;
    }
    e
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: &[f64], b: &[f64], tol: f64) {
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() <= tol * (1.0 + y.abs()), "{x} vs {y}");
        }
    }

    /// A diagonal matrix, a Jordan block (`e^{Jt} = e^{λt}[[1, t], [0, 1]]`), a rotation
    /// generator (`[[cos, −sin], [sin, cos]]`) and a nilpotent block, each in closed form, at
    /// scales that need no squaring and many.
    #[test]
    fn closed_forms() {
        for t in [0.0, 0.1, 1.0, 7.3, 40.0] {
            let e = expm(&[-1.0, 0.0, 0.0, -3.0], 2, t);
            close(&e, &[(-t).exp(), 0.0, 0.0, (-3.0 * t).exp()], 1e-14);
            let lambda = -0.7;
            let e = expm(&[lambda, 1.0, 0.0, lambda], 2, t);
            let l = (lambda * t).exp();
            close(&e, &[l, t * l, 0.0, l], 1e-13);
            let w = 2.5;
            let e = expm(&[0.0, -w, w, 0.0], 2, t);
            let (s, c) = (w * t).sin_cos();
            close(&e, &[c, -s, s, c], 1e-12);
            let e = expm(&[0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0], 3, t);
            close(
                &e,
                &[1.0, t, t * t / 2.0, 0.0, 1.0, t, 0.0, 0.0, 1.0],
                1e-14,
            );
        }
    }

    /// `e^{A(s+t)} = e^{As} e^{At}` for a non-normal matrix with a repeated eigenvalue.
    #[test]
    fn semigroup() {
        let a = [-2.0, 5.0, 1.0, 0.0, -2.0, 3.0, 0.0, 0.0, -0.5];
        let (s, t) = (0.37, 2.9);
        let mut prod = vec![0.0; 9];
        mat_mul(&expm(&a, 3, s), &expm(&a, 3, t), 3, &mut prod);
        close(&prod, &expm(&a, 3, s + t), 1e-13);
    }
}
