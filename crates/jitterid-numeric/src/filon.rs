//! Filon quadrature of a smooth function times a fast exponential.
//!
//! `∫_{-1}^{1} f(s) e^{ω(s+1)} ds` for `Re ω ≤ 0` and any `|ω|`: `f` is replaced by its
//! degree-15 interpolant through the 16 Gauss–Legendre nodes, whose Legendre coefficients are
//! integrated against the exponential exactly ([`exp_legendre_moments`]). The cost is 16
//! values of `f` whatever `ω`, where plain Gauss–Legendre needs `O(|ω|)` nodes.

use super::complex::cexp;
use super::gauss::{gl16, GL_ORDER};
use num_complex::Complex64;
use std::sync::OnceLock;

const ZERO: Complex64 = Complex64::new(0.0, 0.0);

/// Below this `|ω|` the 16 nodes resolve `e^{ω(s+1)}` themselves and [`filon_exp`] uses them.
pub const RESOLVED_OMEGA: f64 = 3.0;

/// `(2k+1)/2 · w_j · P_k(s_j)` at the Gauss–Legendre nodes: row `k` maps the 16 values at the
/// nodes to the `k`-th Legendre coefficient of their degree-15 interpolant.
pub fn legendre_coefficients() -> &'static [[f64; GL_ORDER]; GL_ORDER] {
    static L: OnceLock<[[f64; GL_ORDER]; GL_ORDER]> = OnceLock::new();
    L.get_or_init(|| {
        let (s, w) = gl16();
        let mut coef = [[0.0; GL_ORDER]; GL_ORDER];
        for (j, (&x, &wj)) in s.iter().zip(w).enumerate() {
            let (mut p0, mut p1) = (1.0, x);
            for (k, row) in coef.iter_mut().enumerate() {
                let pk = if k == 0 { p0 } else { p1 };
                row[j] = (2 * k + 1) as f64 / 2.0 * wj * pk;
                if k >= 1 {
                    let p2 = ((2 * k + 1) as f64 * x * p1 - k as f64 * p0) / (k + 1) as f64;
                    p0 = p1;
                    p1 = p2;
                }
            }
        }
        coef
    })
}

/// `N_k = ∫_{−1}^{1} P_k(s) e^{ω(s+1)} ds` for `k = 0..=16`, `Re ω ≤ 0`, `|ω| > 3`.
///
/// Integrating `(2k+1) P_k = P'_{k+1} − P'_{k−1}` by parts gives
/// `N_{k+1} = N_{k−1} − (2k+1) N_k / ω`. Forward from `N_0 = (e^{2ω} − 1)/ω` it is stable while
/// `k ≲ |ω|`; below, `N_k` is the recurrence's minimal solution, computed backward (Miller)
/// from well beyond `k = 16` and normalised by the Legendre series of `e^{ω(s+1)}` at `s = −1`,
/// `Σ (2k+1)/2 (−1)^k N_k = 1`.
pub fn exp_legendre_moments(omega: Complex64, n: &mut [Complex64; GL_ORDER + 1]) {
    let r = omega.norm();
    if r >= (GL_ORDER + 1) as f64 {
        let e2 = cexp(2.0 * omega);
        let inv = omega.inv();
        n[0] = (e2 - 1.0) * inv;
        n[1] = (e2 + 1.0 - n[0]) * inv;
        for k in 1..GL_ORDER {
            n[k + 1] = n[k - 1] - n[k] * inv * (2 * k + 1) as f64;
        }
        return;
    }
    // The minimal solution falls like |ω|^k/(2k+1)!!: from this start its truncation error is
    // far below rounding at k ≤ 16.
    let top = 2 * GL_ORDER + 2 * (r.ceil() as usize) + 16;
    let inv = omega.inv();
    let (mut above, mut cur) = (ZERO, Complex64::new(1.0, 0.0));
    let sign = |k: usize| if k % 2 == 0 { 1.0 } else { -1.0 };
    let mut norm = cur * ((2 * top + 1) as f64 / 2.0 * sign(top));
    n.fill(ZERO);
    for k in (1..=top).rev() {
        let below = above + cur * inv * (2 * k + 1) as f64;
        above = cur;
        cur = below;
        if k - 1 <= GL_ORDER {
            n[k - 1] = cur;
        }
        norm += cur * ((2 * k - 1) as f64 / 2.0 * sign(k - 1));
        if cur.norm() > 1e100 {
            // The recurrence is linear; keep the moduli far from overflow (also of |z|² in
            // complex division).
            above *= 1e-100;
            cur *= 1e-100;
            norm *= 1e-100;
            n.iter_mut().for_each(|x| *x *= 1e-100);
        }
    }
    let m = norm.norm();
    let unit = (norm / m).conj() / m;
    n.iter_mut().for_each(|x| *x *= unit);
}

/// A smooth function on `[−1, 1]` given by its values at the 16 Gauss–Legendre nodes
/// ([`gl16`]), ready to be integrated against `e^{ω(s+1)}` for many `ω`: the Legendre
/// coefficients of its degree-15 interpolant are computed once.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilonIntegrand {
    values: [f64; GL_ORDER],
    legendre: [f64; GL_ORDER],
}

impl FilonIntegrand {
    /// The integrand with values `f_j = f(s_j)` at the nodes of [`gl16`].
    pub fn new(values: &[f64; GL_ORDER]) -> Self {
        let mut legendre = [0.0; GL_ORDER];
        for (fk, row) in legendre.iter_mut().zip(legendre_coefficients()) {
            *fk = row.iter().zip(values).map(|(a, b)| a * b).sum();
        }
        FilonIntegrand {
            values: *values,
            legendre,
        }
    }

    /// `(∫ f(s) e^{ω(s+1)} ds, ∫ (s+1) f(s) e^{ω(s+1)} ds)` over `[−1, 1]`, `Re ω ≤ 0`. Exact
    /// for `f` a polynomial of degree ≤ 15 (up to rounding); for `|ω| ≤` [`RESOLVED_OMEGA`]
    /// the nodes themselves integrate the product.
    pub fn integrate(&self, omega: Complex64) -> (Complex64, Complex64) {
        let (s, w) = gl16();
        let (mut a, mut m) = (ZERO, ZERO);
        if omega.norm() <= RESOLVED_OMEGA {
            for ((sj, wj), fj) in s.iter().zip(w).zip(&self.values) {
                let e = cexp(omega * (sj + 1.0)) * (wj * fj);
                a += e;
                m += e * (sj + 1.0);
            }
            return (a, m);
        }
        let mut n = [ZERO; GL_ORDER + 1];
        exp_legendre_moments(omega, &mut n);
        for (k, &c) in self.legendre.iter().enumerate() {
            a += c * n[k];
            // (s + 1) P_k = ((k+1) P_{k+1} + k P_{k−1})/(2k+1) + P_k.
            let below = if k > 0 { n[k - 1] * k as f64 } else { ZERO };
            m += c * ((n[k + 1] * (k + 1) as f64 + below) / (2 * k + 1) as f64 + n[k]);
        }
        (a, m)
    }
}

/// `(∫ f(s) e^{ω(s+1)} ds, ∫ (s+1) f(s) e^{ω(s+1)} ds)` over `[−1, 1]`, `Re ω ≤ 0`, from the
/// values `f_j = f(s_j)` at the 16 Gauss–Legendre nodes ([`gl16`]): one use of
/// [`FilonIntegrand`].
pub fn filon_exp(values: &[f64; GL_ORDER], omega: Complex64) -> (Complex64, Complex64) {
    FilonIntegrand::new(values).integrate(omega)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gauss::integrate;

    /// Independent route: Gauss–Legendre refined to width `1/|ω|`.
    fn refined(f: impl Fn(f64) -> f64, omega: Complex64, weight: impl Fn(f64) -> f64) -> Complex64 {
        let parts = (omega.norm() * 2.0).ceil() as usize + 1;
        let re = integrate(-1.0, 1.0, parts, |s| {
            f(s) * weight(s) * cexp(omega * (s + 1.0)).re
        });
        let im = integrate(-1.0, 1.0, parts, |s| {
            f(s) * weight(s) * cexp(omega * (s + 1.0)).im
        });
        Complex64::new(re, im)
    }

    #[test]
    fn filon_matches_refined_quadrature_for_every_rate() {
        let f = |s: f64| 1.0 + 0.3 * s - 0.2 * s.powi(7) + 0.05 * s.powi(15);
        let values: [f64; GL_ORDER] = std::array::from_fn(|j| f(gl16().0[j]));
        for omega in [
            Complex64::new(-0.5, 2.0),
            Complex64::new(-2.0, 10.0),
            Complex64::new(-0.1, 150.0),
            Complex64::new(-40.0, -3.0),
            Complex64::new(0.0, 1e3),
        ] {
            let (a, m) = filon_exp(&values, omega);
            let ra = refined(f, omega, |_| 1.0);
            let rm = refined(f, omega, |s| s + 1.0);
            // Both routes are exact up to rounding of O(|ω|) terms each of size ≤ 2.
            let tol = 1e-13 * (1.0 + omega.norm().sqrt());
            assert!((a - ra).norm() < tol, "{omega}: {a} vs {ra}");
            assert!((m - rm).norm() < tol, "{omega}: {m} vs {rm}");
        }
    }

    #[test]
    fn moments_satisfy_the_normalisation() {
        let mut n = [ZERO; GL_ORDER + 1];
        let omega = Complex64::new(-1.0, 8.0);
        exp_legendre_moments(omega, &mut n);
        // N_0 = (e^{2ω} − 1)/ω in closed form.
        let n0 = (cexp(2.0 * omega) - 1.0) / omega;
        assert!((n[0] - n0).norm() < 1e-14);
    }

    #[test]
    fn exp_legendre_moments_match_refined_quadrature() {
        // Against Gauss–Legendre on sub-intervals of width ≤ 1/|ω| (exact to ~1e-16 there);
        // the moduli of the integrands are at most 1, so the error bound is absolute.
        let (s, w) = gl16();
        for r in [3.01, 5.0, 11.0, 16.99, 17.0, 30.0, 300.0, 3000.0] {
            for angle in [0.5, 0.55, 0.7, 0.9, 1.0] {
                let omega = Complex64::from_polar(r, angle * std::f64::consts::PI);
                let mut n = [ZERO; GL_ORDER + 1];
                exp_legendre_moments(omega, &mut n);
                let parts = (2.0 * r).ceil() as usize;
                let h = 1.0 / parts as f64;
                let mut want = [ZERO; GL_ORDER + 1];
                for q in 0..parts {
                    let mid = -1.0 + (2 * q + 1) as f64 * h;
                    for (x, wx) in s.iter().zip(w) {
                        let t = mid + h * x;
                        let e = cexp(omega * (t + 1.0)) * (h * wx);
                        let (mut p0, mut p1) = (1.0, t);
                        for (k, m) in want.iter_mut().enumerate() {
                            *m += e * if k == 0 { p0 } else { p1 };
                            if k >= 1 {
                                let p2 =
                                    ((2 * k + 1) as f64 * t * p1 - k as f64 * p0) / (k + 1) as f64;
                                p0 = p1;
                                p1 = p2;
                            }
                        }
                    }
                }
                for k in 0..=GL_ORDER {
                    assert!(
                        (n[k] - want[k]).norm() < 1e-14,
                        "ω = {omega}, k = {k}: {} vs {}",
                        n[k],
                        want[k]
                    );
                }
            }
        }
    }
}
