//! The coefficients of a rational model as its confluent realisation reads them: a borrowed
//! view that [`Rational`](crate::Rational) hands to [`Confluent`](crate::confluent::Confluent),
//! so that the realisation does not depend on the model type (which falls back on it).

use num_complex::Complex64;

/// `G = N/A` and its parameter derivatives, borrowed from a [`Rational`](crate::Rational).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Coefficients<'a> {
    /// `N`, padded to the denominator's length.
    pub num: &'a [f64],
    /// `A`, monic.
    pub den: &'a [f64],
    /// `∂N/∂θ_j`, padded to the denominator's length.
    pub d_num: &'a [Vec<f64>],
    /// `∂A/∂θ_j` (with a leading 0).
    pub d_den: &'a [Vec<f64>],
    /// The roots of `A`.
    pub poles: &'a [Complex64],
}
