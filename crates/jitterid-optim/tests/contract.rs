//! Every shipped solver keeps the [`Solver`] contract of `jitterid_optim::testing`.

use jitterid_optim::testing::{check_solver, check_solver_on, Valley};
use jitterid_optim::{
    AnySolver, Bfgs, Brent, BrentOrBfgs, GaussNewtonLineSearch, LevenbergMarquardt, MultiStart,
    NelderMead, SolverRegistry,
};

#[test]
fn least_squares_solvers_keep_the_contract() {
    check_solver(&LevenbergMarquardt::default(), &[1, 2, 4], 1e-6).unwrap();
    check_solver(&GaussNewtonLineSearch::default(), &[1, 2, 4], 1e-6).unwrap();
}

#[test]
fn objective_solvers_keep_the_contract() {
    check_solver(&Bfgs::default(), &[1, 2, 3], 1e-4).unwrap();
    check_solver(&BrentOrBfgs::default(), &[1, 2, 3], 1e-4).unwrap();
    check_solver(&NelderMead::default(), &[1, 2], 1e-3).unwrap();
    // Brent's method is for one parameter.
    check_solver(&Brent::default(), &[1], 1e-6).unwrap();
}

#[test]
fn multistart_keeps_the_contract() {
    let ms = MultiStart::new(LevenbergMarquardt::default(), 3, 0.5, 7);
    check_solver(&ms, &[1, 2], 1e-6).unwrap();
}

#[test]
fn every_registry_solver_keeps_the_contract() {
    let registry = SolverRegistry::builtin();
    for entry in registry.entries() {
        let table = serde_json::json!({ "solver": entry.name });
        let solver: AnySolver = registry.build(table.as_object().unwrap()).unwrap();
        let dims: &[usize] = if entry.name == "brent" { &[1] } else { &[1, 2] };
        for &n in dims {
            let problem = Valley::new(n);
            check_solver_on(&solver, &problem, &problem.start(), None)
                .unwrap_or_else(|e| panic!("{} ({n} parameters): {e}", entry.name));
        }
    }
}
