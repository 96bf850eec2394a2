//! The normal equations that a fit accumulates without its Jacobian equal the explicit
//! `JᵀJ`, `Jᵀr` of the frequency-domain Jacobian (the independent route), and the fit and its
//! covariance are the same whichever route is taken.

use jitterid_estimate::solver::{LeastSquares, NormalEquations};
use jitterid_estimate::{
    fit, Bcls, Criterion, FitOptions, FitProblem, Frequencies, FrequencyData, Ls, ModelStructure,
    Record,
};
use jitterid_jitter::Gaussian;
use jitterid_signal::{simulate, LtiResponse, RandomBinary, Root, SampleGrid, Zpk};
use jitterid_window::{DirichletWindow, FrequencySet, HannWindow, Window};
use rand::SeedableRng;

type Sys = LtiResponse<Zpk>;

fn eq17(k: f64, z: f64, re: f64, im: f64) -> Zpk {
    Zpk::new(k, vec![Root::Real(-z)], vec![Root::Pair { re, im }]).expect("valid")
}

/// A simulated Table 2 style record of `n` samples and a JOE structure (Gaussian jitter
/// estimated) started off the truth.
fn setup(n: usize, seed: u64) -> (Record, ModelStructure<Sys, Gaussian>) {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let u = RandomBinary::paper()
        .generate(0.0, n as f64 + 1.0, &mut rng)
        .expect("input");
    let grid = SampleGrid::new(0.0, 1.0, n).expect("grid");
    let jitter = Gaussian::new(0.15).expect("jitter");
    let truth = LtiResponse::new(eq17(0.2, 0.5, -0.25, 0.3), u.clone());
    let y = simulate(&truth, &jitter, &grid, 0.01, &mut rng)
        .expect("simulate")
        .y;
    let start = LtiResponse::new(eq17(0.21, 0.45, -0.27, 0.33), u);
    let structure = ModelStructure::joe(start, Gaussian::new(0.1).expect("jitter"));
    (Record::new(grid, y).expect("record"), structure)
}

fn max_abs_gram(ne: &NormalEquations) -> f64 {
    let p = ne.num_params();
    (0..p)
        .flat_map(|a| (0..p).map(move |b| (a, b)))
        .map(|(a, b)| ne.gram[(a, b)].abs())
        .fold(0.0, f64::max)
}

/// Compares the accumulated normal equations of `criterion` on `freqs` with the explicit ones:
/// `Jᵀr` bit for bit (same products, same order), `JᵀJ` to rounding (Parseval sums in time
/// instead of frequency: relative 1e-12 of the largest entry, some thousand ulps of sums of
/// a few hundred terms).
fn check<C: Criterion, W: Window + Clone>(
    criterion: &C,
    record: &Record,
    structure: &ModelStructure<Sys, Gaussian>,
    window: W,
    freqs: FrequencySet,
) {
    let data = FrequencyData::new(record.clone(), window, freqs).expect("data");
    let problem = FitProblem::new(structure, criterion, &data);
    let theta = structure.params();
    let r = problem.residuals(&theta).expect("residuals");
    let flat = problem
        .normal_equations(&theta, &r)
        .expect("normal equations");
    let mut explicit = NormalEquations::from_jacobian(&problem.jacobian(&theta).expect("J"), &r)
        .expect("explicit");
    // The search's matrix carries an even jitter width's second-order term `g/σ` where it is
    // positive (the Gaussian's σ, when estimated; see `even_widths`).
    let (ns, nj, _) = structure.blocks();
    if nj == 1 {
        let extra = explicit.gradient[ns] / theta[ns];
        if extra > 0.0 {
            explicit.gram[(ns, ns)] += extra;
        }
    }
    assert!(flat.is_finite() && explicit.is_finite());
    assert_eq!(flat.gradient, explicit.gradient);
    let scale = max_abs_gram(&explicit);
    let p = theta.len();
    for a in 0..p {
        for b in 0..p {
            let (x, y) = (flat.gram[(a, b)], explicit.gram[(a, b)]);
            assert!(
                (x - y).abs() <= 1e-12 * scale,
                "{} N = {}: JᵀJ[{a},{b}] {x} vs {y}",
                criterion.name(),
                record.y().len()
            );
        }
    }
}

#[test]
fn accumulated_normal_equations_equal_the_explicit_ones() {
    // Even and odd N (the Nyquist bin exists only for even N), with and without the jitter in
    // the first moment, and the explicit fallback (band, Hann window) for comparison.
    for (n, seed) in [(200, 1), (201, 2), (64, 3)] {
        let (record, structure) = setup(n, seed);
        let grid = *record.grid();
        check(
            &Bcls,
            &record,
            &structure,
            DirichletWindow,
            FrequencySet::dft(&grid),
        );
        let oe = structure.clone().with_estimated(true, false, false);
        check(&Ls, &record, &oe, DirichletWindow, FrequencySet::dft(&grid));
        check(
            &Bcls,
            &record,
            &structure,
            DirichletWindow,
            FrequencySet::band(&grid, 0.05, 0.3).expect("band"),
        );
        check(
            &Bcls,
            &record,
            &structure,
            HannWindow,
            FrequencySet::dft(&grid),
        );
    }
}

#[test]
fn a_point_outside_the_domain_has_non_finite_normal_equations() {
    let (record, structure) = setup(64, 4);
    let data = FrequencyData::new(
        record.clone(),
        DirichletWindow,
        FrequencySet::dft(record.grid()),
    )
    .expect("data");
    let problem = FitProblem::new(&structure, &Bcls, &data);
    let mut theta = structure.params();
    let r = problem.residuals(&theta).expect("residuals");
    *theta.last_mut().expect("jitter parameter") = -1.0;
    let ne = problem.normal_equations(&theta, &r).expect("no error");
    assert!(!ne.is_finite());
    assert_eq!(
        ne.first_non_finite().map(|(what, i, _)| (what, i)),
        Some(("gradient", 0))
    );
}

#[test]
fn covariance_by_sums_over_samples_matches_the_projected_jacobian() {
    // The DFT set takes the accumulated route; the same frequencies listed in reverse order
    // take the explicit Jacobian. Estimates and covariances agree to the solver's tolerance.
    let (record, structure) = setup(200, 5);
    let grid = *record.grid();
    let mut list: Vec<f64> = FrequencySet::dft(&grid).frequencies().to_vec();
    list.reverse();
    let by_sums = fit(&structure, &record, &Bcls, &FitOptions::default()).expect("fit");
    let explicit = fit(
        &structure,
        &record,
        &Bcls,
        &FitOptions::default().with_frequencies(Frequencies::List(list)),
    )
    .expect("fit");
    assert!(by_sums.converged && explicit.converged);
    let (ca, cb) = (
        by_sums.covariance.expect("covariance"),
        explicit.covariance.expect("covariance"),
    );
    for (i, (a, b)) in by_sums.params.iter().zip(&explicit.params).enumerate() {
        // Both stop at the same minimum, up to where the cost's tolerances (ftol = 1e-12)
        // leave a weakly determined parameter: a tiny fraction of its standard error.
        let se = ca[i][i].sqrt();
        assert!((a - b).abs() <= 1e-4 * se, "θ[{i}] {a} vs {b} (se {se})");
        for j in 0..ca.len() {
            let scale = (ca[i][i] * ca[j][j]).sqrt();
            assert!(
                (ca[i][j] - cb[i][j]).abs() <= 1e-6 * scale,
                "cov[{i}][{j}] {} vs {}",
                ca[i][j],
                cb[i][j]
            );
        }
    }
}

/// The residual evaluation keeps the sensitivities of its pass for the normal equations at the
/// same point: the numbers are those of a problem that evaluates everything afresh, bit for
/// bit, and a moved point is evaluated anew.
#[test]
fn memoised_evaluation_equals_a_fresh_one() {
    let (record, structure) = setup(200, 11);
    let data = FrequencyData::new(
        record.clone(),
        DirichletWindow,
        FrequencySet::dft(record.grid()),
    )
    .expect("data");
    let theta = structure.params();
    let memoised = FitProblem::new(&structure, &Bcls, &data);
    let r = memoised.residuals(&theta).expect("residuals");
    let ne = memoised
        .normal_equations(&theta, &r)
        .expect("normal equations");
    // A fresh problem asked for the normal equations first has no memo to use.
    let fresh = FitProblem::new(&structure, &Bcls, &data);
    let ne_fresh = fresh
        .normal_equations(&theta, &r)
        .expect("normal equations");
    assert_eq!(ne.gradient, ne_fresh.gradient);
    assert_eq!(ne.gram, ne_fresh.gram);
    assert_eq!(r, fresh.residuals(&theta).expect("residuals"));
    let mut moved = theta.clone();
    moved[0] *= 1.01;
    let r_moved = memoised.residuals(&moved).expect("residuals");
    assert_ne!(r_moved, r);
    assert_eq!(
        r_moved,
        FitProblem::new(&structure, &Bcls, &data)
            .residuals(&moved)
            .expect("residuals")
    );
    assert_eq!(
        memoised.normal_equations(&moved, &r_moved).expect("ne"),
        FitProblem::new(&structure, &Bcls, &data)
            .normal_equations(&moved, &r_moved)
            .expect("ne")
    );
}
