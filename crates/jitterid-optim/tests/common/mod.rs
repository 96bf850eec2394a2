//! Test problems the optimisation layer's integration tests share.

use faer::Mat;
use jitterid_optim::{LeastSquares, SolverError};

/// Rosenbrock's function as residuals `[10(y − x²), 1 − x]`: zero residual at (1, 1), a
/// curved valley on the way.
pub struct Rosenbrock;

impl LeastSquares for Rosenbrock {
    fn num_params(&self) -> usize {
        2
    }
    fn num_residuals(&self) -> usize {
        2
    }
    fn residuals(&self, p: &[f64]) -> Result<Vec<f64>, SolverError> {
        Ok(vec![10.0 * (p[1] - p[0] * p[0]), 1.0 - p[0]])
    }
    fn jacobian(&self, p: &[f64]) -> Result<Mat<f64>, SolverError> {
        let j = [[-20.0 * p[0], 10.0], [-1.0, 0.0]];
        Ok(Mat::from_fn(2, 2, |r, c| j[r][c]))
    }
}
