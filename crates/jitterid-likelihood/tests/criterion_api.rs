//! The criterion as a researcher uses it: trait objects compared in a loop, weights that depend
//! on the data and the model (checked against finite differences), the residual-flatness guard
//! for a criterion of one's own, and the registries.

use jitterid_estimate::solver::{fd_jacobian, SolverRegistry, DEFAULT_FD_STEP};
use jitterid_estimate::{
    fit, Bcls, Criterion, FitOptions, FitProblem, Frequencies, FrequencyData, ModelStructure,
    Record, WeightContext,
};
use jitterid_estimate::{AnyNoise, WhiteNoise};
use jitterid_jitter::AnyJitter;
use jitterid_jitter::UniformSum;
use jitterid_likelihood::{AnyStructure, CriterionRegistry};
use jitterid_signal::AnySignal;
use jitterid_signal::{
    simulate, LtiResponse, PiecewiseConstant, RandomBinary, Root, SampleGrid, Zpk,
};
use jitterid_window::{DirichletWindow, FrequencySet};
use rand::SeedableRng;

type Structure = ModelStructure<LtiResponse<Zpk>, UniformSum>;

fn eq17(k0: f64, z: f64, pr: f64, pi: f64) -> Zpk {
    Zpk::new(
        k0,
        vec![Root::Real(-z)],
        vec![Root::Pair { re: pr, im: pi }],
    )
    .unwrap()
}

/// A Table 2 record (seed `seed`) and the OE structure started 10 % off the truth.
fn table2(seed: u64) -> (Structure, Record, PiecewiseConstant) {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let u = RandomBinary::paper()
        .generate(0.0, 201.0, &mut rng)
        .unwrap();
    let jitter = UniformSum::new(2, 0.5 / 3f64.sqrt()).unwrap();
    let grid = SampleGrid::new(0.0, 1.0, 200).unwrap();
    let truth = LtiResponse::new(eq17(0.2, 0.5, -0.25, 0.3), u.clone());
    let data = simulate(&truth, &jitter, &grid, 0.01, &mut rng).unwrap();
    let start = LtiResponse::new(eq17(0.22, 0.45, -0.27, 0.33), u.clone());
    (
        ModelStructure::oe(start, jitter),
        Record::new(grid, data.y).unwrap(),
        u,
    )
}

/// BCLS written outside the crate, declaring flat residuals.
#[derive(Debug)]
struct MyBcls;

impl Criterion for MyBcls {
    fn name(&self) -> &'static str {
        "my-bcls"
    }
    fn models_jitter(&self) -> bool {
        true
    }
    fn flat_residuals(&self) -> bool {
        true
    }
    fn weights(&self, context: &WeightContext<'_>) -> Vec<f64> {
        vec![1.0; context.frequencies().len()]
    }
}

/// Weights that depend on the data and the model: `|γ(f)|² / (|Y(f)|² + |μ_Y(f)|²)`.
#[derive(Debug)]
struct ModelWeighted;

impl Criterion for ModelWeighted {
    fn name(&self) -> &'static str {
        "model-weighted"
    }
    fn models_jitter(&self) -> bool {
        true
    }
    fn model_dependent_weights(&self) -> bool {
        true
    }
    fn weights(&self, context: &WeightContext<'_>) -> Vec<f64> {
        let gamma = context.jitter_cf();
        context
            .dtft()
            .iter()
            .zip(context.model_dtft())
            .zip(&gamma)
            .map(|((y, mu), g)| g.norm_sqr() / (y.norm_sqr() + mu.norm_sqr()))
            .collect()
    }
}

#[test]
fn boxed_criteria_fit_like_the_concrete_type_and_keep_the_flatness_guard() {
    let (structure, record, _) = table2(11);
    let opts = FitOptions::default();
    let concrete = fit(&structure, &record, &Bcls, &opts).unwrap();
    let criteria: Vec<Box<dyn Criterion>> = vec![Box::new(Bcls), Box::new(MyBcls)];
    for c in &criteria {
        let fit = fit(&structure, &record, c, &opts).unwrap();
        // The same arithmetic behind a trait object: identical to the last bit.
        assert_eq!(fit.params, concrete.params, "{}", c.name());
        assert_eq!(fit.cost, concrete.cost);
        // A criterion of one's own that declares flat residuals is checked like BCLS.
        assert_eq!(fit.residual_flatness, concrete.residual_flatness);
        assert!(fit.residual_flatness.is_some());
    }
}

#[test]
fn jacobian_of_model_dependent_weights_matches_finite_differences() {
    let (structure, record, _) = table2(12);
    let structure = structure.with_estimated(true, true, false);
    let freqs = FrequencySet::dft(record.grid());
    let data = FrequencyData::new(record, DirichletWindow, freqs).unwrap();
    let problem = FitProblem::new(&structure, &ModelWeighted, &data);
    let theta = structure.params();
    let analytic = data.jacobian(&ModelWeighted, &structure);
    // An independent route: central differences of the whole residual vector.
    let fd = fd_jacobian(&problem, &theta, DEFAULT_FD_STEP).unwrap();
    let scale = (0..fd.nrows())
        .flat_map(|i| (0..fd.ncols()).map(move |j| (i, j)))
        .fold(0.0f64, |m, (i, j)| m.max(fd[(i, j)].abs()));
    for i in 0..fd.nrows() {
        for j in 0..fd.ncols() {
            // Both are O(h²)-accurate differences (steps 1e-6 and 6e-6 relative) of smooth
            // functions except the analytic signal columns: agreement to 1e-5 of the largest
            // entry is far above their rounding (≈ ε/h ≈ 1e-10 relative) and far below any
            // missing term (the weights' own derivative is of order one here).
            assert!(
                (analytic[(i, j)] - fd[(i, j)]).abs() <= 1e-5 * scale,
                "({i}, {j}): {} vs {}",
                analytic[(i, j)],
                fd[(i, j)]
            );
        }
    }
    // Without the weights' derivative the Jacobian is visibly wrong: the check above can fail.
    #[derive(Debug)]
    struct Frozen;
    impl Criterion for Frozen {
        fn name(&self) -> &'static str {
            "frozen"
        }
        fn models_jitter(&self) -> bool {
            true
        }
        fn weights(&self, context: &WeightContext<'_>) -> Vec<f64> {
            ModelWeighted.weights(context)
        }
    }
    let frozen = data.jacobian(&Frozen, &structure);
    let worst = (0..fd.nrows())
        .flat_map(|i| (0..fd.ncols()).map(move |j| (i, j)))
        .fold(0.0f64, |m, (i, j)| {
            m.max((frozen[(i, j)] - fd[(i, j)]).abs())
        });
    assert!(worst > 1e-3 * scale, "{worst} vs {scale}");
}

#[test]
fn registries_build_what_a_front_end_asks_for_and_fit_through_one_entry() {
    let (structure, record, _) = table2(13);
    let criteria = CriterionRegistry::builtin();
    let solvers = SolverRegistry::builtin();
    let table = |v: serde_json::Value| v.as_object().unwrap().clone();
    let bcls = criteria
        .build(&table(serde_json::json!({ "criterion": "bcls" })))
        .unwrap();
    let lm = solvers
        .build(&table(serde_json::json!({ "solver": "lm" })))
        .unwrap();
    let options = FitOptions {
        solver: Some(lm),
        ..FitOptions::default()
    };
    // What a front end fits: the same model behind the run-time types.
    let any_structure =
        |s: &Structure| -> AnyStructure {
            let signal = AnySignal::new("zpk", s.signal.clone(), |_| serde_json::Map::new());
            let jitter = AnyJitter::new("uniform-sum", s.jitter, |_| serde_json::Map::new());
            let mut a = ModelStructure::bj(signal, jitter, AnyNoise::new(WhiteNoise))
                .with_estimated(s.estimate_signal, s.estimate_jitter, false);
            a.noise_std = s.noise_std;
            a
        };
    let any = fit(&any_structure(&structure), &record, &bcls, &options).unwrap();
    let direct = fit(&structure, &record, &Bcls, &FitOptions::default()).unwrap();
    assert_eq!(any.params, direct.params);
    assert_eq!(any.std_errors, direct.std_errors);
    // A likelihood with a residual-only solver: a typed error, not a panic.
    let ml = criteria
        .build(&table(serde_json::json!({ "criterion": "quasi-ml" })))
        .unwrap();
    let known = structure.clone().with_noise_std(0.01).unwrap();
    let err = fit(&any_structure(&known), &record, &ml, &options).unwrap_err();
    assert!(err.to_string().contains("lm"), "{err}");
    // Errors name the key.
    let e = criteria
        .build(&table(
            serde_json::json!({ "criterion": "weighted-bcls", "weights": [1.0, -1.0] }),
        ))
        .unwrap_err();
    assert_eq!(e.key(), Some("weights"));
    let e = solvers
        .build(&table(
            serde_json::json!({ "solver": "bfgs", "max_iters": 0 }),
        ))
        .unwrap_err();
    assert_eq!(e.key(), Some("max_iters"));
    let e = solvers
        .build(&table(
            serde_json::json!({ "solver": "lm", "starts": 2, "radius": -1.0 }),
        ))
        .unwrap_err();
    assert_eq!(e.key(), Some("radius"));
    // A band of frequencies through the same options.
    let band = FitOptions {
        frequencies: Frequencies::Band { min: 0.0, max: 0.2 },
        ..FitOptions::default()
    };
    assert!(
        fit(&any_structure(&structure), &record, &bcls, &band)
            .unwrap()
            .converged
    );
}
