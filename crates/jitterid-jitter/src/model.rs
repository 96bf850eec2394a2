pub(crate) use crate::kernels::complex::{cexp, phasor};
use crate::rule::{build_rule, build_rule_from, QuadratureRule};
use crate::JitterError;
use num_complex::Complex64;
use rand::RngCore;
use std::fmt;

/// A point mass of a jitter distribution: `P(τ = position) = mass`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Atom {
    /// Where the mass sits, in seconds.
    pub position: f64,
    /// The probability carried, in `(0, 1]`.
    pub mass: f64,
}

/// Probability mass that a family may leave outside its [`pieces`](JitterModel::pieces) when its
/// support is unbounded.
pub const TAIL_MASS: f64 = 1e-17;

/// A family of sampling-jitter distributions `p(τ; θ)`, with `τ` in seconds.
///
/// The required methods are the family's closed forms; everything the estimators need beyond
/// them (reach, expectation rules) is provided. A family is a validated value: once built,
/// no method can fail. The [`testing::check_contract`](crate::testing::check_contract) helper
/// checks a new family against the properties every family must have.
///
/// Conventions (see the crate docs): `γ(f) = E[e^{-i2πfτ}]`, `f` in Hz, and
/// `M(z) = E[e^{zτ}]`, so that `γ(f) = M(-i2πf)`.
pub trait JitterModel: fmt::Debug + Send + Sync {
    /// Short name of the family, for messages and reports (for example `"uniform-sum"`).
    fn name(&self) -> &'static str;

    /// Names of the continuous parameters `θ`, in the order of [`params`](Self::params).
    fn param_names(&self) -> Vec<String>;

    /// The current continuous parameters `θ`.
    fn params(&self) -> Vec<f64>;

    /// The same family with parameters `θ` (structure such as the integer `n` of the uniform
    /// sum is kept). Validates like the constructor.
    fn with_params(&self, params: &[f64]) -> Result<Self, JitterError>
    where
        Self: Sized;

    /// Characteristic function `γ(f) = E[e^{-i2πfτ}]`.
    fn cf(&self, f: f64) -> Complex64;

    /// `∂γ(f)/∂θ_j` for every parameter, in the order of [`params`](Self::params) (length
    /// [`num_params`](Self::num_params)).
    fn cf_gradient(&self, f: f64) -> Vec<Complex64>;

    /// Moment-generating function `M(z) = E[e^{zτ}]` at a complex `z`, or `None` where the
    /// expectation diverges.
    fn mgf(&self, z: Complex64) -> Option<Complex64>;

    /// Density of the absolutely continuous part of the distribution (zero for a family made
    /// of atoms only).
    fn pdf(&self, tau: f64) -> f64;

    /// Point masses of the distribution, if any.
    fn atoms(&self) -> Vec<Atom> {
        Vec::new()
    }

    /// Intervals, sorted and non-overlapping, that carry the continuous part: the density is
    /// analytic inside each one, varies little enough over it for a 16-point Gauss–Legendre
    /// rule, and the mass outside all of them is below [`TAIL_MASS`]. Knots where the density
    /// is not smooth are interval ends.
    fn pieces(&self) -> Vec<(f64, f64)>;

    /// Mean `E[τ]`.
    fn mean(&self) -> f64;

    /// Variance `Var τ`.
    fn variance(&self) -> f64;

    /// One draw of `τ`.
    fn sample(&self, rng: &mut dyn RngCore) -> f64;

    /// Number of continuous parameters.
    fn num_params(&self) -> usize {
        self.params().len()
    }

    /// Standard deviation `√Var τ`.
    fn std_dev(&self) -> f64 {
        self.variance().sqrt()
    }

    /// The interval `[lo, hi]` outside which the distribution has mass below [`TAIL_MASS`]:
    /// a sample at `t` only sees `s` on `[t + lo, t + hi]`.
    fn reach(&self) -> (f64, f64) {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for (a, b) in self.pieces() {
            lo = lo.min(a);
            hi = hi.max(b);
        }
        for atom in self.atoms() {
            lo = lo.min(atom.position);
            hi = hi.max(atom.position);
        }
        (lo, hi)
    }

    /// A quadrature rule for `E[h(τ)]` where `h` is analytic between the points `breaks`
    /// (in jitter time, relative to the requested sampling instant) and its fastest local rate
    /// is `rate` (1/s; the largest `|z|` of a factor `e^{zτ}` or `2πf` of an oscillation).
    fn rule(&self, breaks: &[f64], rate: f64) -> QuadratureRule {
        build_rule(self, breaks, rate)
    }

    /// The part of [`rule`](Self::rule) on `τ ≥ from`, for `E[h(τ) 1{τ ≥ from}]` (an atom
    /// exactly at `from` counts): half the nodes of cutting the full rule at `from`.
    fn rule_from(&self, from: f64, breaks: &[f64], rate: f64) -> QuadratureRule {
        build_rule_from(self, from, breaks, rate)
    }
}

/// Draws `n` jitter values.
pub fn sample_n<J: JitterModel + ?Sized>(jitter: &J, n: usize, rng: &mut dyn RngCore) -> Vec<f64> {
    (0..n).map(|_| jitter.sample(rng)).collect()
}
