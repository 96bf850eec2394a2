//! Complex exponentials that stay finite and exact where the textbook form gives NaN.

use num_complex::Complex64;

/// `e^{-i2πx}`, with `x` reduced modulo 1 first so that large `x` keeps the phase accuracy of
/// `x` itself. A double with `|x| ≥ 2^52` is an integer (or infinite), so its phase is 0: the
/// result is then 1 instead of a NaN from `sin(∞)`.
///
/// ```
/// use jitterid_numeric::complex::phasor;
/// let e = phasor(0.25); // e^{-iπ/2} = -i
/// assert!(e.re.abs() < 1e-16 && (e.im + 1.0).abs() < 1e-16);
/// assert_eq!(phasor(1e300).re, 1.0);
/// ```
pub fn phasor(x: f64) -> Complex64 {
    // Exact: x - round(x) is a multiple of ulp(x) no larger than 1/2.
    let r = if x.abs() < 4_503_599_627_370_496.0 {
        x - x.round()
    } else if x.is_nan() {
        x
    } else {
        0.0
    };
    let (s, c) = (2.0 * std::f64::consts::PI * r).sin_cos();
    Complex64::new(c, -s)
}

/// `e^w` that returns an exactly real result for a real argument (so that an overflow gives
/// `+∞` rather than `∞ · sin(0) = NaN` in the imaginary part), and exactly zero once the
/// modulus underflows (so that a huge imaginary part cannot turn `0 · sin(∞)` into a NaN).
///
/// ```
/// use jitterid_numeric::complex::cexp;
/// use num_complex::Complex64;
/// assert_eq!(cexp(Complex64::new(1e3, 0.0)), Complex64::new(f64::INFINITY, 0.0));
/// assert_eq!(cexp(Complex64::new(-1e3, 1e300)), Complex64::new(0.0, 0.0));
/// ```
#[inline]
pub fn cexp(w: Complex64) -> Complex64 {
    if w.im == 0.0 {
        Complex64::new(w.re.exp(), 0.0)
    } else if w.re < -746.0 {
        // e^{-746} is below the smallest subnormal double.
        Complex64::new(0.0, 0.0)
    } else {
        w.exp()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn phasor_matches_the_direct_exponential_where_that_is_accurate() {
        for x in [0.0, 0.1, -0.37, 2.75, 13.125, -1e3 - 0.2] {
            let direct = Complex64::new(0.0, -2.0 * PI * x).exp();
            // The direct form loses |2πx| ε of phase.
            let tol = 4.0 * f64::EPSILON * (1.0 + 2.0 * PI * x.abs());
            assert!((phasor(x) - direct).norm() < tol, "{x}");
        }
        // Exactness of the reduction: 1e8 + 0.25 is still a quarter turn.
        let q = phasor(1e8 + 0.25);
        assert!(q.re.abs() < 1e-8 && (q.im + 1.0).abs() < 1e-15);
        assert!(phasor(f64::NAN).re.is_nan());
    }

    #[test]
    fn cexp_agrees_with_exp_and_never_gives_nan() {
        for w in [
            Complex64::new(0.3, -2.0),
            Complex64::new(-5.0, 7.0),
            Complex64::new(2.0, 0.0),
        ] {
            assert!((cexp(w) - w.exp()).norm() <= 4.0 * f64::EPSILON * w.exp().norm());
        }
        assert!(!cexp(Complex64::new(800.0, 0.0)).im.is_nan());
        let z = cexp(Complex64::new(-800.0, f64::MAX));
        assert!(!z.re.is_nan() && !z.im.is_nan());
    }
}
