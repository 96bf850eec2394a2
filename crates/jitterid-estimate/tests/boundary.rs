//! Estimates on the boundary of a parameter's domain are answers: the Table 2 setup with a
//! Gaussian jitter whose width is estimated (JOE, BCLS) drives `σ` to 0 on some records (the
//! data show no detectable jitter there). Those fits once ended "NOT converged (residuals or
//! Jacobian not finite at every nearby trial point)" with `σ ≈ 2e-11`, or spent the iteration
//! limit with the width bouncing between `σ/4` and `2σ` (Gauss–Newton's model of a width is too
//! flat near 0; the search's matrix now has the width's curvature, `even_widths`).

use jitterid_estimate::montecarlo::realization_rng;
use jitterid_estimate::solver::{
    LeastSquares, LevenbergMarquardt, Solver, SolverReport, Termination,
};
use jitterid_estimate::{
    fit, Bcls, Fit as Estimate, FitOptions, FitProblem, FrequencyData, ModelStructure, Record,
};
use jitterid_jitter::Gaussian;
use jitterid_signal::{simulate, LtiResponse, RandomBinary, Root, SampleGrid, Zpk};
use jitterid_window::{DirichletWindow, FrequencySet};
use rand::rngs::StdRng;
use rand::Rng;

const TRUTH: [f64; 5] = [0.2, 0.5, -0.25, 0.3, 0.096_225_044_864_937_63];

fn eq17(k: f64, z: f64, re: f64, im: f64) -> Option<Zpk> {
    Zpk::new(k, vec![Root::Real(-z)], vec![Root::Pair { re, im }]).ok()
}

/// Realisation `r` of the study (seed 20051205): the Table 2 record with Gaussian jitter of the
/// Table 2 width (σ = 1/(6√3)), and the JOE structure started at the truth × (1 + U(−0.2, 0.2)).
fn setup(r: u64) -> (ModelStructure<LtiResponse<Zpk>, Gaussian>, Record) {
    let mut rng: StdRng = realization_rng(20_051_205, r);
    let u = RandomBinary::new(8.0, 0.0, 1.0)
        .and_then(|b| b.generate(0.0, 201.0, &mut rng))
        .expect("input");
    let grid = SampleGrid::new(0.0, 1.0, 200).expect("grid");
    let [k, z, re, im, sigma] = TRUTH;
    let truth = LtiResponse::new(eq17(k, z, re, im).expect("stable"), u.clone());
    let jitter = Gaussian::new(sigma).expect("jitter");
    let y = simulate(&truth, &jitter, &grid, 0.01, &mut rng)
        .expect("simulate")
        .y;
    let s: Vec<f64> = TRUTH
        .iter()
        .map(|x| x * (1.0 + rng.random_range(-0.2..=0.2)))
        .collect();
    let start = eq17(s[0], s[1], s[2], s[3]).expect("stable start");
    let structure = ModelStructure::joe(
        LtiResponse::new(start, u),
        Gaussian::new(s[4]).expect("width"),
    );
    (structure, Record::new(grid, y).expect("record"))
}

/// Record `r`'s structure, its data on the DFT grid, and where the plain solver
/// (Levenberg–Marquardt without the estimator's handling of the bound) stops from the start.
fn plain_search(
    r: u64,
) -> (
    ModelStructure<LtiResponse<Zpk>, Gaussian>,
    FrequencyData<DirichletWindow>,
    SolverReport,
) {
    let (structure, record) = setup(r);
    let grid = *record.grid();
    let data = FrequencyData::new(record, DirichletWindow, FrequencySet::dft(&grid)).expect("data");
    let stalled = LevenbergMarquardt::default()
        .minimize(
            &FitProblem::new(&structure, &Bcls, &data),
            &structure.params(),
        )
        .expect("runs");
    (structure, data, stalled)
}

fn fit_realisation(r: u64) -> Estimate {
    let (structure, record) = setup(r);
    fit(&structure, &record, &Bcls, &FitOptions::default()).expect("fit runs")
}

/// Prints every realisation's termination, iterations and cost with Levenberg–Marquardt's
/// default (adaptive) model and with Gauss–Newton's (`cargo test -p jitterid-estimate --test
/// boundary -- --ignored --nocapture`): how the regression records below were found, and the
/// iteration counts in `docs/method.md`.
#[test]
#[ignore = "a scan over 128 records that prints, for finding regression records"]
fn scan_terminations() {
    use jitterid_estimate::solver::LmModel;
    let mut iterations = [Vec::new(), Vec::new()];
    for r in 0..128 {
        let (structure, record) = setup(r);
        for (k, model) in [LmModel::Adaptive, LmModel::GaussNewton]
            .into_iter()
            .enumerate()
        {
            let clock = std::time::Instant::now();
            let options =
                FitOptions::default().with_solver(LevenbergMarquardt::default().with_model(model));
            let e = fit(&structure, &record, &Bcls, &options).expect("fit runs");
            iterations[k].push(e.iterations);
            println!(
                "{r:3} {model:?}: converged {} after {} iterations, V = {:.10e}, σ̂ = {:.3e} ({}) {:.3} s",
                e.converged,
                e.iterations,
                e.cost,
                e.params[4],
                e.termination,
                clock.elapsed().as_secs_f64()
            );
        }
    }
    for (k, name) in ["adaptive", "Gauss–Newton"].iter().enumerate() {
        let its = &mut iterations[k];
        its.sort_unstable();
        let mean = its.iter().sum::<u64>() as f64 / its.len() as f64;
        println!(
            "{name}: iterations median {}, mean {mean:.1}, most {}",
            (its[63] + its[64]) as f64 / 2.0,
            its[127]
        );
    }
}

/// Records of the study where the width goes to 0 (14 of the 128 do; found with
/// [`scan_terminations`]).
const AT_BOUND: [u64; 2] = [7, 105];

#[test]
fn a_width_at_zero_is_converged_at_the_bound() {
    for r in AT_BOUND {
        // The plain solver now reaches the bound itself (it once stalled against the domain's
        // edge, σ ≤ 0 being no model): with the width's curvature in its matrix it goes to 0
        // quadratically and stops on its cost-change test far below the bound's threshold.
        let (structure, data, stalled) = plain_search(r);
        let start = structure.params();
        let problem = FitProblem::new(&structure, &Bcls, &data);
        assert!(
            stalled.termination.is_convergence(),
            "record {r}: {}",
            stalled.termination
        );
        assert!(
            stalled.iterations < 50,
            "record {r}: {}",
            stalled.iterations
        );
        assert!(
            stalled.params[4] < 1e-6 * start[4],
            "record {r}: {:?}",
            stalled.params
        );

        let fit = fit_realisation(r);
        assert!(fit.converged, "record {r}: {}", fit.termination);
        assert_eq!(fit.termination, Termination::AtBound { params: vec![4] });
        assert!(fit.params[4] > 0.0 && fit.params[4] < 1e-6 * start[4]);
        // The other parameters were refitted with the width held: no worse than where the
        // plain solver stalled, and a first-order stationary point of the criterion.
        assert!(
            fit.cost <= stalled.cost,
            "record {r}: {} > {}",
            fit.cost,
            stalled.cost
        );
        let residuals = problem.residuals(&fit.params).expect("residuals");
        let ne = problem
            .normal_equations(&fit.params, &residuals)
            .expect("normal equations");
        for i in 0..4 {
            // The gradient's cosine with each free column (the solver's own test, gtol 1e-10,
            // or a cost change below ftol 1e-12 with the gradient then of order √ftol).
            let norm_r = residuals.iter().map(|x| x * x).sum::<f64>().sqrt();
            let cosine = ne.gradient[i].abs() / (ne.gram[(i, i)].sqrt() * norm_r);
            assert!(
                cosine < 1e-5,
                "record {r}, parameter {i}: cosine {cosine:e}"
            );
        }
        // Standard errors: withheld (0) at the bound, finite and positive for the others.
        let se = fit.std_errors.expect("covariance of the free parameters");
        assert_eq!(se[4], 0.0);
        assert!(se[..4].iter().all(|s| s.is_finite() && *s > 0.0), "{se:?}");
        let covariance = fit.covariance.expect("covariance");
        assert!(covariance[4].iter().all(|c| *c == 0.0));
    }
}

/// A record of the study (found with [`scan_terminations`]) where the width creeps towards 0:
/// the plain solver once spent its iteration limit with the width at `3e-8` of its start and
/// no step refused; now it stops on its cost-change test after a few iterations with the width
/// at about `1e-4` of its start, where a step changes the criterion by the square of a small
/// width. Either way the search stopped short of the bound: it is tried there, where the
/// criterion's slope in the width points out of the domain, and ends converged there.
#[test]
fn a_width_creeping_to_zero_is_converged_at_the_bound() {
    let r = 98;
    let (structure, data, stalled) = plain_search(r);
    let start = structure.params();
    let problem = FitProblem::new(&structure, &Bcls, &data);
    assert!(
        stalled.termination.is_convergence(),
        "{}",
        stalled.termination
    );
    assert!(
        stalled.params[4] < 1e-3 * start[4] && stalled.params[4] > 1e-6 * start[4],
        "{:?}",
        stalled.params
    );
    let fit = fit_realisation(r);
    assert!(fit.converged, "{}", fit.termination);
    assert_eq!(fit.termination, Termination::AtBound { params: vec![4] });
    assert_eq!(fit.params[4], 1e-6 * start[4]);
    assert!(fit.cost <= stalled.cost, "{} > {}", fit.cost, stalled.cost);
    // The slope of the cost in the width at the bound: outwards (the cost rises into the
    // domain), the condition of a constrained minimum.
    let residuals = problem.residuals(&fit.params).expect("residuals");
    let ne = problem
        .normal_equations(&fit.params, &residuals)
        .expect("normal equations");
    assert!(ne.gradient[4] >= 0.0, "{}", ne.gradient[4]);
    let se = fit.std_errors.expect("covariance of the free parameters");
    assert_eq!(se[4], 0.0);
    assert!(se[..4].iter().all(|s| s.is_finite() && *s > 0.0), "{se:?}");
}

/// A record (42) that the chaotic search once took to the bound, where the criterion's slope
/// pointed out of the domain, so it was reported converged at the bound: its profile in the
/// width has a lower minimum inside, `σ ≈ 0.0082`, which the search now finds. The check is
/// independent of the search: the system refitted with the width held at several values
/// (output-error fits, the width known) costs more at each than the joint fit.
#[test]
fn a_small_width_inside_the_domain_is_found() {
    let r = 42;
    let (structure, record) = setup(r);
    let fit = fit_realisation(r);
    assert_converged_inside(&fit);
    assert!(
        fit.params[4] > 1e-3 && fit.params[4] < 2e-2,
        "{:?}",
        fit.params
    );
    for held in [1e-9, 1e-3, 4e-3, 1.2e-2, 2e-2] {
        let oe = ModelStructure::oe(
            structure.signal.clone(),
            Gaussian::new(held).expect("width"),
        );
        let profile = fit_with(&oe, &record);
        assert!(profile.converged, "σ = {held}: {}", profile.termination);
        assert!(
            fit.cost < profile.cost,
            "σ = {held}: {} ≥ {}",
            fit.cost,
            profile.cost
        );
    }
}

/// `fit` converged inside the domain, not by stopping at the width's bound.
fn assert_converged_inside(fit: &Estimate) {
    assert!(fit.converged, "{}", fit.termination);
    assert!(
        !matches!(
            fit.termination,
            jitterid_estimate::FitTermination::Solver(Termination::AtBound { .. })
        ),
        "{}",
        fit.termination
    );
}

fn fit_with(structure: &ModelStructure<LtiResponse<Zpk>, Gaussian>, record: &Record) -> Estimate {
    fit(structure, record, &Bcls, &FitOptions::default()).expect("fit runs")
}

/// A record (66) whose width is small but inside the domain (σ ≈ 0.0104): with Gauss–Newton's
/// model alone the search crept along a curved valley and spent the 500-iteration limit (about
/// 800 were needed), its gain ratio stuck near ½ — the large residuals' second-order term,
/// which Gauss–Newton's matrix leaves out, couples the width to the system's parameters. The
/// default adaptive model (Gauss–Newton's matrix plus a secant estimate of that term, taken
/// when it predicts the steps better) converges in a few dozen iterations to a lower cost.
#[test]
fn an_interior_small_width_converges_within_the_default_limit() {
    use jitterid_estimate::solver::LmModel;
    let r = 66;
    let (structure, record) = setup(r);
    let plain = fit(
        &structure,
        &record,
        &Bcls,
        &FitOptions::default()
            .with_solver(LevenbergMarquardt::default().with_model(LmModel::GaussNewton)),
    )
    .expect("fit runs");
    assert!(!plain.converged, "{}", plain.termination);
    assert_eq!(plain.iterations, 500);

    let fit = fit_realisation(r);
    assert_converged_inside(&fit);
    assert!(fit.iterations < 50, "{}", fit.iterations);
    assert!(fit.cost < plain.cost, "{} ≥ {}", fit.cost, plain.cost);
    assert!(
        fit.params[4] > 0.009 && fit.params[4] < 0.012,
        "{:?}",
        fit.params
    );
    // A stationary point: the gradient's cosine with every column is small.
    let grid = *record.grid();
    let data = FrequencyData::new(record, DirichletWindow, FrequencySet::dft(&grid)).expect("data");
    let problem = FitProblem::new(&structure, &Bcls, &data);
    let residuals = problem.residuals(&fit.params).expect("residuals");
    let ne = problem
        .normal_equations(&fit.params, &residuals)
        .expect("normal equations");
    let norm_r = residuals.iter().map(|x| x * x).sum::<f64>().sqrt();
    for i in 0..5 {
        let cosine = ne.gradient[i].abs() / (ne.gram[(i, i)].sqrt() * norm_r);
        assert!(cosine < 1e-5, "parameter {i}: cosine {cosine:e}");
    }
}
