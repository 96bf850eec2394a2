//! Levenberg–Marquardt's adaptive quadratic model ([`Model::Adaptive`], the default): on a
//! problem whose residuals stay large at the minimum, Gauss–Newton's matrix misses the
//! second-order term `Σ rᵢ ∇²rᵢ` and the plain iteration converges only linearly; the secant
//! estimate of that term restores a fast rate. Where Gauss–Newton's model is right (zero
//! residual), the adaptive search keeps to it and takes the same steps.

mod common;

use common::Rosenbrock;
use faer::Mat;
use jitterid_optim::LmModel as Model;
use jitterid_optim::{LeastSquares, LevenbergMarquardt, Solver, SolverError, SolverReport};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

/// Madsen, Nielsen & Tingleff's large-residual example (*Methods for non-linear least squares
/// problems*, 2004, Examples 3.7 and 3.13): `r(x) = [x + 1, λx² + x − 1]`, a minimum at `x = 0`
/// with `V = 1` for `0 < λ < 1`. There `JᵀJ = 2` while `V'' = 2 − 2λ`, so Gauss–Newton's
/// iteration contracts only by the factor `λ` per step.
struct LargeResidual {
    lambda: f64,
}

impl LeastSquares for LargeResidual {
    fn num_params(&self) -> usize {
        1
    }
    fn num_residuals(&self) -> usize {
        2
    }
    fn residuals(&self, p: &[f64]) -> Result<Vec<f64>, SolverError> {
        let x = p[0];
        Ok(vec![x + 1.0, self.lambda * x * x + x - 1.0])
    }
    fn jacobian(&self, p: &[f64]) -> Result<Mat<f64>, SolverError> {
        let j = [1.0, 2.0 * self.lambda * p[0] + 1.0];
        Ok(Mat::from_fn(2, 1, |r, _| j[r]))
    }
}

fn run<P: LeastSquares>(problem: &P, model: Model, start: &[f64]) -> SolverReport {
    LevenbergMarquardt::default()
        .with_model(model)
        .with_max_iters(2000)
        .minimize(problem, start)
        .expect("runs")
}

#[test]
fn the_default_model_is_adaptive() {
    assert_eq!(
        LevenbergMarquardt::default().options().model,
        Model::Adaptive
    );
}

#[test]
fn secant_model_converges_fast_on_a_large_residual_problem() {
    let mut rng = StdRng::seed_from_u64(27);
    for lambda in [0.5, 0.8, 0.95] {
        let problem = LargeResidual { lambda };
        for _ in 0..4 {
            let start = [rng.random_range(0.0..2.0)];
            let plain = run(&problem, Model::GaussNewton, &start);
            let adaptive = run(&problem, Model::Adaptive, &start);
            let case =
                format!("λ = {lambda}, start {start:?}: plain {plain:?}, adaptive {adaptive:?}");
            assert!(adaptive.converged, "{case}");
            // The cost determines x only to about √(2ε / V'') ≈ 7e-8 at λ = 0.95.
            assert!(adaptive.params[0].abs() < 1e-7, "{case}");
            assert!(adaptive.iterations <= 15, "{case}");
            // Gauss–Newton's linear rate: more than twice the iterations.
            assert!(plain.converged, "{case}");
            assert!(plain.iterations >= 2 * adaptive.iterations, "{case}");
        }
    }
}

#[test]
fn zero_residual_problems_keep_gauss_newton_steps() {
    let mut rng = StdRng::seed_from_u64(28);
    let mut same = 0;
    for _ in 0..10 {
        let start = [rng.random_range(-2.0..2.0), rng.random_range(-2.0..2.0)];
        let plain = run(&Rosenbrock, Model::GaussNewton, &start);
        let adaptive = run(&Rosenbrock, Model::Adaptive, &start);
        let case = format!("start {start:?}: plain {plain:?}, adaptive {adaptive:?}");
        assert!(plain.converged && adaptive.converged, "{case}");
        assert!(
            adaptive.params.iter().all(|p| (p - 1.0).abs() < 1e-8),
            "{case}"
        );
        assert!(adaptive.iterations <= plain.iterations + 1, "{case}");
        same += usize::from(adaptive.params == plain.params);
    }
    // Gauss–Newton predicts these steps well, so the secant model is never switched on.
    assert_eq!(same, 10);
}

#[test]
fn options_written_without_a_model_read_as_adaptive() {
    let old = r#"{"max_iters":5,"xtol":1e-10,"ftol":1e-12,"gtol":1e-10,"initial_lambda":0.001,"scaling":"Marquardt"}"#;
    let options: jitterid_optim::LmOptions = serde_json::from_str(old).expect("reads");
    assert_eq!(options.model, Model::Adaptive);
    let plain = old.replace('}', r#","model":"GaussNewton"}"#);
    let options: jitterid_optim::LmOptions = serde_json::from_str(&plain).expect("reads");
    assert_eq!(options.model, Model::GaussNewton);
}
