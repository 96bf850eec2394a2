//! Bounded work: every fit has an iteration and a wall-clock budget and says where it stopped,
//! degenerate data end quickly with a reason, and progress reaches the observer hook. No test
//! here compares durations: a zero budget must end the run at once, whatever the machine.

use jitterid_estimate::solver::Bfgs;
use jitterid_estimate::solver::{
    LeastSquares, LevenbergMarquardt, LmOptions, Progress, ProgressHook, Solver, SolverError,
    Termination,
};
use jitterid_estimate::{fit, Bcls, EstimateError, FitOptions, ModelStructure, Record};
use jitterid_jitter::UniformSum;
use jitterid_signal::{LtiResponse, RandomBinary, Root, SampleGrid, Zpk};
use rand::SeedableRng;
use std::sync::{Arc, Mutex};

/// Rosenbrock's function as residuals `[10(y − x²), 1 − x]`.
struct Rosenbrock;

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
}

#[test]
fn a_spent_time_budget_stops_least_squares_with_its_reason() {
    let report = LevenbergMarquardt::default()
        .with_max_seconds(0.0)
        .minimize(&Rosenbrock, &[-1.2, 1.0])
        .expect("runs");
    assert_eq!(report.termination, Termination::TimeLimit);
    assert!(!report.converged);
    assert_eq!(report.iterations, 0);
    // The start's cost, finite: the run ended where it stood.
    assert!((report.cost - 0.5 * (4.4f64.powi(2) + 2.2f64.powi(2))).abs() < 1e-12);
    // The same through `estimate`.
    let (structure, record) = table2_like(200);
    let fit = fit(
        &structure,
        &record,
        &Bcls,
        &FitOptions::default().with_solver(LevenbergMarquardt::default().with_max_seconds(0.0)),
    )
    .expect("fit runs");
    assert_eq!(fit.termination, Termination::TimeLimit);
    assert!(!fit.converged);
}

#[test]
fn budgets_are_validated_and_default_to_finite_values() {
    assert!(LmOptions::default().max_seconds.is_finite());
    assert!(Bfgs::default().max_seconds.is_finite());
    assert!(matches!(
        LevenbergMarquardt::default()
            .with_max_seconds(f64::NAN)
            .minimize(&Rosenbrock, &[0.0, 0.0]),
        Err(SolverError::InvalidOption {
            option: "max_seconds",
            ..
        })
    ));
    // Options written before the budget existed still read, with the default budget.
    let old = r#"{"max_iters":5,"xtol":1e-10,"ftol":1e-12,"gtol":1e-10,"initial_lambda":0.001,"scaling":"Marquardt"}"#;
    let options: LmOptions = serde_json::from_str(old).expect("reads");
    assert_eq!(options.max_seconds, LmOptions::default().max_seconds);
}

#[test]
fn a_spent_time_budget_stops_maximum_likelihood_with_its_reason() {
    struct Quadratic;
    impl jitterid_estimate::Objective for Quadratic {
        fn num_params(&self) -> usize {
            2
        }
        fn cost(&self, p: &[f64]) -> f64 {
            p[0] * p[0] + 10.0 * p[1] * p[1]
        }
    }
    let report = Bfgs {
        max_seconds: 0.0,
        ..Bfgs::default()
    }
    .minimize(&Quadratic, &[1.0, 1.0])
    .expect("runs");
    assert_eq!(report.termination, Termination::TimeLimit);
    assert_eq!(report.iterations, 0);
}

#[test]
fn progress_reaches_the_hook_once_per_iteration() {
    let seen: Arc<Mutex<Vec<Progress>>> = Arc::default();
    let sink = seen.clone();
    let report = LevenbergMarquardt::default()
        .with_progress(ProgressHook::new(move |p| {
            sink.lock().expect("not poisoned").push(*p);
        }))
        .minimize(&Rosenbrock, &[-1.2, 1.0])
        .expect("runs");
    assert!(report.converged);
    let seen = seen.lock().expect("not poisoned");
    // The start, then one report per iteration, numbered in order, with non-increasing cost
    // (every iteration is an accepted step) ending at the reported cost.
    assert_eq!(seen.len() as u64, report.iterations + 1);
    assert!(seen
        .iter()
        .enumerate()
        .all(|(i, p)| p.iteration == i as u64));
    assert!(seen.windows(2).all(|w| w[1].cost <= w[0].cost));
    assert_eq!(seen.last().map(|p| p.cost), Some(report.cost));
}

fn eq17(k: f64, z: f64, re: f64, im: f64) -> Zpk {
    Zpk::new(k, vec![Root::Real(-z)], vec![Root::Pair { re, im }]).expect("valid")
}

/// An OE structure of the Table 2 system started off the truth, and an all-zero record.
fn table2_like(n: usize) -> (ModelStructure<LtiResponse<Zpk>, UniformSum>, Record) {
    let mut rng = rand::rngs::StdRng::seed_from_u64(11);
    let u = RandomBinary::paper()
        .generate(0.0, n as f64 + 1.0, &mut rng)
        .expect("input");
    let grid = SampleGrid::new(0.0, 1.0, n).expect("grid");
    let jitter = UniformSum::new(2, 0.5 / 3f64.sqrt()).expect("jitter");
    let structure = ModelStructure::oe(LtiResponse::new(eq17(0.21, 0.45, -0.27, 0.33), u), jitter);
    (structure, Record::new(grid, vec![0.0; n]).expect("record"))
}

#[test]
fn all_zero_data_end_quickly_with_a_reason() {
    // The best model of all-zero data has gain 0, where the other parameters are not
    // determined: the fit must still end by one of its tests, well inside the iteration budget,
    // with the gain driven to (almost) 0.
    let (structure, record) = table2_like(200);
    let fit = fit(&structure, &record, &Bcls, &FitOptions::default()).expect("runs");
    assert!(fit.iterations < LmOptions::default().max_iters, "{fit:?}");
    assert_ne!(fit.termination, Termination::TimeLimit);
    assert!(fit.params[0].abs() < 1e-6, "gain {}", fit.params[0]);
}

#[test]
fn maximum_likelihood_refuses_constant_data_before_searching() {
    use jitterid_likelihood::ExactMl;
    let (mut structure, record) = table2_like(64);
    structure.noise_std = Some(0.05);
    let err = fit(
        &structure,
        &record,
        &ExactMl::default(),
        &FitOptions::default().with_covariance(false),
    )
    .expect_err("constant data");
    assert!(
        matches!(err, EstimateError::ConstantData { value } if value == 0.0),
        "{err:?}"
    );
}
