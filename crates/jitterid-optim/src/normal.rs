//! The normal equations `JᵀJ` and `Jᵀr`: all a Gauss–Newton-type step needs of the Jacobian.
//!
//! A long record has millions of residuals but a handful of parameters, so the `m × n`
//! Jacobian is the largest object of a fit while the `n × n` matrix `JᵀJ` and the gradient
//! `Jᵀr` are tiny. Problems that can form them without the Jacobian
//! ([`LeastSquares::normal_equations`](super::LeastSquares::normal_equations)) keep the memory
//! of a fit flat in the number of parameters.

use super::SolverError;
use argmin::core::Error;
use faer::Mat;

/// `JᵀJ` and `Jᵀr` of a least-squares problem at one point.
#[derive(Clone, Debug, PartialEq)]
pub struct NormalEquations {
    /// `JᵀJ`, `n × n`, symmetric.
    pub gram: Mat<f64>,
    /// `Jᵀr`, the gradient of `½‖r‖²`, length `n`.
    pub gradient: Vec<f64>,
}

impl NormalEquations {
    /// The normal equations of an explicit Jacobian `j` (`m × n`) and residuals `r` (length `m`).
    ///
    /// # Errors
    ///
    /// [`SolverError::ResidualLength`] if `r` does not have one entry per row of `j`.
    pub fn from_jacobian(j: &Mat<f64>, r: &[f64]) -> Result<Self, SolverError> {
        if r.len() != j.nrows() {
            return Err(SolverError::ResidualLength {
                expected: j.nrows(),
                got: r.len(),
            });
        }
        Ok(NormalEquations {
            gram: gram(j),
            gradient: jt_r(j, r),
        })
    }

    /// Normal equations of `n` parameters that are all NaN: the value of a point outside the
    /// model's domain, which solvers reject like a non-finite residual.
    pub fn not_finite(n: usize) -> Self {
        NormalEquations {
            gram: Mat::from_fn(n, n, |_, _| f64::NAN),
            gradient: vec![f64::NAN; n],
        }
    }

    /// Number of parameters `n`.
    pub fn num_params(&self) -> usize {
        self.gradient.len()
    }

    /// Whether every entry of `JᵀJ` and `Jᵀr` is finite.
    pub fn is_finite(&self) -> bool {
        self.first_non_finite().is_none()
    }

    /// The first entry that is not finite: `("gradient", i, value)` for `Jᵀr`, or
    /// `("gram", a·n + b, value)` for `JᵀJ` (row `a`, column `b`).
    pub fn first_non_finite(&self) -> Option<(&'static str, usize, f64)> {
        if let Some((i, &v)) = self
            .gradient
            .iter()
            .enumerate()
            .find(|(_, g)| !g.is_finite())
        {
            return Some(("gradient", i, v));
        }
        let n = self.gram.ncols();
        (0..self.gram.nrows())
            .flat_map(|a| (0..n).map(move |b| (a, b)))
            .map(|(a, b)| (a * n + b, self.gram[(a, b)]))
            .find(|(_, v)| !v.is_finite())
            .map(|(i, v)| ("gram", i, v))
    }

    /// Checks that the shapes fit `n` parameters.
    ///
    /// # Errors
    ///
    /// [`SolverError::JacobianShape`] when they do not.
    pub fn check_shape(&self, n: usize) -> Result<(), SolverError> {
        let (rows, cols) = (self.gram.nrows(), self.gram.ncols());
        if rows != n || cols != n || self.gradient.len() != n {
            return Err(SolverError::JacobianShape {
                expected_rows: n,
                expected_cols: n,
                rows,
                cols: if self.gradient.len() == n {
                    cols
                } else {
                    self.gradient.len()
                },
            });
        }
        Ok(())
    }
}

/// An argmin problem that provides the normal equations at a parameter vector and its
/// residuals, without handing out the Jacobian.
///
/// [`LevenbergMarquardt`](super::LevenbergMarquardt) requires it;
/// [`ArgminProblem`](super::ArgminProblem) implements it for every
/// [`LeastSquares`](super::LeastSquares) problem.
pub trait NormalEquationsOperator {
    /// Parameter vector type.
    type Param;

    /// `JᵀJ` and `Jᵀr` at `param`, where `residuals` are the residuals at `param`.
    ///
    /// # Errors
    ///
    /// Implementation-defined; an error aborts the solve.
    fn normal_equations(
        &self,
        param: &Self::Param,
        residuals: &[f64],
    ) -> Result<NormalEquations, Error>;
}

/// Column `c` of `j` as a slice (a `Mat` stores its columns contiguously).
fn column(j: &Mat<f64>, c: usize) -> &[f64] {
    j.col(c)
        .try_as_col_major()
        .map_or(&[][..], |col| col.as_slice())
}

/// `Σ a_i b_i`.
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// `Jᵀ r` (the gradient of `½‖r‖²`); `j` must have `r.len()` rows.
///
/// Plain sequential dot products rather than faer's product: with a handful of columns and up
/// to millions of rows the parallel kernel spends its time in barriers, and a fixed summation
/// order keeps Monte Carlo runs bit-identical whatever the thread count.
pub fn jt_r(j: &Mat<f64>, r: &[f64]) -> Vec<f64> {
    (0..j.ncols()).map(|c| dot(column(j, c), r)).collect()
}

/// `JᵀJ`, sequential (plain dot products in a fixed order: bit-identical whatever the thread
/// count).
pub fn gram(j: &Mat<f64>) -> Mat<f64> {
    let cols: Vec<&[f64]> = (0..j.ncols()).map(|c| column(j, c)).collect();
    gram_of(&cols, dot)
}

/// The symmetric matrix `G_ab = inner(col_a, col_b)`, each pair computed once.
pub fn gram_of<C: AsRef<[f64]>>(cols: &[C], inner: impl Fn(&[f64], &[f64]) -> f64) -> Mat<f64> {
    let p = cols.len();
    let mut g = Mat::zeros(p, p);
    for a in 0..p {
        for b in 0..=a {
            let v = inner(cols[a].as_ref(), cols[b].as_ref());
            g[(a, b)] = v;
            g[(b, a)] = v;
        }
    }
    g
}
