//! Real polynomials with coefficients in decreasing powers (`[a_n, …, a_0]`), as in the usual
//! `num`/`den` notation of transfer functions.

use num_complex::Complex64;

/// `p(z)` by Horner's rule.
pub fn eval(p: &[f64], z: Complex64) -> Complex64 {
    p.iter()
        .fold(Complex64::new(0.0, 0.0), |acc, &c| acc * z + c)
}

/// `A'(r_i) = Π_{l≠i} (r_i − r_l)` of the monic polynomial `A = Π (z − r_l)` with these
/// roots: from the roots, so that partial fractions over them sum back to `N/A` even where two
/// roots nearly coincide (the coefficients' `A'` there is a small difference of large terms).
pub(crate) fn derivative_at_root(roots: &[Complex64], i: usize) -> Complex64 {
    roots
        .iter()
        .enumerate()
        .filter(|&(l, _)| l != i)
        .map(|(_, &r)| roots[i] - r)
        .product()
}

/// The derivative's coefficients.
pub fn derivative(p: &[f64]) -> Vec<f64> {
    let n = p.len().saturating_sub(1);
    p[..n]
        .iter()
        .enumerate()
        .map(|(i, &c)| c * (n - i) as f64)
        .collect()
}

/// The product `a · b`.
pub fn mul(a: &[f64], b: &[f64]) -> Vec<f64> {
    if a.is_empty() || b.is_empty() {
        return Vec::new();
    }
    let mut out = vec![0.0; a.len() + b.len() - 1];
    for (i, &x) in a.iter().enumerate() {
        for (j, &y) in b.iter().enumerate() {
            out[i + j] += x * y;
        }
    }
    out
}

/// `p` padded with leading zeros to `len` coefficients (no-op when already that long).
pub fn pad(p: &[f64], len: usize) -> Vec<f64> {
    let mut out = vec![0.0; len.saturating_sub(p.len())];
    out.extend_from_slice(p);
    out
}

/// Roots of `p` (leading coefficient non-zero) as eigenvalues of the companion matrix, each
/// polished by Newton steps on `p`, and conjugate pairs made exact. `None` if the eigenvalue
/// solver fails or a root is not finite.
pub fn roots(p: &[f64]) -> Option<Vec<Complex64>> {
    let n = p.len().checked_sub(1)?;
    if n == 0 {
        return Some(Vec::new());
    }
    let lead = p[0];
    if lead == 0.0 || !lead.is_finite() {
        return None;
    }
    let companion = faer::Mat::<f64>::from_fn(n, n, |i, j| {
        if i == 0 {
            -p[j + 1] / lead
        } else if i == j + 1 {
            1.0
        } else {
            0.0
        }
    });
    let mut r = companion.eigenvalues().ok()?;
    let dp = derivative(p);
    for z in r.iter_mut() {
        for _ in 0..3 {
            let d = eval(&dp, *z);
            if d.norm() == 0.0 {
                break;
            }
            let step = eval(p, *z) / d;
            if !step.is_finite() {
                break;
            }
            *z -= step;
        }
    }
    // Snap near-real roots onto the real axis and make pairs exact conjugates.
    let scale = r.iter().map(|z| z.norm()).fold(1.0, f64::max);
    for z in r.iter_mut() {
        if z.im.abs() <= 1e-12 * scale {
            z.im = 0.0;
        }
    }
    let mut out: Vec<Complex64> = Vec::with_capacity(n);
    let mut used = vec![false; n];
    for i in 0..n {
        if used[i] {
            continue;
        }
        used[i] = true;
        let z = r[i];
        if z.im == 0.0 {
            out.push(z);
            continue;
        }
        let partner = (0..n).filter(|&j| !used[j]).min_by(|&a, &b| {
            (r[a] - z.conj())
                .norm()
                .total_cmp(&(r[b] - z.conj()).norm())
        })?;
        used[partner] = true;
        let avg = 0.5 * (z + r[partner].conj());
        let upper = Complex64::new(avg.re, avg.im.abs());
        out.push(upper);
        out.push(upper.conj());
    }
    out.iter().all(|z| z.is_finite()).then_some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roots_of_known_polynomial() {
        // (s + 2)(s² + 0.5 s + 0.1525): roots −2, −0.25 ± 0.3i.
        let p = mul(&[1.0, 2.0], &[1.0, 0.5, 0.1525]);
        let r = roots(&p).unwrap();
        let mut found = [false; 3];
        for z in r {
            for (i, want) in [
                Complex64::new(-2.0, 0.0),
                Complex64::new(-0.25, 0.3),
                Complex64::new(-0.25, -0.3),
            ]
            .iter()
            .enumerate()
            {
                if (z - want).norm() < 1e-13 {
                    found[i] = true;
                }
            }
        }
        assert_eq!(found, [true; 3]);
    }

    #[test]
    fn derivative_and_eval_agree_with_difference() {
        let p = [2.0, -3.0, 0.5, 7.0];
        let z = Complex64::new(0.3, -0.7);
        let h = 1e-6;
        let fd = (eval(&p, z + h) - eval(&p, z - h)) / (2.0 * h);
        assert!((fd - eval(&derivative(&p), z)).norm() < 1e-8);
    }
}
