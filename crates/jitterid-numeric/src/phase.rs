//! Exact-enough phase reduction: products such as `f·k·T` reduced modulo one cycle with an
//! absolute error near `1e-16`, however large the product.
//!
//! A product `a·b` of two doubles is split exactly into `hi + lo` with a fused multiply-add
//! (`lo = fma(a, b, -hi)`); the integer part of `hi` is removed exactly (`hi - round(hi)` is
//! exact by Sterbenz's lemma), and only then is `lo` added.
//!
//! The window crate's DTFTs, Dirichlet kernels and first moments reduce their phases here.
//!
//! ```
//! use jitterid_numeric::phase::{frac_prod, Cycles};
//! // 0.1 · 1e15 keeps its fractional part 0.00555…: the product is split exactly.
//! assert!((frac_prod(0.1, 1e15) - 0.005_551_115_123_125_783).abs() < 1e-15);
//! // 3 Hz at T = 0.5 s is 1.5 cycles per sample: 12 345 samples are half a cycle.
//! assert_eq!(Cycles::new(3.0, 0.5).times(12345.0).abs(), 0.5);
//! ```

use num_complex::Complex64;
use std::f64::consts::{PI, TAU};

/// `a·b` as an unevaluated sum `hi + lo`, exactly.
#[inline]
fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let hi = a * b;
    (hi, a.mul_add(b, -hi))
}

/// `x - round(x)`, in `[-0.5, 0.5]`, exact.
#[inline]
fn centred_frac(x: f64) -> f64 {
    x - x.round()
}

/// A frequency expressed in cycles per sample, `x = f·T`, reduced modulo 1 and kept as an
/// unevaluated sum `hi + lo` (`hi ∈ [-0.5, 0.5]`, `|lo| ≲ 1e-16`), so that phases `k·x` can
/// be reduced modulo one cycle without losing the digits `f·T` has above the unit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cycles {
    hi: f64,
    lo: f64,
}

impl Cycles {
    /// `f·T` reduced modulo 1.
    #[inline]
    pub fn new(f: f64, interval: f64) -> Self {
        let (p, e) = two_prod(f, interval);
        Self {
            hi: centred_frac(p),
            lo: e,
        }
    }

    /// The same frequency shifted by `d` cycles per sample (`d` small, such as `±1/N`),
    /// reduced again, without rounding the sum.
    #[inline]
    pub fn shifted(self, d: f64) -> Self {
        // two-sum of hi and d
        let s = self.hi + d;
        let bb = s - self.hi;
        let err = (self.hi - (s - bb)) + (d - bb);
        let h = centred_frac(s);
        Self {
            hi: h,
            lo: self.lo + err,
        }
    }

    /// The reduced value `x mod 1`, rounded to a double, in about `[-0.5, 0.5]`.
    #[inline]
    pub fn value(self) -> f64 {
        self.hi + self.lo
    }

    /// Whether the value is finite.
    #[inline]
    pub fn is_finite(self) -> bool {
        self.hi.is_finite() && self.lo.is_finite()
    }

    /// `k·x` reduced modulo 1 into about `[-0.5, 0.5]`, with an absolute error of a few
    /// `1e-17` for any `k` below `2^53`.
    #[inline]
    pub fn times(self, k: f64) -> f64 {
        let (p, e) = two_prod(k, self.hi);
        let s = centred_frac(p) + (e + k * self.lo);
        centred_frac(s)
    }

    /// `k·x` reduced modulo 2 into about `[-1, 1]` (for half-angle formulas), as accurately
    /// as [`times`](Self::times).
    #[inline]
    pub fn times_mod2(self, k: f64) -> f64 {
        let (p, e) = two_prod(k, self.hi);
        let r = p - 2.0 * (0.5 * p).round();
        let s = r + (e + k * self.lo);
        s - 2.0 * (0.5 * s).round()
    }
}

/// `e^{-i2πφ}` for a phase `φ` in cycles.
#[inline]
pub fn cis_neg_cycles(phi: f64) -> Complex64 {
    let (s, c) = (TAU * phi).sin_cos();
    Complex64::new(c, -s)
}

/// `e^{+i2πφ}` for a phase `φ` in cycles.
#[inline]
pub fn cis_cycles(phi: f64) -> Complex64 {
    let (s, c) = (TAU * phi).sin_cos();
    Complex64::new(c, s)
}

/// `e^{-iπφ}` for a half-phase `φ` (so `φ = 2` is a full cycle).
#[inline]
pub fn cis_neg_half_cycles(phi: f64) -> Complex64 {
    let (s, c) = (PI * phi).sin_cos();
    Complex64::new(c, -s)
}

/// `(a·b) mod 1` in about `[-0.5, 0.5]`, with an absolute error near `1e-16`.
#[inline]
pub fn frac_prod(a: f64, b: f64) -> f64 {
    let (p, e) = two_prod(a, b);
    centred_frac(centred_frac(p) + e)
}

/// `sin(π·k·x)` for `x` in cycles per sample, exact up to rounding of the final sine: the
/// product is reduced modulo 2 first.
#[inline]
pub fn sin_pi_times(x: Cycles, k: f64) -> f64 {
    (PI * x.times_mod2(k)).sin()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frac_prod_is_exact_for_large_products() {
        // 0.1 * 1e15 is not 1e14 in binary: the exact product of the two doubles is
        // 100000000000000.0055511151231257827...; its fractional part survives.
        let a = 0.1_f64;
        let b = 1e15_f64;
        let f = frac_prod(a, b);
        assert!((f - 0.005_551_115_123_125_783).abs() < 1e-15, "{f}");
    }

    #[test]
    fn cycles_times_matches_integer_multiples() {
        let x = Cycles::new(0.25, 1.0);
        assert_eq!(x.times(4.0), 0.0);
        assert_eq!(x.times(2.0).abs(), 0.5);
        // 3 Hz at T = 0.5 s is 1.5 cycles per sample, i.e. half a cycle.
        let y = Cycles::new(3.0, 0.5);
        assert_eq!(y.value().abs(), 0.5);
        assert_eq!(y.times(12345.0).abs(), 0.5);
        assert_eq!(y.times(12346.0), 0.0);
    }

    #[test]
    fn shifted_keeps_small_differences() {
        let x = Cycles::new(1.0 / 3.0, 1.0);
        let y = x.shifted(-1.0 / 3.0);
        assert!(y.value().abs() < 1e-16);
    }

    #[test]
    fn times_mod2_is_periodic() {
        let x = Cycles::new(0.3, 1.0);
        let a = x.times_mod2(5.0); // 1.5 -> -0.5
        assert!((a + 0.5).abs() < 1e-15 || (a - 1.5).abs() < 1e-15, "{a}");
    }
}
