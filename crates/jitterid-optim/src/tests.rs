//! Unit tests of the optimisation layer's internals and argmin adapters.

use super::lm::{LevenbergMarquardt, LmState};
use super::problem::{half_sum_sq, Scaled};
use super::*;
use argmin::core::{
    CostFunction, Executor, Gradient, Jacobian, Operator, State, TerminationReason,
    TerminationStatus,
};
use faer::Mat;

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
    fn jacobian(&self, p: &[f64]) -> Result<Mat<f64>, SolverError> {
        let j = [[-20.0 * p[0], 10.0], [-1.0, 0.0]];
        Ok(Mat::from_fn(2, 2, |r, c| j[r][c]))
    }
}

#[test]
fn transforms_round_trip_and_differentiate() {
    let cases = [
        (Transform::Free, -3.25),
        (Transform::Positive, 0.02),
        (Transform::Negative, -7.5),
        (Transform::Bounded { lo: -1.0, hi: 4.0 }, 3.999),
        (Transform::Bounded { lo: -1.0, hi: 4.0 }, -0.999),
    ];
    for (t, theta) in cases {
        let phi = t.to_internal(theta).unwrap();
        assert!(
            (t.to_external(phi) - theta).abs() <= 1e-13 * theta.abs().max(1.0),
            "{t:?}"
        );
        let h = 1e-6;
        let fd = (t.to_external(phi + h) - t.to_external(phi - h)) / (2.0 * h);
        assert!(
            (fd - t.derivative(phi)).abs() < 1e-8,
            "{t:?}: {fd} vs {}",
            t.derivative(phi)
        );
    }
}

#[test]
fn bounded_transform_saturates_without_overflow() {
    let t = Transform::Bounded { lo: 1.0, hi: 2.0 };
    for phi in [-1e4, -800.0, 800.0, 1e4] {
        let theta = t.to_external(phi);
        assert!((1.0..=2.0).contains(&theta), "{phi}: {theta}");
        let d = t.derivative(phi);
        assert!(d.is_finite() && d >= 0.0, "{phi}: {d}");
    }
    assert_eq!(t.to_internal(1.0), None);
    assert_eq!(t.to_internal(f64::NAN), None);
    assert_eq!(Transform::Positive.to_internal(f64::INFINITY), None);
    assert!(!Transform::Bounded {
        lo: 0.0,
        hi: f64::INFINITY
    }
    .is_valid());
}

#[test]
fn argmin_adapter_matches_the_problem() {
    let a = ArgminProblem::new(&Rosenbrock);
    let x = vec![-1.2, 1.0];
    let r = a.apply(&x).unwrap();
    assert_eq!(r, Rosenbrock.residuals(&x).unwrap());
    assert_eq!(a.cost(&x).unwrap(), half_sum_sq(&r));
    let j = Jacobian::jacobian(&a, &x).unwrap();
    let g = a.gradient(&x).unwrap();
    for (k, gk) in g.iter().enumerate() {
        let expect = j[(0, k)] * r[0] + j[(1, k)] * r[1];
        assert_eq!(*gk, expect);
    }
    // A wrong parameter length is an error that comes back out as a `SolverError`.
    let err = a.apply(&vec![1.0]).unwrap_err();
    assert_eq!(
        SolverError::from_argmin(err),
        SolverError::WrongStartLength {
            expected: 2,
            got: 1
        }
    );
    let f = ArgminFaerProblem::new(&Rosenbrock);
    let xc = Mat::from_fn(2, 1, |i, _| x[i]);
    let gc = f.gradient(&xc).unwrap();
    assert_eq!((gc.nrows(), gc.ncols()), (2, 1));
    assert_eq!((gc[(0, 0)], gc[(1, 0)]), (g[0], g[1]));
    assert_eq!(f.cost(&xc).unwrap(), half_sum_sq(&r));
    assert!(f.apply(&Mat::zeros(2, 2)).is_err());
}

#[test]
fn argmin_solvers_run_on_the_adapter() {
    use argmin::solver::linesearch::MoreThuenteLineSearch;
    use argmin::solver::quasinewton::LBFGS;
    let solver = LBFGS::new(MoreThuenteLineSearch::new(), 5);
    let result = Executor::new(ArgminProblem::new(&Rosenbrock), solver)
        .configure(|s| s.param(vec![-1.2, 1.0]).max_iters(200))
        .run()
        .unwrap();
    let best = result.state.get_best_param().unwrap();
    assert!(
        (best[0] - 1.0).abs() < 1e-5 && (best[1] - 1.0).abs() < 1e-5,
        "{best:?}"
    );
}

#[test]
fn lm_as_argmin_solver_reports_through_termination_status() {
    let result = Executor::new(
        ArgminProblem::new(&Rosenbrock),
        LevenbergMarquardt::default(),
    )
    .configure(|s: LmState| s.param(vec![-1.2, 1.0]))
    .run()
    .unwrap();
    assert_eq!(
        result.state.termination_status,
        TerminationStatus::Terminated(TerminationReason::SolverConverged)
    );
    assert_eq!(result.solver.termination(), Some(&Termination::SmallStep));
    assert!(result.solver.lambda() > 0.0);
    let state = &result.state;
    // Rosenbrock's last iteration stops on a small step without an accepted one, and the
    // residuals were released while the rejected trial point was evaluated.
    assert!(state.get_residuals().is_none());
    // The state carries the gradient; the Jacobian is never stored (memory flat in `m`).
    assert!(state.get_jacobian().is_none() && state.get_gradient().is_some());
    let evaluations = result.problem.counts.get("normal_equations_count").copied();
    assert!(evaluations.is_some_and(|c| c >= 1 && c <= result.state.get_iter() + 1));

    // Without a start, `init` fails with a typed error rather than panicking.
    let run = Executor::new(
        ArgminProblem::new(&Rosenbrock),
        LevenbergMarquardt::default(),
    )
    .run();
    let Err(err) = run else {
        panic!("ran without a start")
    };
    assert_eq!(SolverError::from_argmin(err), SolverError::MissingStart);

    // The executor's own iteration limit is honoured as well as the solver's option.
    let result = Executor::new(
        ArgminProblem::new(&Rosenbrock),
        LevenbergMarquardt::default(),
    )
    .configure(|s: LmState| s.param(vec![-1.2, 1.0]).max_iters(3))
    .run()
    .unwrap();
    assert_eq!(result.state.get_iter(), 3);
    assert_eq!(
        result.state.termination_status,
        TerminationStatus::Terminated(TerminationReason::MaxItersReached)
    );
}

#[test]
fn scaling_residuals_keeps_the_minimiser() {
    let scaled = Scaled {
        problem: &Rosenbrock,
        scale: 1e-3,
    };
    let report = LevenbergMarquardt::default()
        .minimize(&scaled, &[-1.2, 1.0])
        .unwrap();
    assert!(report.converged, "{report:?}");
    assert!((report.params[0] - 1.0).abs() < 1e-10 && (report.params[1] - 1.0).abs() < 1e-10);
}

#[test]
fn termination_reasons_classify() {
    assert!(Termination::SmallStep.is_convergence());
    assert!(Termination::SmallCostChange.is_convergence());
    assert!(Termination::SmallGradient.is_convergence());
    for t in [
        Termination::MaxIterations,
        Termination::NonFinite,
        Termination::LineSearchFailed,
        Termination::Other("x".into()),
    ] {
        assert!(!t.is_convergence(), "{t}");
        assert!(!t.to_string().is_empty());
    }
}

fn registry_solver(table: serde_json::Value) -> AnySolver {
    SolverRegistry::builtin()
        .build(table.as_object().expect("a table"))
        .expect("a valid solver table")
}

#[test]
fn solver_registry_budget_keys_reach_the_solver() {
    // The registry's defaults are the types' defaults: the same run, to the bit.
    let by_name = registry_solver(serde_json::json!({ "solver": "lm" }));
    let by_hand = LevenbergMarquardt::default();
    let start = [-1.2, 1.0];
    assert_eq!(
        Solver::minimize(&by_name, &Rosenbrock, &start).unwrap(),
        Solver::minimize(&by_hand, &Rosenbrock, &start).unwrap()
    );
    // An iteration limit of 3 stops Levenberg–Marquardt on Rosenbrock (it needs about 20).
    let short = registry_solver(serde_json::json!({ "solver": "lm", "max_iters": 3 }));
    let report = Solver::minimize(&short, &Rosenbrock, &start).unwrap();
    assert_eq!(report.termination, Termination::MaxIterations);
    assert_eq!(report.iterations, 3);
    // No time at all: the first iteration boundary ends the run.
    for name in ["lm", "bfgs"] {
        let none = registry_solver(serde_json::json!({ "solver": name, "max_seconds": 0.0 }));
        let report = Solver::minimize(&none, &Rosenbrock, &start).unwrap();
        assert_eq!(report.termination, Termination::TimeLimit, "{name}");
    }
    for bad in [-1.0, f64::MAX * 2.0] {
        let table = serde_json::json!({ "solver": "lm", "max_seconds": bad });
        let err = SolverRegistry::builtin()
            .build(table.as_object().unwrap())
            .unwrap_err();
        assert_eq!(err.key(), Some("max_seconds"), "{bad}");
    }
}

#[test]
fn solver_registry_reads_a_multistart_seed_above_2_pow_53_exactly() {
    let seed = u64::MAX - 1;
    let by_name = registry_solver(
        serde_json::json!({ "solver": "lm", "starts": 4, "radius": 0.5, "seed": seed }),
    );
    let start = [-1.2, 1.0];
    let exact = MultiStart::new(LevenbergMarquardt::default(), 4, 0.5, seed);
    assert_eq!(
        Solver::minimize(&by_name, &Rosenbrock, &start).unwrap(),
        Solver::minimize(&exact, &Rosenbrock, &start).unwrap()
    );
}

#[test]
fn solver_progress_hook_goes_through_the_trait_and_the_multistart_wrapper() {
    use std::sync::atomic::{AtomicU64, Ordering};
    use std::sync::Arc;
    let start = [-1.2, 1.0];
    for table in [
        serde_json::json!({ "solver": "lm" }),
        serde_json::json!({ "solver": "lm", "starts": 2 }),
        serde_json::json!({ "solver": "bfgs" }),
    ] {
        let calls = Arc::new(AtomicU64::new(0));
        let seen = Arc::clone(&calls);
        let hook = ProgressHook::new(move |_| {
            seen.fetch_add(1, Ordering::Relaxed);
        });
        let plain = registry_solver(table.clone());
        assert!(plain.reports_progress(), "{table}");
        let hooked = plain.with_progress(hook);
        let report = Solver::minimize(&hooked, &Rosenbrock, &start).unwrap();
        // One report after the start's evaluation and one per iteration, for every run.
        assert!(calls.load(Ordering::Relaxed) > report.iterations, "{table}");
        // The hook only watches: the run is the one without it.
        assert_eq!(
            report,
            Solver::minimize(&plain, &Rosenbrock, &start).unwrap(),
            "{table}"
        );
    }
    // A solver without progress reports is returned unchanged.
    let gn = registry_solver(serde_json::json!({ "solver": "gauss-newton" }));
    assert!(!gn.reports_progress());
    assert_eq!(
        gn.with_progress(ProgressHook::new(|_| {})).name(),
        "gauss-newton"
    );
}

#[test]
fn a_cancelled_budget_ends_the_run_where_it_is() {
    use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
    use std::sync::Arc;
    let start = [-1.2, 1.0];
    for table in [
        serde_json::json!({ "solver": "lm" }),
        serde_json::json!({ "solver": "lm", "starts": 2 }),
        serde_json::json!({ "solver": "bfgs" }),
    ] {
        // The flag is set by the third report (the end of iteration 2), as a front end's
        // Ctrl-C would set it while the solver runs under the budget that carries it.
        let stop = Arc::new(AtomicBool::new(false));
        let reports = Arc::new(AtomicU64::new(0));
        let (flag, seen) = (Arc::clone(&stop), Arc::clone(&reports));
        let hook = ProgressHook::new(move |_| {
            if seen.fetch_add(1, Ordering::Relaxed) == 2 {
                flag.store(true, Ordering::Relaxed);
            }
        });
        let budget = jitterid_numeric::budget::Budget::new(None, Some(Arc::clone(&stop)));
        let plain = registry_solver(table.clone());
        let watched = plain.with_progress(hook);
        let report = budget
            .run(|| Solver::minimize(&watched, &Rosenbrock, &start))
            .unwrap();
        assert_eq!(report.termination, Termination::Stopped, "{table}");
        assert!(!report.converged, "{table}");
        assert!(report.iterations <= 2, "{table}: {report:?}");
        // Unstopped, the same solver runs on to Rosenbrock's minimum.
        let whole = Solver::minimize(&plain, &Rosenbrock, &start).unwrap();
        assert!(
            whole.converged && whole.iterations > 2,
            "{table}: {whole:?}"
        );
    }
}
