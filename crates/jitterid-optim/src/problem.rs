//! The least-squares problem trait, finite differences, and adapters to argmin's problem traits.

use super::normal::{jt_r, NormalEquations, NormalEquationsOperator};
use super::SolverError;
use argmin::core::{CostFunction, Error, Gradient, Jacobian, Operator};
use faer::Mat;

/// Default relative step of [`fd_jacobian`]: `ε^{1/3}`, which balances truncation and rounding
/// error of central differences for smooth residuals of order one.
pub const DEFAULT_FD_STEP: f64 = 6.055_454_452_393_343e-6;

/// A nonlinear least-squares problem: residuals `r(θ) ∈ ℝᵐ` of parameters `θ ∈ ℝⁿ`, minimised
/// in the sense of the cost `V(θ) = ½ Σ rᵢ(θ)²`.
///
/// Like argmin's problem traits this is one capability with the crate's error type. Only
/// [`residuals`](Self::residuals) is mandatory; [`jacobian`](Self::jacobian) falls back to
/// central finite differences ([`fd_jacobian`]).
///
/// Return non-finite residuals (e.g. `f64::INFINITY`) to mark `θ` as infeasible: solvers then
/// avoid that point. Return an `Err` only for failures that should abort the solve.
pub trait LeastSquares: Send + Sync {
    /// Number of parameters `n`.
    fn num_params(&self) -> usize;

    /// Number of residuals `m` (at least `n` for the solvers to accept the problem).
    fn num_residuals(&self) -> usize;

    /// The residual vector `r(θ)`, of length [`num_residuals`](Self::num_residuals).
    ///
    /// # Errors
    ///
    /// Implementation-defined; an error aborts the solve.
    fn residuals(&self, theta: &[f64]) -> Result<Vec<f64>, SolverError>;

    /// The Jacobian `∂rᵢ/∂θⱼ`: rows are residuals, columns are parameters.
    ///
    /// Defaults to [`fd_jacobian`] with [`DEFAULT_FD_STEP`]; override it with the analytic
    /// Jacobian when one is available.
    ///
    /// # Errors
    ///
    /// Implementation-defined; the default forwards errors of [`residuals`](Self::residuals).
    fn jacobian(&self, theta: &[f64]) -> Result<Mat<f64>, SolverError> {
        fd_jacobian(self, theta, DEFAULT_FD_STEP)
    }

    /// `JᵀJ` and `Jᵀr` at `theta`, where `residuals` are the residuals at `theta`.
    ///
    /// Defaults to forming them from [`jacobian`](Self::jacobian). Override it when the
    /// products can be accumulated without storing the `m × n` Jacobian: the
    /// [Levenberg–Marquardt](super::LevenbergMarquardt) solver only asks for these, so its
    /// memory then stays flat in the number of residuals.
    ///
    /// # Errors
    ///
    /// Those of [`jacobian`](Self::jacobian), a Jacobian of the wrong shape, and
    /// [`SolverError::ResidualLength`] if `residuals` has the wrong length.
    fn normal_equations(
        &self,
        theta: &[f64],
        residuals: &[f64],
    ) -> Result<NormalEquations, SolverError> {
        NormalEquations::from_jacobian(&checked_jacobian(self, theta)?, residuals)
    }
}

impl<P: LeastSquares + ?Sized> LeastSquares for &P {
    fn num_params(&self) -> usize {
        (**self).num_params()
    }
    fn num_residuals(&self) -> usize {
        (**self).num_residuals()
    }
    fn residuals(&self, theta: &[f64]) -> Result<Vec<f64>, SolverError> {
        (**self).residuals(theta)
    }
    fn jacobian(&self, theta: &[f64]) -> Result<Mat<f64>, SolverError> {
        (**self).jacobian(theta)
    }
    fn normal_equations(
        &self,
        theta: &[f64],
        residuals: &[f64],
    ) -> Result<NormalEquations, SolverError> {
        (**self).normal_equations(theta, residuals)
    }
}

/// Central-difference Jacobian of `problem` at `theta`.
///
/// Parameter `j` is stepped by `h = rel_step · max(|θⱼ|, 1)` (rounded so that `θⱼ ± h` is
/// exact). Where a residual is not finite on one side, the one-sided difference from the other
/// side is used; where neither works the entry is NaN. Costs `2n` residual evaluations (plus one
/// at `theta` if a one-sided difference is needed).
///
/// # Errors
///
/// [`SolverError::InvalidOption`] if `rel_step` is not finite and positive,
/// [`SolverError::WrongStartLength`] if `theta` has the wrong length, and errors of
/// [`LeastSquares::residuals`] (including [`SolverError::ResidualLength`]).
pub fn fd_jacobian<P: LeastSquares + ?Sized>(
    problem: &P,
    theta: &[f64],
    rel_step: f64,
) -> Result<Mat<f64>, SolverError> {
    super::error::check_option(
        "rel_step",
        rel_step,
        rel_step.is_finite() && rel_step > 0.0,
        "must be finite and > 0",
    )?;
    let n = problem.num_params();
    if theta.len() != n {
        return Err(SolverError::WrongStartLength {
            expected: n,
            got: theta.len(),
        });
    }
    let m = problem.num_residuals();
    let mut jac = Mat::<f64>::zeros(m, n);
    let mut x = theta.to_vec();
    let mut r0: Option<Vec<f64>> = None;
    for j in 0..n {
        let xj = theta[j];
        let h = rel_step * xj.abs().max(1.0);
        let (xp, xm) = (xj + h, xj - h);
        x[j] = xp;
        let rp = checked_residuals(problem, &x)?;
        x[j] = xm;
        let rm = checked_residuals(problem, &x)?;
        x[j] = xj;
        for i in 0..m {
            jac[(i, j)] = if rp[i].is_finite() && rm[i].is_finite() {
                (rp[i] - rm[i]) / (xp - xm)
            } else {
                if r0.is_none() {
                    r0 = Some(checked_residuals(problem, theta)?);
                }
                let c = r0.as_ref().map_or(f64::NAN, |r| r[i]);
                if rp[i].is_finite() && c.is_finite() {
                    (rp[i] - c) / (xp - xj)
                } else if rm[i].is_finite() && c.is_finite() {
                    (c - rm[i]) / (xj - xm)
                } else {
                    f64::NAN
                }
            };
        }
    }
    Ok(jac)
}

/// `problem.residuals(theta)`, checked for the declared length.
pub(crate) fn checked_residuals<P: LeastSquares + ?Sized>(
    problem: &P,
    theta: &[f64],
) -> Result<Vec<f64>, SolverError> {
    let r = problem.residuals(theta)?;
    let expected = problem.num_residuals();
    if r.len() != expected {
        return Err(SolverError::ResidualLength {
            expected,
            got: r.len(),
        });
    }
    Ok(r)
}

/// `problem.jacobian(theta)`, checked for the declared shape (faer panics on mismatched
/// products, so no unchecked Jacobian may reach the linear algebra).
pub(crate) fn checked_jacobian<P: LeastSquares + ?Sized>(
    problem: &P,
    theta: &[f64],
) -> Result<Mat<f64>, SolverError> {
    let j = problem.jacobian(theta)?;
    check_jacobian_shape(&j, problem.num_residuals(), problem.num_params())?;
    Ok(j)
}

/// Checks that `j` is `rows × cols`.
pub(crate) fn check_jacobian_shape(
    j: &Mat<f64>,
    rows: usize,
    cols: usize,
) -> Result<(), SolverError> {
    if j.nrows() != rows || j.ncols() != cols {
        return Err(SolverError::JacobianShape {
            expected_rows: rows,
            expected_cols: cols,
            rows: j.nrows(),
            cols: j.ncols(),
        });
    }
    Ok(())
}

/// Checks the problem's dimensions and the start's length and finiteness.
pub(crate) fn validate_start<P: LeastSquares + ?Sized>(
    problem: &P,
    start: &[f64],
) -> Result<(), SolverError> {
    let n = problem.num_params();
    let m = problem.num_residuals();
    if n == 0 {
        return Err(SolverError::NoParameters);
    }
    if m < n {
        return Err(SolverError::TooFewResiduals {
            residuals: m,
            params: n,
        });
    }
    if start.len() != n {
        return Err(SolverError::WrongStartLength {
            expected: n,
            got: start.len(),
        });
    }
    if let Some((index, value)) = first_non_finite(start) {
        return Err(SolverError::NonFiniteStart { index, value });
    }
    Ok(())
}

/// Residuals at a validated start, which must be finite with a finite sum of squares.
pub(crate) fn start_residuals<P: LeastSquares + ?Sized>(
    problem: &P,
    start: &[f64],
) -> Result<Vec<f64>, SolverError> {
    let r = checked_residuals(problem, start)?;
    if let Some((index, value)) = first_non_finite(&r) {
        return Err(SolverError::NonFiniteResidual { index, value });
    }
    if !half_sum_sq(&r).is_finite() {
        return Err(SolverError::Evaluation(
            "the sum of squared residuals overflows at the start".to_string(),
        ));
    }
    Ok(r)
}

/// First non-finite entry, if any.
pub(crate) fn first_non_finite(v: &[f64]) -> Option<(usize, f64)> {
    v.iter().copied().enumerate().find(|(_, x)| !x.is_finite())
}

/// `½ Σ rᵢ²`.
pub(crate) fn half_sum_sq(r: &[f64]) -> f64 {
    0.5 * r.iter().map(|x| x * x).sum::<f64>()
}

/// Exposes a [`LeastSquares`] problem through argmin's problem traits with `Vec<f64>`
/// parameters, so that argmin's solvers (and [`lm::LevenbergMarquardt`](super::lm)) run on it.
///
/// | argmin trait     | `Param`    | output                                    |
/// |------------------|------------|-------------------------------------------|
/// | [`Operator`]     | `Vec<f64>` | residuals `Vec<f64>`                      |
/// | [`Jacobian`]     | `Vec<f64>` | `faer::Mat<f64>`, residuals × parameters  |
/// | [`CostFunction`] | `Vec<f64>` | `½ Σ rᵢ²`                                 |
/// | [`Gradient`]     | `Vec<f64>` | `Jᵀ r`                                    |
/// | [`NormalEquationsOperator`] | `Vec<f64>` | `JᵀJ` and `Jᵀ r` ([`NormalEquations`]) |
///
/// Lengths and shapes are checked; violations surface as [`SolverError`]s inside argmin's
/// error, recoverable with `err.downcast::<SolverError>()`. Pass `&problem` to borrow.
#[derive(Clone, Debug)]
pub struct ArgminProblem<P> {
    problem: P,
}

impl<P: LeastSquares> ArgminProblem<P> {
    /// Wraps `problem`.
    pub fn new(problem: P) -> Self {
        ArgminProblem { problem }
    }

    /// The wrapped problem.
    pub fn inner(&self) -> &P {
        &self.problem
    }

    /// Unwraps the problem.
    pub fn into_inner(self) -> P {
        self.problem
    }

    fn check_len(&self, param: &[f64]) -> Result<(), SolverError> {
        let expected = self.problem.num_params();
        if param.len() != expected {
            return Err(SolverError::WrongStartLength {
                expected,
                got: param.len(),
            });
        }
        Ok(())
    }
}

impl<P: LeastSquares> Operator for ArgminProblem<P> {
    type Param = Vec<f64>;
    type Output = Vec<f64>;

    fn apply(&self, param: &Vec<f64>) -> Result<Vec<f64>, Error> {
        self.check_len(param)?;
        Ok(checked_residuals(&self.problem, param)?)
    }
}

impl<P: LeastSquares> Jacobian for ArgminProblem<P> {
    type Param = Vec<f64>;
    type Jacobian = Mat<f64>;

    fn jacobian(&self, param: &Vec<f64>) -> Result<Mat<f64>, Error> {
        self.check_len(param)?;
        Ok(checked_jacobian(&self.problem, param)?)
    }
}

impl<P: LeastSquares> NormalEquationsOperator for ArgminProblem<P> {
    type Param = Vec<f64>;

    fn normal_equations(
        &self,
        param: &Vec<f64>,
        residuals: &[f64],
    ) -> Result<NormalEquations, Error> {
        self.check_len(param)?;
        let expected = self.problem.num_residuals();
        if residuals.len() != expected {
            return Err(SolverError::ResidualLength {
                expected,
                got: residuals.len(),
            }
            .into());
        }
        let ne = self.problem.normal_equations(param, residuals)?;
        ne.check_shape(param.len())?;
        Ok(ne)
    }
}

impl<P: LeastSquares> CostFunction for ArgminProblem<P> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, param: &Vec<f64>) -> Result<f64, Error> {
        Ok(half_sum_sq(&self.apply(param)?))
    }
}

impl<P: LeastSquares> Gradient for ArgminProblem<P> {
    type Param = Vec<f64>;
    type Gradient = Vec<f64>;

    fn gradient(&self, param: &Vec<f64>) -> Result<Vec<f64>, Error> {
        let r = self.apply(param)?;
        let j = Jacobian::jacobian(self, param)?;
        Ok(jt_r(&j, &r))
    }
}

/// Like [`ArgminProblem`], but with parameters, residuals and gradients as faer column matrices
/// (`Mat<f64>` with one column), as argmin's matrix solvers need (`GaussNewtonLS` inverts
/// `JᵀJ`, which argmin-math implements for faer but not for `Vec`).
#[derive(Clone, Debug)]
pub struct ArgminFaerProblem<P> {
    problem: P,
}

impl<P: LeastSquares> ArgminFaerProblem<P> {
    /// Wraps `problem`.
    pub fn new(problem: P) -> Self {
        ArgminFaerProblem { problem }
    }

    /// The wrapped problem.
    pub fn inner(&self) -> &P {
        &self.problem
    }

    /// Unwraps the problem.
    pub fn into_inner(self) -> P {
        self.problem
    }

    fn to_vec(&self, param: &Mat<f64>) -> Result<Vec<f64>, SolverError> {
        let expected = self.problem.num_params();
        if param.ncols() != 1 || param.nrows() != expected {
            return Err(SolverError::WrongStartLength {
                expected,
                got: param.nrows() * param.ncols(),
            });
        }
        Ok(col_to_vec(param))
    }
}

/// First column of `m` as a `Vec`.
pub(crate) fn col_to_vec(m: &Mat<f64>) -> Vec<f64> {
    if m.ncols() == 0 {
        return Vec::new();
    }
    (0..m.nrows()).map(|i| m[(i, 0)]).collect()
}

/// `v` as a one-column matrix.
pub(crate) fn vec_to_col(v: &[f64]) -> Mat<f64> {
    Mat::from_fn(v.len(), 1, |i, _| v[i])
}

impl<P: LeastSquares> Operator for ArgminFaerProblem<P> {
    type Param = Mat<f64>;
    type Output = Mat<f64>;

    fn apply(&self, param: &Mat<f64>) -> Result<Mat<f64>, Error> {
        let theta = self.to_vec(param)?;
        Ok(vec_to_col(&checked_residuals(&self.problem, &theta)?))
    }
}

impl<P: LeastSquares> Jacobian for ArgminFaerProblem<P> {
    type Param = Mat<f64>;
    type Jacobian = Mat<f64>;

    fn jacobian(&self, param: &Mat<f64>) -> Result<Mat<f64>, Error> {
        let theta = self.to_vec(param)?;
        Ok(checked_jacobian(&self.problem, &theta)?)
    }
}

impl<P: LeastSquares> CostFunction for ArgminFaerProblem<P> {
    type Param = Mat<f64>;
    type Output = f64;

    fn cost(&self, param: &Mat<f64>) -> Result<f64, Error> {
        let theta = self.to_vec(param)?;
        Ok(half_sum_sq(&checked_residuals(&self.problem, &theta)?))
    }
}

impl<P: LeastSquares> Gradient for ArgminFaerProblem<P> {
    type Param = Mat<f64>;
    type Gradient = Mat<f64>;

    fn gradient(&self, param: &Mat<f64>) -> Result<Mat<f64>, Error> {
        let theta = self.to_vec(param)?;
        let r = checked_residuals(&self.problem, &theta)?;
        let j = checked_jacobian(&self.problem, &theta)?;
        Ok(vec_to_col(&jt_r(&j, &r)))
    }
}

/// `problem` with residuals and Jacobian multiplied by a constant `scale`; the minimiser is
/// unchanged. Used to normalise the starting residual norm for argmin's Gauss–Newton.
pub(crate) struct Scaled<'a, P: ?Sized> {
    pub(crate) problem: &'a P,
    pub(crate) scale: f64,
}

impl<P: LeastSquares + ?Sized> LeastSquares for Scaled<'_, P> {
    fn num_params(&self) -> usize {
        self.problem.num_params()
    }
    fn num_residuals(&self) -> usize {
        self.problem.num_residuals()
    }
    fn residuals(&self, theta: &[f64]) -> Result<Vec<f64>, SolverError> {
        let mut r = self.problem.residuals(theta)?;
        r.iter_mut().for_each(|x| *x *= self.scale);
        Ok(r)
    }
    fn jacobian(&self, theta: &[f64]) -> Result<Mat<f64>, SolverError> {
        let j = self.problem.jacobian(theta)?;
        Ok(Mat::from_fn(j.nrows(), j.ncols(), |r, c| {
            j[(r, c)] * self.scale
        }))
    }
}
