//! Tests of the optimisation layer through its public API.

mod common;

use common::Rosenbrock;
use faer::Mat;
use jitterid_optim::{
    fd_jacobian, GaussNewtonLineSearch, LeastSquares, LevenbergMarquardt, MultiStart, NelderMead,
    Scaling, Solver, SolverError, SolverReport, Termination, Transform, Transformed,
};

/// `y = a e^{−bt} + c` sampled at `t = 0, 0.25, …`, with an analytic Jacobian.
struct Exponential {
    t: Vec<f64>,
    y: Vec<f64>,
}

impl Exponential {
    fn model(p: &[f64], t: f64) -> f64 {
        p[0] * (-p[1] * t).exp() + p[2]
    }

    /// Exact data from `truth`, plus `noise · sin(17 k)` on sample `k`.
    fn new(truth: [f64; 3], noise: f64) -> Self {
        let t: Vec<f64> = (0..40).map(|k| 0.25 * k as f64).collect();
        let y = t
            .iter()
            .enumerate()
            .map(|(k, &t)| Self::model(&truth, t) + noise * (17.0 * k as f64).sin())
            .collect();
        Exponential { t, y }
    }
}

impl LeastSquares for Exponential {
    fn num_params(&self) -> usize {
        3
    }
    fn num_residuals(&self) -> usize {
        self.t.len()
    }
    fn residuals(&self, p: &[f64]) -> Result<Vec<f64>, SolverError> {
        Ok(self
            .t
            .iter()
            .zip(&self.y)
            .map(|(&t, &y)| Self::model(p, t) - y)
            .collect())
    }
    fn jacobian(&self, p: &[f64]) -> Result<Mat<f64>, SolverError> {
        Ok(Mat::from_fn(self.t.len(), 3, |i, j| {
            let e = (-p[1] * self.t[i]).exp();
            match j {
                0 => e,
                1 => -p[0] * self.t[i] * e,
                _ => 1.0,
            }
        }))
    }
}

/// `y = A sin(ωt)`; the cost has many local minima in `ω`.
struct Sinusoid {
    t: Vec<f64>,
    y: Vec<f64>,
}

impl Sinusoid {
    fn new(amplitude: f64, omega: f64) -> Self {
        let t: Vec<f64> = (0..100).map(|k| 0.1 * k as f64).collect();
        let y = t.iter().map(|&t| amplitude * (omega * t).sin()).collect();
        Sinusoid { t, y }
    }
}

impl LeastSquares for Sinusoid {
    fn num_params(&self) -> usize {
        2
    }
    fn num_residuals(&self) -> usize {
        self.t.len()
    }
    fn residuals(&self, p: &[f64]) -> Result<Vec<f64>, SolverError> {
        Ok(self
            .t
            .iter()
            .zip(&self.y)
            .map(|(&t, &y)| p[0] * (p[1] * t).sin() - y)
            .collect())
    }
    fn jacobian(&self, p: &[f64]) -> Result<Mat<f64>, SolverError> {
        Ok(Mat::from_fn(self.t.len(), 2, |i, j| {
            let t = self.t[i];
            match j {
                0 => (p[1] * t).sin(),
                _ => p[0] * t * (p[1] * t).cos(),
            }
        }))
    }
}

/// Residual `x − 3` (minimum at 3), but NaN for `x > 1`: the solvers must stop at the wall.
struct NanWall;

impl LeastSquares for NanWall {
    fn num_params(&self) -> usize {
        1
    }
    fn num_residuals(&self) -> usize {
        1
    }
    fn residuals(&self, p: &[f64]) -> Result<Vec<f64>, SolverError> {
        Ok(vec![if p[0] <= 1.0 { p[0] - 3.0 } else { f64::NAN }])
    }
    fn jacobian(&self, p: &[f64]) -> Result<Mat<f64>, SolverError> {
        Ok(Mat::from_fn(
            1,
            1,
            |_, _| {
                if p[0] <= 1.0 {
                    1.0
                } else {
                    f64::NAN
                }
            },
        ))
    }
}

/// Declares 3 residuals but returns 2.
struct WrongLength;

impl LeastSquares for WrongLength {
    fn num_params(&self) -> usize {
        1
    }
    fn num_residuals(&self) -> usize {
        3
    }
    fn residuals(&self, p: &[f64]) -> Result<Vec<f64>, SolverError> {
        Ok(vec![p[0], p[0]])
    }
}

/// Declares a 2×2 Jacobian but returns 2×1.
struct WrongShape;

impl LeastSquares for WrongShape {
    fn num_params(&self) -> usize {
        2
    }
    fn num_residuals(&self) -> usize {
        2
    }
    fn residuals(&self, p: &[f64]) -> Result<Vec<f64>, SolverError> {
        Ok(vec![p[0] - 1.0, p[1] - 2.0])
    }
    fn jacobian(&self, _p: &[f64]) -> Result<Mat<f64>, SolverError> {
        Ok(Mat::zeros(2, 1))
    }
}

/// One residual, two parameters.
struct Underdetermined;

impl LeastSquares for Underdetermined {
    fn num_params(&self) -> usize {
        2
    }
    fn num_residuals(&self) -> usize {
        1
    }
    fn residuals(&self, p: &[f64]) -> Result<Vec<f64>, SolverError> {
        Ok(vec![p[0] + p[1]])
    }
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

fn assert_sane(report: &SolverReport) {
    assert!(report.cost.is_finite(), "{report:?}");
    assert!(report.params.iter().all(|p| p.is_finite()), "{report:?}");
    assert_eq!(
        report.converged,
        report.termination.is_convergence(),
        "{report:?}"
    );
}

#[test]
fn lm_solves_rosenbrock() {
    for scaling in [Scaling::Marquardt, Scaling::Identity] {
        let lm = LevenbergMarquardt::default().with_scaling(scaling);
        let report = lm.minimize(&Rosenbrock, &[-1.2, 1.0]).unwrap();
        assert!(report.converged, "{scaling:?}: {report:?}");
        assert!(
            max_abs_diff(&report.params, &[1.0, 1.0]) < 1e-10,
            "{scaling:?}: {report:?}"
        );
        assert!(report.cost < 1e-20, "{report:?}");
        assert!(report.iterations > 0 && report.iterations < 100);
    }
}

#[test]
fn lm_with_finite_difference_jacobian_solves_rosenbrock() {
    /// Rosenbrock without an analytic Jacobian.
    struct FdRosenbrock;
    impl LeastSquares for FdRosenbrock {
        fn num_params(&self) -> usize {
            2
        }
        fn num_residuals(&self) -> usize {
            2
        }
        fn residuals(&self, p: &[f64]) -> Result<Vec<f64>, SolverError> {
            Rosenbrock.residuals(p)
        }
    }
    let report = LevenbergMarquardt::default()
        .minimize(&FdRosenbrock, &[-1.2, 1.0])
        .unwrap();
    assert!(report.converged, "{report:?}");
    assert!(
        max_abs_diff(&report.params, &[1.0, 1.0]) < 1e-10,
        "{report:?}"
    );
}

#[test]
fn lm_fits_exponential_from_fifty_percent_off() {
    let truth = [2.0, 0.7, 0.5];
    let problem = Exponential::new(truth, 0.0);
    for start in [[3.0, 1.05, 0.75], [1.0, 0.35, 0.25], [3.0, 0.35, 0.75]] {
        let report = LevenbergMarquardt::default()
            .minimize(&problem, &start)
            .unwrap();
        assert!(report.converged, "{start:?}: {report:?}");
        assert!(
            max_abs_diff(&report.params, &truth) < 1e-9,
            "{start:?}: {report:?}"
        );
    }
}

#[test]
fn lm_and_gauss_newton_agree_on_a_noisy_fit() {
    let problem = Exponential::new([2.0, 0.7, 0.5], 0.02);
    let start = [3.0, 1.05, 0.75];
    let lm = LevenbergMarquardt::default()
        .minimize(&problem, &start)
        .unwrap();
    let gn = GaussNewtonLineSearch::default()
        .minimize(&problem, &start)
        .unwrap();
    assert!(lm.converged, "{lm:?}");
    assert!(gn.converged, "{gn:?}");
    assert!(lm.cost > 1e-4, "the fit has a nonzero residual: {lm:?}");
    assert!(
        max_abs_diff(&lm.params, &gn.params) < 1e-6,
        "{lm:?}\n{gn:?}"
    );
    assert!(
        (lm.cost - gn.cost).abs() <= 1e-10 * lm.cost,
        "{lm:?}\n{gn:?}"
    );
}

#[test]
fn gauss_newton_fits_exact_exponential() {
    let truth = [2.0, 0.7, 0.5];
    let report = GaussNewtonLineSearch::default()
        .minimize(&Exponential::new(truth, 0.0), &[3.0, 1.05, 0.75])
        .unwrap();
    assert!(report.converged, "{report:?}");
    assert!(max_abs_diff(&report.params, &truth) < 1e-8, "{report:?}");
}

#[test]
fn nelder_mead_solves_rosenbrock() {
    let report = NelderMead::default()
        .minimize(&Rosenbrock, &[-1.2, 1.0])
        .unwrap();
    assert!(report.converged, "{report:?}");
    assert!(
        max_abs_diff(&report.params, &[1.0, 1.0]) < 1e-6,
        "{report:?}"
    );
}

#[test]
fn fd_jacobian_matches_analytic() {
    let problem = Exponential::new([2.0, 0.7, 0.5], 0.0);
    for theta in [[2.0, 0.7, 0.5], [-1.3, 0.1, 4.0], [0.0, 2.0, 0.0]] {
        let analytic = problem.jacobian(&theta).unwrap();
        let fd = fd_jacobian(&problem, &theta, 1e-6).unwrap();
        for i in 0..analytic.nrows() {
            for j in 0..analytic.ncols() {
                assert!(
                    (analytic[(i, j)] - fd[(i, j)]).abs() < 1e-7,
                    "{theta:?} ({i},{j}): {} vs {}",
                    analytic[(i, j)],
                    fd[(i, j)]
                );
            }
        }
    }
    let analytic = Rosenbrock.jacobian(&[-1.2, 1.0]).unwrap();
    let fd = fd_jacobian(&Rosenbrock, &[-1.2, 1.0], 1e-6).unwrap();
    for i in 0..2 {
        for j in 0..2 {
            assert!((analytic[(i, j)] - fd[(i, j)]).abs() < 1e-7);
        }
    }
}

#[test]
fn fd_jacobian_uses_one_sided_differences_at_a_wall() {
    // At x = 1 the forward point is NaN; the backward difference still gives the slope 1.
    let j = fd_jacobian(&NanWall, &[1.0], 1e-6).unwrap();
    assert!((j[(0, 0)] - 1.0).abs() < 1e-9, "{}", j[(0, 0)]);
    assert!(matches!(
        fd_jacobian(&NanWall, &[1.0], 0.0),
        Err(SolverError::InvalidOption {
            option: "rel_step",
            ..
        })
    ));
}

#[test]
fn transformed_jacobian_obeys_the_chain_rule() {
    let problem = Exponential::new([2.0, 0.7, 0.5], 0.0);
    let transformed = Transformed::new(
        &problem,
        vec![
            Transform::Positive,
            Transform::Bounded { lo: 0.1, hi: 3.0 },
            Transform::Negative,
        ],
    )
    .unwrap();
    let phi = transformed.to_internal(&[1.7, 0.4, -0.3]).unwrap();
    let analytic = transformed.jacobian(&phi).unwrap();
    let fd = fd_jacobian(&transformed, &phi, 1e-6).unwrap();
    for i in 0..analytic.nrows() {
        for j in 0..analytic.ncols() {
            assert!(
                (analytic[(i, j)] - fd[(i, j)]).abs() < 1e-7,
                "({i},{j}): {} vs {}",
                analytic[(i, j)],
                fd[(i, j)]
            );
        }
    }
    // The residuals are those of the external parameters.
    let external = transformed.to_external(&phi).unwrap();
    assert!(max_abs_diff(&external, &[1.7, 0.4, -0.3]) < 1e-14);
    assert_eq!(
        transformed.residuals(&phi).unwrap(),
        problem.residuals(&external).unwrap()
    );
}

#[test]
fn transformed_fit_respects_constraints() {
    let truth = [2.0, 0.7, 0.5];
    let problem = Exponential::new(truth, 0.0);
    let transformed = Transformed::new(
        &problem,
        vec![
            Transform::Positive,
            Transform::Bounded { lo: 0.0, hi: 5.0 },
            Transform::Free,
        ],
    )
    .unwrap();
    let report = transformed
        .minimize(&LevenbergMarquardt::default(), &[1.0, 1.05, 0.25])
        .unwrap();
    assert!(report.converged, "{report:?}");
    assert!(max_abs_diff(&report.params, &truth) < 1e-8, "{report:?}");
}

#[test]
fn start_outside_a_constraint_is_a_typed_error() {
    let problem = Exponential::new([2.0, 0.7, 0.5], 0.0);
    let transformed = Transformed::new(
        &problem,
        vec![
            Transform::Free,
            Transform::Positive,
            Transform::Bounded { lo: 0.0, hi: 1.0 },
        ],
    )
    .unwrap();
    let err = transformed
        .minimize(&LevenbergMarquardt::default(), &[1.0, -0.7, 0.5])
        .unwrap_err();
    assert_eq!(
        err,
        SolverError::OutsideConstraint {
            index: 1,
            value: -0.7,
            constraint: Transform::Positive
        }
    );
    assert!(err.to_string().contains("θ > 0"), "{err}");
    // Zero is outside `Positive` too, and a bound itself is outside `Bounded`.
    assert!(matches!(
        transformed.to_internal(&[1.0, 0.0, 0.5]),
        Err(SolverError::OutsideConstraint { index: 1, .. })
    ));
    assert!(matches!(
        transformed.to_internal(&[1.0, 0.7, 1.0]),
        Err(SolverError::OutsideConstraint { index: 2, .. })
    ));
    assert!(matches!(
        Transformed::new(&problem, vec![Transform::Free; 2]),
        Err(SolverError::WrongTransformCount {
            expected: 3,
            got: 2
        })
    ));
    assert!(matches!(
        Transformed::new(
            &problem,
            vec![
                Transform::Free,
                Transform::Free,
                Transform::Bounded { lo: 1.0, hi: 1.0 }
            ]
        ),
        Err(SolverError::InvalidBounds { index: 2, .. })
    ));
}

#[test]
fn nan_start_is_a_typed_error_for_every_solver() {
    let start = [-1.2, f64::NAN];
    let expect = |r: Result<SolverReport, SolverError>| match r {
        Err(SolverError::NonFiniteStart { index: 1, value }) => assert!(value.is_nan()),
        other => panic!("expected NonFiniteStart, got {other:?}"),
    };
    expect(LevenbergMarquardt::default().minimize(&Rosenbrock, &start));
    expect(GaussNewtonLineSearch::default().minimize(&Rosenbrock, &start));
    expect(NelderMead::default().minimize(&Rosenbrock, &start));
    expect(MultiStart::new(LevenbergMarquardt::default(), 3, 0.1, 1).minimize(&Rosenbrock, &start));
}

#[test]
fn invalid_problems_and_starts_are_typed_errors() {
    let lm = LevenbergMarquardt::default();
    assert_eq!(
        lm.minimize(&Rosenbrock, &[1.0]).unwrap_err(),
        SolverError::WrongStartLength {
            expected: 2,
            got: 1
        }
    );
    assert_eq!(
        lm.minimize(&Underdetermined, &[1.0, 2.0]).unwrap_err(),
        SolverError::TooFewResiduals {
            residuals: 1,
            params: 2
        }
    );
    assert!(matches!(
        lm.minimize(&NanWall, &[2.0]),
        Err(SolverError::NonFiniteResidual { index: 0, .. })
    ));
    for solver_result in [
        lm.minimize(&WrongLength, &[1.0]),
        GaussNewtonLineSearch::default().minimize(&WrongLength, &[1.0]),
        NelderMead::default().minimize(&WrongLength, &[1.0]),
    ] {
        assert_eq!(
            solver_result.unwrap_err(),
            SolverError::ResidualLength {
                expected: 3,
                got: 2
            }
        );
    }
    for solver_result in [
        lm.minimize(&WrongShape, &[0.0, 0.0]),
        GaussNewtonLineSearch::default().minimize(&WrongShape, &[0.0, 0.0]),
    ] {
        assert!(
            matches!(
                solver_result,
                Err(SolverError::JacobianShape {
                    expected_rows: 2,
                    expected_cols: 2,
                    rows: 2,
                    cols: 1
                })
            ),
            "{solver_result:?}"
        );
    }
    assert!(matches!(
        lm.clone()
            .with_initial_lambda(0.0)
            .minimize(&Rosenbrock, &[0.0, 0.0]),
        Err(SolverError::InvalidOption {
            option: "initial_lambda",
            ..
        })
    ));
    assert!(matches!(
        MultiStart::new(lm, 2, f64::NAN, 0).minimize(&Rosenbrock, &[0.0, 0.0]),
        Err(SolverError::InvalidOption {
            option: "radius",
            ..
        })
    ));
}

#[test]
fn nan_region_ends_with_a_clear_reason() {
    let lm = LevenbergMarquardt::default()
        .minimize(&NanWall, &[0.0])
        .unwrap();
    assert_sane(&lm);
    assert!(!lm.converged, "{lm:?}");
    assert_eq!(lm.termination, Termination::NonFinite, "{lm:?}");
    assert!(lm.params[0] <= 1.0 && lm.params[0] > 0.99, "{lm:?}");

    let gn = GaussNewtonLineSearch::default()
        .minimize(&NanWall, &[0.0])
        .unwrap();
    assert_sane(&gn);
    assert!(!gn.converged, "{gn:?}");
    assert!(gn.params[0] <= 1.0, "{gn:?}");

    // For Nelder–Mead the wall is an infinite cost: it ends at the wall with a finite cost.
    let nm = NelderMead::default().minimize(&NanWall, &[0.0]).unwrap();
    assert_sane(&nm);
    assert!(nm.params[0] <= 1.0 && nm.params[0] > 0.99, "{nm:?}");
}

#[test]
fn iteration_limit_is_reported() {
    let report = LevenbergMarquardt::default()
        .with_max_iters(2)
        .minimize(&Rosenbrock, &[-1.2, 1.0])
        .unwrap();
    assert_eq!(report.termination, Termination::MaxIterations);
    assert!(!report.converged);
    assert_eq!(report.iterations, 2);
    assert_sane(&report);

    let report = GaussNewtonLineSearch {
        max_iters: 1,
        ..Default::default()
    }
    .minimize(&Exponential::new([2.0, 0.7, 0.5], 0.0), &[3.0, 1.05, 0.75])
    .unwrap();
    assert_eq!(report.termination, Termination::MaxIterations);
    assert!(!report.converged);
}

#[test]
fn exact_start_converges_immediately() {
    for report in [
        LevenbergMarquardt::default().minimize(&Rosenbrock, &[1.0, 1.0]),
        GaussNewtonLineSearch::default().minimize(&Rosenbrock, &[1.0, 1.0]),
        NelderMead::default().minimize(&Rosenbrock, &[1.0, 1.0]),
    ] {
        let report = report.unwrap();
        assert!(report.converged, "{report:?}");
        assert_eq!(report.termination, Termination::SmallGradient);
        assert_eq!(report.iterations, 0);
        assert_eq!(report.params, vec![1.0, 1.0]);
    }
}

#[test]
fn multistart_escapes_a_local_minimum() {
    let problem = Sinusoid::new(1.5, 2.0);
    let start = [1.0, 1.3];
    let single = LevenbergMarquardt::default()
        .minimize(&problem, &start)
        .unwrap();
    assert!(
        single.cost > 1.0,
        "the single start must be trapped for this test to mean anything: {single:?}"
    );
    let multi = MultiStart::new(LevenbergMarquardt::default(), 30, 0.6, 11)
        .minimize(&problem, &start)
        .unwrap();
    assert!(multi.converged, "{multi:?}");
    assert!(multi.cost < 1e-20, "{multi:?}");
    assert!(max_abs_diff(&multi.params, &[1.5, 2.0]) < 1e-9, "{multi:?}");
    assert!(multi.iterations > single.iterations);
}

#[test]
fn multistart_is_deterministic_for_a_seed() {
    let problem = Sinusoid::new(1.5, 2.0);
    let start = [1.0, 1.3];
    let run = |seed| {
        MultiStart::new(LevenbergMarquardt::default(), 8, 0.6, seed)
            .minimize(&problem, &start)
            .unwrap()
    };
    assert_eq!(run(3), run(3));
    assert_eq!(run(4), run(4));
    let nm = MultiStart::new(NelderMead::default(), 4, 0.3, 5);
    assert_eq!(
        nm.minimize(&Rosenbrock, &[-1.2, 1.0]).unwrap(),
        nm.minimize(&Rosenbrock, &[-1.2, 1.0]).unwrap()
    );
}

/// The second parameter has no influence: `JᵀJ` is singular.
struct Inert;

impl LeastSquares for Inert {
    fn num_params(&self) -> usize {
        2
    }
    fn num_residuals(&self) -> usize {
        2
    }
    fn residuals(&self, p: &[f64]) -> Result<Vec<f64>, SolverError> {
        Ok(vec![p[0] - 1.0, 2.0 * (p[0] - 1.0)])
    }
    fn jacobian(&self, _p: &[f64]) -> Result<Mat<f64>, SolverError> {
        Ok(Mat::from_fn(2, 2, |r, c| {
            if c == 0 {
                1.0 + r as f64
            } else {
                0.0
            }
        }))
    }
}

#[test]
fn singular_normal_equations_do_not_panic() {
    let lm = LevenbergMarquardt::default()
        .minimize(&Inert, &[3.0, 5.0])
        .unwrap();
    assert!(lm.converged, "{lm:?}");
    assert!((lm.params[0] - 1.0).abs() < 1e-10, "{lm:?}");
    assert_eq!(lm.params[1], 5.0, "an inert parameter stays put: {lm:?}");

    // argmin's Gauss–Newton inverts JᵀJ: it stops at the start with a reason, not a panic.
    let gn = GaussNewtonLineSearch::default()
        .minimize(&Inert, &[3.0, 5.0])
        .unwrap();
    assert_sane(&gn);
    assert!(!gn.converged, "{gn:?}");
    assert!(matches!(gn.termination, Termination::Other(_)), "{gn:?}");
    assert_eq!(gn.params, vec![3.0, 5.0]);
}

#[test]
fn solvers_accept_trait_objects_and_extreme_options() {
    let problem: &dyn LeastSquares = &Rosenbrock;
    let report = LevenbergMarquardt::default()
        .minimize(problem, &[-1.2, 1.0])
        .unwrap();
    assert!(report.converged);
    // A huge radius gives absurd starts, but no panic; the unperturbed run still counts.
    let report = MultiStart::new(LevenbergMarquardt::default(), 3, 1e308, 0)
        .minimize(problem, &[-1.2, 1.0])
        .unwrap();
    assert!(report.converged, "{report:?}");
}
