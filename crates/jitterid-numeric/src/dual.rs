//! Forward-mode automatic differentiation: a real number that carries one directional
//! derivative, and the [`Real`] trait that lets one piece of code run on plain `f64`s and on
//! [`Dual`]s.
//!
//! A model written once, generically over [`Real`], is evaluated with `f64` for its value and
//! with `Dual` seeded in parameter `j` (`Dual::variable(θ_j)`, every other parameter
//! `Dual::constant`) for its exact derivative with respect to `θ_j`: one pass per parameter.
//! One derivative per pass keeps the type `Copy` (no allocation in the arithmetic), which is
//! what the small matrices of a grey-box model need; `p` passes over a few dozen entries cost
//! nothing next to one matrix exponential.
//!
//! ```
//! use jitterid_numeric::dual::{Dual, Real};
//! fn f<R: Real>(x: R) -> R {
//!     x * x.sin() + R::constant(2.0)
//! }
//! let d = f(Dual::variable(1.5));
//! assert_eq!(d.value, 1.5 * 1.5f64.sin() + 2.0);
//! assert!((d.derivative - (1.5f64.sin() + 1.5 * 1.5f64.cos())).abs() < 1e-15);
//! ```

use std::fmt::Debug;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// A real scalar: `f64` or a [`Dual`]. The operations a physical model's matrices are written
/// with.
pub trait Real:
    Copy
    + Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// A constant (zero derivative).
    fn constant(x: f64) -> Self;
    /// The value (without derivative).
    fn value(self) -> f64;
    /// `√x`.
    fn sqrt(self) -> Self;
    /// `eˣ`.
    fn exp(self) -> Self;
    /// The natural logarithm.
    fn ln(self) -> Self;
    /// `sin x`.
    fn sin(self) -> Self;
    /// `cos x`.
    fn cos(self) -> Self;
    /// `selfᵉ` for a real exponent `e` (which may carry a derivative too).
    fn pow(self, e: Self) -> Self;
}

impl Real for f64 {
    fn constant(x: f64) -> Self {
        x
    }
    fn value(self) -> f64 {
        self
    }
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    fn exp(self) -> Self {
        f64::exp(self)
    }
    fn ln(self) -> Self {
        f64::ln(self)
    }
    fn sin(self) -> Self {
        f64::sin(self)
    }
    fn cos(self) -> Self {
        f64::cos(self)
    }
    fn pow(self, e: Self) -> Self {
        self.powf(e)
    }
}

/// `value + derivative·ε` with `ε² = 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dual {
    /// The value.
    pub value: f64,
    /// The derivative along the seeded direction.
    pub derivative: f64,
}

impl Dual {
    /// The variable being differentiated against: derivative 1.
    pub fn variable(x: f64) -> Self {
        Dual {
            value: x,
            derivative: 1.0,
        }
    }

    /// `x` seeded with derivative 1 when `seed`, 0 otherwise.
    pub fn seeded(x: f64, seed: bool) -> Self {
        Dual {
            value: x,
            derivative: if seed { 1.0 } else { 0.0 },
        }
    }

    /// The chain rule through `f` at this value: `f(v) + f'(v)·d ε`.
    fn chain(self, value: f64, slope: f64) -> Self {
        Dual {
            value,
            derivative: slope * self.derivative,
        }
    }
}

impl Add for Dual {
    type Output = Dual;
    fn add(self, o: Dual) -> Dual {
        Dual {
            value: self.value + o.value,
            derivative: self.derivative + o.derivative,
        }
    }
}

impl Sub for Dual {
    type Output = Dual;
    fn sub(self, o: Dual) -> Dual {
        Dual {
            value: self.value - o.value,
            derivative: self.derivative - o.derivative,
        }
    }
}

impl Mul for Dual {
    type Output = Dual;
    fn mul(self, o: Dual) -> Dual {
        Dual {
            value: self.value * o.value,
            derivative: self.derivative * o.value + self.value * o.derivative,
        }
    }
}

impl Div for Dual {
    type Output = Dual;
    fn div(self, o: Dual) -> Dual {
        let value = self.value / o.value;
        Dual {
            value,
            derivative: (self.derivative - value * o.derivative) / o.value,
        }
    }
}

impl Neg for Dual {
    type Output = Dual;
    fn neg(self) -> Dual {
        Dual {
            value: -self.value,
            derivative: -self.derivative,
        }
    }
}

impl Real for Dual {
    fn constant(x: f64) -> Self {
        Dual {
            value: x,
            derivative: 0.0,
        }
    }
    fn value(self) -> f64 {
        self.value
    }
    fn sqrt(self) -> Self {
        let r = self.value.sqrt();
        self.chain(r, 0.5 / r)
    }
    fn exp(self) -> Self {
        let e = self.value.exp();
        self.chain(e, e)
    }
    fn ln(self) -> Self {
        self.chain(self.value.ln(), 1.0 / self.value)
    }
    fn sin(self) -> Self {
        let (s, c) = self.value.sin_cos();
        self.chain(s, c)
    }
    fn cos(self) -> Self {
        let (s, c) = self.value.sin_cos();
        self.chain(c, -s)
    }
    fn pow(self, e: Self) -> Self {
        let value = self.value.powf(e.value);
        // d(a^b) = b a^{b−1} da + a^b ln(a) db; the second term only when the exponent moves,
        // so that a negative base to a constant (integer) power keeps a finite derivative.
        let mut derivative = e.value * self.value.powf(e.value - 1.0) * self.derivative;
        if e.derivative != 0.0 {
            derivative += value * self.value.ln() * e.derivative;
        }
        Dual { value, derivative }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every operation's derivative against a central difference.
    #[test]
    fn derivatives_match_central_differences() {
        fn f<R: Real>(x: R) -> R {
            let two = R::constant(2.0);
            (x * x - two / x).sqrt() + x.exp().ln() * x.sin() - x.cos() / (-x)
                + x.pow(R::constant(3.0))
                + two.pow(x)
        }
        for x in [1.7, 2.3, 4.0] {
            let d = f(Dual::variable(x));
            let h = 1e-6;
            let fd = (f(x + h) - f(x - h)) / (2.0 * h);
            assert_eq!(d.value, f(x));
            assert!((d.derivative - fd).abs() < 1e-7 * (1.0 + fd.abs()), "{x}");
        }
    }

    /// A negative base to a constant integer power has the derivative `n x^{n−1}`, not NaN.
    #[test]
    fn negative_base_integer_power() {
        let d = Dual::variable(-2.0).pow(Dual::constant(2.0));
        assert_eq!((d.value, d.derivative), (4.0, -4.0));
    }
}
