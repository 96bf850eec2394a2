//! Bessel functions of order 0 and 1, for the periodic (arcsine) jitter family:
//! `J₀(2πq)`, `J₁(2πq)` for real `q` with the phase reduced exactly, and `J₀(ζ)` for complex
//! `ζ` (so `I₀(w) = J₀(iw)`).
//!
//! Two routes, each accurate to rounding where it is used:
//! * `|x| ≤ 25`: the trapezoidal rule on `J₀(x) = (1/2π)∮ cos(x sin θ) dθ` with 64 points; for a
//!   periodic analytic integrand it is exact up to the aliased terms `2J₆₄(x) + …`, below
//!   `(e·25/128)^64 ≈ 1e-18`;
//! * `|x| > 25`: Hankel's asymptotic expansion, whose terms fall until `k ≈ 2|x| > 50`; 30 terms
//!   leave an error below `1e-30`.

use super::complex::phasor;
use num_complex::Complex64;
use std::f64::consts::PI;
use std::sync::OnceLock;

/// Points of the trapezoidal rule.
const TRAPEZOID: usize = 64;

/// Where the asymptotic expansion takes over.
const ASYMPTOTIC: f64 = 25.0;

/// Terms of the asymptotic series.
const TERMS: usize = 30;

/// `sin(2πk/64)`, `k = 0..64`.
fn sines() -> &'static [f64; TRAPEZOID] {
    static S: OnceLock<[f64; TRAPEZOID]> = OnceLock::new();
    S.get_or_init(|| std::array::from_fn(|k| (2.0 * PI * k as f64 / TRAPEZOID as f64).sin()))
}

/// Hankel coefficients `a_k(ν) = Π_{j=1..k} (4ν² − (2j−1)²) / (k! 8^k)`.
fn hankel(nu: f64) -> [f64; TERMS] {
    let mut a = [0.0; TERMS];
    a[0] = 1.0;
    for k in 1..TERMS {
        let j = (2 * k - 1) as f64;
        a[k] = a[k - 1] * (4.0 * nu * nu - j * j) / (k as f64 * 8.0);
    }
    a
}

/// `(P_ν(x), Q_ν(x))` of Hankel's expansion, for complex `x` with `|x| > 25`.
fn p_q(nu: f64, x: Complex64) -> (Complex64, Complex64) {
    let a = hankel(nu);
    let inv = x.inv();
    let (mut p, mut q) = (Complex64::new(0.0, 0.0), Complex64::new(0.0, 0.0));
    let mut pow = Complex64::new(1.0, 0.0);
    for (k, ak) in a.iter().enumerate() {
        // (−1)^{⌊k/2⌋} a_k / x^k, into P for even k and Q for odd k.
        let sign = if (k / 2) % 2 == 0 { 1.0 } else { -1.0 };
        let t = pow * (sign * ak);
        if k % 2 == 0 {
            p += t;
        } else {
            q += t;
        }
        pow *= inv;
    }
    (p, q)
}

/// `(J₀(2πq), J₁(2πq))` for real `q`; 0 for an infinite argument.
pub fn j0_j1(q: f64) -> (f64, f64) {
    let x = 2.0 * PI * q;
    if !x.is_finite() {
        return (0.0, 0.0);
    }
    if x.abs() <= ASYMPTOTIC {
        let (mut j0, mut j1) = (0.0, 0.0);
        for &s in sines() {
            let (sn, cs) = (x * s).sin_cos();
            j0 += cs;
            j1 += s * sn;
        }
        let n = TRAPEZOID as f64;
        return (j0 / n, j1 / n);
    }
    let ax = x.abs();
    let aq = q.abs();
    let amp = (2.0 / (PI * ax)).sqrt();
    let (p0, q0) = p_q(0.0, Complex64::new(ax, 0.0));
    let (p1, q1) = p_q(1.0, Complex64::new(ax, 0.0));
    // cos(x − π/4) and sin(x − π/4) from the phase reduced modulo one turn: phasor(y) is
    // cos(2πy) − i sin(2πy).
    let e0 = phasor(aq - 0.125);
    let e1 = phasor(aq - 0.375);
    let j0 = amp * (p0.re * e0.re + q0.re * e0.im);
    let j1 = amp * (p1.re * e1.re + q1.re * e1.im);
    (j0, if q < 0.0 { -j1 } else { j1 })
}

/// `J₀(ζ)` for complex `ζ` (even in `ζ`).
pub fn j0_complex(z: Complex64) -> Complex64 {
    let z = if z.re < 0.0 { -z } else { z };
    if z.norm() <= ASYMPTOTIC {
        let sum: Complex64 = sines().iter().map(|&s| (z * s).cos()).sum();
        return sum / TRAPEZOID as f64;
    }
    let (p, q) = p_q(0.0, z);
    let chi = z - PI / 4.0;
    (2.0 / (PI * z)).sqrt() * (p * chi.cos() - q * chi.sin())
}

/// `I₀(w)` for real `w`: a series of positive terms for `|w| ≤ 25`, else the asymptotic
/// `e^{|w|}/√(2π|w|) Σ a_k/|w|^k` (positive terms), with the exponential last so that a huge `w`
/// overflows to `+∞` rather than to a NaN.
pub fn i0_real(w: f64) -> f64 {
    let w = w.abs();
    if w <= ASYMPTOTIC {
        // Σ (w/2)^{2k}/(k!)²: terms fall once k > w/2; 80 terms leave < 1e-20 of the sum.
        let y = 0.25 * w * w;
        let (mut t, mut s) = (1.0, 1.0);
        for k in 1..80 {
            t *= y / (k as f64 * k as f64);
            s += t;
        }
        return s;
    }
    let a = hankel(0.0);
    let mut s = 0.0;
    let mut pow = 1.0;
    for ak in a {
        // I₀'s series: a_k(0) alternates in sign; with 1/(−w)^k every term is positive.
        s += ak.abs() * pow;
        pow /= w;
    }
    (w - 0.5 * (2.0 * PI * w).ln() + s.ln()).exp()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gauss::integrate;

    /// Independent route: `J_n(x) = (1/π)∫_0^π cos(nθ − x sin θ) dθ` by refined Gauss–Legendre.
    fn bessel_integral(n: f64, x: f64) -> f64 {
        let parts = (x.abs() / 2.0).ceil() as usize + 2;
        integrate(0.0, PI, parts, |t| (n * t - x * t.sin()).cos()) / PI
    }

    #[test]
    fn both_routes_match_the_integral_representation() {
        for x in [
            0.0,
            1e-8,
            0.3,
            2.404825557695773,
            7.0,
            24.9,
            25.1,
            40.0,
            123.4,
            -3.0,
            -60.0,
        ] {
            let (j0, j1) = j0_j1(x / (2.0 * PI));
            let (r0, r1) = (bessel_integral(0.0, x), bessel_integral(1.0, x));
            assert!((j0 - r0).abs() < 2e-15, "J0({x}) = {j0}, integral {r0}");
            assert!((j1 - r1).abs() < 2e-15, "J1({x}) = {j1}, integral {r1}");
            let c = j0_complex(Complex64::new(x, 0.0));
            assert!((c.re - r0).abs() < 2e-15 && c.im.abs() < 1e-15, "{x}");
        }
        assert_eq!(j0_j1(f64::MAX), (0.0, 0.0));
        assert!(j0_j1(1e300).0.abs() < 1e-150);
    }

    #[test]
    fn i0_matches_the_complex_route_and_the_integral() {
        for w in [0.0f64, 0.5, 3.0, 20.0, 24.0, 26.0, 50.0] {
            // Independent route: I₀(w) = (1/π)∫_0^π e^{w cos θ} dθ.
            let parts = (w / 2.0).ceil() as usize + 2;
            let r = integrate(0.0, PI, parts, |t| (w * t.cos()).exp()) / PI;
            assert!(
                (i0_real(w) / r - 1.0).abs() < 1e-14,
                "I0({w}) = {} vs {r}",
                i0_real(w)
            );
            let c = j0_complex(Complex64::new(0.0, w));
            assert!(
                (c.re / r - 1.0).abs() < 1e-14 && c.im.abs() < 1e-14 * r,
                "{w}: {c}"
            );
        }
        assert_eq!(i0_real(1e4), f64::INFINITY);
    }
}
