//! The workspace's numerical kernels, re-exported from their one home, the crate
//! [`jitterid_numeric`], so that a family author (and the crates that import them as
//! `jitterid_jitter::kernels::…`) finds them next to the trait:
//!
//! * [`gauss`]: Gauss–Legendre rules, with the cached 16-point rule [`gauss::gl16`];
//! * [`clenshaw_curtis`]: the closed 17-point Clenshaw–Curtis rule;
//! * [`bessel`]: `J₀`, `J₁` and `I₀`, for the periodic family;
//! * [`chebyshev`]: Chebyshev interpolation of any degree, and adaptive piecewise tables;
//! * [`filon`]: Filon quadrature of a smooth function times a fast exponential `e^{ωs}`;
//! * [`complex`]: [`cexp`](complex::cexp) and [`phasor`](complex::phasor), the exponentials that
//!   never turn an overflow or a huge argument into a NaN;
//! * [`phase`]: exact-enough phase reduction;
//! * [`pieces`]: merging the smooth pieces of several laws into one sorted, disjoint list, as
//!   a sum or a mixture of families needs.
//!
//! Only [`validate`] is this crate's own: the validators of [`jitterid_numeric::validate`] with
//! the error converted to a [`JitterError`](crate::JitterError) that names the parameter, plus
//! `param_count` for `with_params`.

pub use jitterid_numeric::{
    bessel, chebyshev, clenshaw_curtis, complex, filon, gauss, phase, pieces,
};
pub mod validate;
