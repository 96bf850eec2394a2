//! The numerical kernels of **jitterid**, in one home.
//!
//! Every crate of the workspace that integrates, interpolates, reduces a phase or evaluates a
//! complex exponential uses these rather than keeping a copy; the jitter crate re-exports this
//! crate as `jitterid_jitter::kernels`, where a family author finds the helpers the built-in
//! families use. The crate depends on nothing of the workspace.
//!
//! * [`gauss`]: Gauss–Legendre rules, with the cached 16-point rule [`gauss::gl16`], the
//!   composite panels and the rate-based subdivision of the workspace's expectation rules;
//! * [`clenshaw_curtis`]: the closed 17-point Clenshaw–Curtis rule, the second opinion of the
//!   adaptive reference integrations of the contract tests;
//! * [`filon`]: Filon quadrature of a smooth function times a fast exponential `e^{ωs}`;
//! * [`chebyshev`]: Chebyshev interpolation of any degree, and adaptive piecewise tables;
//! * [`bessel`]: `J₀`, `J₁` and `I₀`, for the periodic jitter family;
//! * [`complex`]: [`cexp`](complex::cexp) and [`phasor`](complex::phasor), the exponentials that
//!   never turn an overflow or a huge argument into a NaN;
//! * [`phase`]: phases `f·k·T` reduced modulo one cycle exactly enough, for the DTFTs and the
//!   Dirichlet kernels of the window crate;
//! * [`pieces`]: merging the smooth pieces of several laws into one sorted, disjoint list, as
//!   a sum or a mixture of jitter families needs;
//! * [`limits`]: the documented limits on the sizes a caller can ask for (samples, switches,
//!   tones, poles, sum terms, quadrature nodes, file sizes, realisations), checked where each
//!   size enters the library;
//! * [`dual`]: forward-mode derivatives (dual numbers) and the [`Real`](dual::Real) trait a
//!   model is written over to get them;
//! * [`expr`]: arithmetic expressions of named parameters, parsed once and evaluated on `f64`
//!   or on dual numbers (the matrices of a grey-box model written in an experiment file);
//! * [`budget`]: the wall-clock budget and cancel flag that every long loop checks;
//! * [`validate`]: the validators of a constructor's real parameters (`finite`, `positive`,
//!   `non_negative`), whose error names the parameter.
//!
//! # Conventions
//!
//! * Time in seconds, frequency in Hz; a phase "in cycles" `φ` means the angle `2πφ`.
//! * The Fourier sign is negative: [`complex::phasor`]`(x) = e^{-i2πx}`, matching the
//!   characteristic function `γ(f) = E[e^{-i2πfτ}]` and the DTFT `Σ y_k e^{-i2πfkT}`.
//! * Rules are given on `[-1, 1]` as `(nodes, weights)`, nodes increasing for Gauss–Legendre;
//!   a composite rule maps node `x` of a panel `(mid, half)` to `mid + half·x`, weight
//!   `half·w`.
//! * A composite rule keeps `rate × panel width ≤` [`gauss::MAX_RATE_WIDTH`], where `rate` is
//!   the integrand's fastest local rate in 1/s (the largest `|z|` of a factor `e^{zτ}`, or
//!   `2π|f|` of an oscillation).
//! * The exponentials of [`complex`] never turn a finite argument into a NaN: an overflow
//!   gives `∞`, an underflow `0`.
#![warn(missing_docs)]

pub mod bessel;
pub mod budget;
pub mod chebyshev;
pub mod clenshaw_curtis;
pub mod complex;
pub mod dual;
pub mod expr;
pub mod filon;
pub mod gauss;
pub mod limits;
pub mod phase;
pub mod pieces;
pub mod validate;
