//! Sampling-jitter families for **jitterid**.
//!
//! A sensor asked to sample at `t_k = t0 + kT` measures at `t_k + τ_k`, with `τ_k` independent
//! draws from a jitter distribution `p(τ; θ)`. This crate holds the [`JitterModel`] trait, its
//! families, the run-time type [`AnyJitter`] with the [`registry`] of families by name, and
//! [`kernels`], a re-export of the workspace's numerical kernels from their one home, the
//! crate `jitterid-numeric`.
//!
//! Families: [`NoJitter`], [`UniformSum`] (the paper's), [`Gaussian`], [`Laplace`],
//! [`TwoPoint`], [`ExponentialDelay`], [`Periodic`] (arcsine law of a tone), and the
//! combinators [`Shifted`] (a constant offset), [`Sum`] (independent sum, e.g. the dual-Dirac
//! model `Sum<Gaussian, TwoPoint>`) and [`Mixture`].
//!
//! # Conventions
//!
//! * Time in seconds, frequency `f` in Hz (never rad/s in public APIs).
//! * Characteristic function `γ(f) = E[e^{-i2πfτ}]`: `γ(0) = 1`, `|γ| ≤ 1`,
//!   `γ(-f) = conj γ(f)`, real for a symmetric density.
//! * Moment-generating function `M(z) = E[e^{zτ}]` for complex `z`, so `γ(f) = M(-i2πf)`.
//!   The first moment of an LTI system's jittered output needs `M` at the system's poles.
//! * The uniform-sum family is the corrected form of the paper's eq. (15):
//!   `τ = U_1 + … + U_{n+1}`, `U_j ~ U[-a/(n+1), a/(n+1)]`, support `[-a, a]`,
//!   variance `a²/(3(n+1))`, `γ(f) = [sin(2πfa/(n+1)) / (2πfa/(n+1))]^{n+1}`.
//!
//! # Example
//!
//! ```
//! use jitterid_jitter::{JitterModel, UniformSum};
//!
//! // The paper's Table 2 jitter: n = 2, a = 1/(2√3) s.
//! let jitter = UniformSum::new(2, 0.5 / 3f64.sqrt()).unwrap();
//! assert!((jitter.variance() - 0.25 / 3.0 / 9.0).abs() < 1e-15);
//! let g = jitter.cf(0.25); // damping of a 0.25 Hz component
//! assert!(g.re > 0.9 && g.im == 0.0);
//! // Expectations over the jitter by quadrature: E[τ²] is the variance.
//! let rule = jitter.rule(&[], 0.0);
//! assert!((rule.expect(|t| t * t) - jitter.variance()).abs() < 1e-15);
//! ```
//!
//! # Choosing a family at run time
//!
//! ```
//! use jitterid_jitter::registry::JitterRegistry;
//! use jitterid_jitter::serde_json::json;
//! use jitterid_jitter::JitterModel;
//! let spec = json!({"family": "sum", "terms": [
//!     {"family": "gaussian", "sigma": 0.01}, {"family": "periodic", "amplitude": 0.02}]});
//! let j = JitterRegistry::builtin().build(spec.as_object().unwrap()).unwrap();
//! assert!((j.variance() - (1e-4 + 2e-4)).abs() < 1e-18);
//! ```
//!
//! # Adding a family
//!
//! Implement [`JitterModel`] for a new type with a validating constructor (the validators are in
//! [`kernels::validate`]), run [`testing::check_contract`] on it in a test, and give a
//! [`registry::Family`] entry to [`registry::JitterRegistry::register`] so that front ends can
//! build it from key/value pairs. Nothing else in the workspace changes: signals, windows and
//! estimators take any `JitterModel`. See `docs/extending.md`, which walks through the periodic
//! family.
#![warn(missing_docs)]

mod any;
mod error;
pub mod kernels;
mod model;
pub mod registry;
pub mod rule;
pub mod testing;

mod dirac;
mod exponential;
mod gaussian;
mod laplace;
mod mixture;
mod periodic;
mod shifted;
mod sum;
mod two_point;
mod uniform_sum;

pub use any::AnyJitter;
pub use dirac::NoJitter;
pub use error::JitterError;
pub use exponential::ExponentialDelay;
pub use gaussian::Gaussian;
pub use laplace::Laplace;
pub use mixture::Mixture;
pub use model::{
    sample_n, Atom, CfAtParams, InverseSampler, JitterModel, CF_GRADIENT_STEP, TAIL_MASS,
};
pub use num_complex;
pub use periodic::Periodic;
pub use rule::QuadratureRule;
/// Re-exported: spec tables ([`registry::SpecTable`]) are `serde_json` maps.
pub use serde_json;
pub use shifted::Shifted;
pub use sum::Sum;
pub use two_point::TwoPoint;
pub use uniform_sum::UniformSum;
