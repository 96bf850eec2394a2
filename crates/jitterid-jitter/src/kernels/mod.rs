//! The workspace's numerical kernels, in one home.
//!
//! Every crate of the workspace that integrates, interpolates or evaluates complex exponentials
//! uses these, and a family author finds here the helpers the built-in families use:
//!
//! * [`gauss`]: Gauss–Legendre rules, with the cached 16-point rule [`gauss::gl16`];
//! * [`bessel`]: `J₀`, `J₁` and `I₀`, for the periodic family;
//! * [`chebyshev`]: Chebyshev interpolation of any degree, and adaptive piecewise tables;
//! * [`filon`]: Filon quadrature of a smooth function times a fast exponential `e^{ωs}`;
//! * [`complex`]: [`cexp`](complex::cexp) and [`phasor`](complex::phasor), the exponentials that
//!   never turn an overflow or a huge argument into a NaN;
//! * [`validate`]: the validators of a family's constructor (`finite`, `positive`,
//!   `param_count`), each returning a [`JitterError`](crate::JitterError) that names the
//!   parameter;
//! * [`pieces`]: merging the smooth pieces of several laws into one sorted, disjoint list, as
//!   a sum or a mixture of families needs.

pub mod bessel;
pub mod chebyshev;
pub mod complex;
pub mod filon;
pub mod gauss;
pub mod pieces;
pub mod validate;
