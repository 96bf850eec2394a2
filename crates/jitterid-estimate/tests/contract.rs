//! `testing::check_criterion` on every shipped first-moment criterion, and on broken criteria
//! that it must reject (so that it cannot pass vacuously).

use jitterid_estimate::testing::{check_criterion, check_criterion_on, CriterionFixture};
use jitterid_estimate::{
    Bcls, BoxJenkins, Criterion, EstimateError, Ls, WeightContext, WeightedBcls,
};
use jitterid_window::FrequencySet;

fn assert_contract<C: Criterion + ?Sized>(criterion: &C, fixture: &CriterionFixture) {
    if let Err(e) = check_criterion_on(criterion, fixture) {
        panic!("{e}");
    }
}

/// Weights `0.3, 1.7, 0.9, 0.05, 2.4, …` (asymmetric, none round), one per frequency.
fn asymmetric_weights(n: usize) -> Vec<f64> {
    const PATTERN: [f64; 5] = [0.3, 1.7, 0.9, 0.05, 2.4];
    (0..n)
        .map(|i| PATTERN[i % PATTERN.len()] * (1.0 + i as f64 / n as f64))
        .collect()
}

#[test]
fn every_shipped_criterion_meets_the_contract() {
    for seed in [1, 2] {
        let fixture = CriterionFixture::new(seed);
        let n = fixture.frequencies().len();
        // Box–Jenkins on the fixture's AR(1) noise model, a non-white shape.
        assert!(!jitterid_estimate::NoiseModel::is_white(
            &fixture.truth().noise
        ));
        let criteria: Vec<Box<dyn Criterion>> = vec![
            Box::new(Ls),
            Box::new(Bcls),
            Box::new(WeightedBcls::new(asymmetric_weights(n)).unwrap()),
            Box::new(BoxJenkins),
        ];
        for criterion in &criteria {
            // Through the boxed trait object (the forwarding impl) and the value itself.
            assert_contract(criterion, &fixture);
            assert_contract(criterion.as_ref(), &fixture);
        }
    }
}

#[test]
fn check_criterion_builds_its_own_fixture() {
    check_criterion(&Bcls, 3).unwrap_or_else(|e| panic!("{e}"));
    check_criterion(&BoxJenkins, 3).unwrap_or_else(|e| panic!("{e}"));
}

/// The out-of-tree criterion of `docs/extending.md`: BCLS weighted by 1/f below a cutoff.
#[derive(Debug)]
struct InverseFrequency {
    cutoff: f64,
}

impl Criterion for InverseFrequency {
    fn name(&self) -> &'static str {
        "bcls-1/f"
    }
    fn models_jitter(&self) -> bool {
        true
    }
    fn weights(&self, context: &WeightContext<'_>) -> Vec<f64> {
        let f = context.frequencies().frequencies();
        f.iter()
            .map(|&f| {
                if f > 0.0 && f <= self.cutoff {
                    1.0 / f
                } else {
                    0.0
                }
            })
            .collect()
    }
}

#[test]
fn the_criterion_of_the_extending_guide_meets_the_contract() {
    check_criterion(&InverseFrequency { cutoff: 0.2 }, 1).unwrap_or_else(|e| panic!("{e}"));
}

/// A criterion with ones as weights, changed by `f` at the context.
struct Broken<F> {
    name: &'static str,
    weights: F,
    model_dependent: bool,
    uses_noise: bool,
    flat: bool,
    rejects: bool,
}

impl<F> std::fmt::Debug for Broken<F> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Broken({:?})", self.name)
    }
}

impl<F: Fn(&WeightContext<'_>) -> Vec<f64> + Send + Sync> Criterion for Broken<F> {
    fn name(&self) -> &'static str {
        self.name
    }
    fn models_jitter(&self) -> bool {
        true
    }
    fn model_dependent_weights(&self) -> bool {
        self.model_dependent
    }
    fn uses_noise_model(&self) -> bool {
        self.uses_noise
    }
    fn flat_residuals(&self) -> bool {
        self.flat
    }
    fn weights(&self, context: &WeightContext<'_>) -> Vec<f64> {
        (self.weights)(context)
    }
    fn validate(&self, _: &FrequencySet) -> Result<(), EstimateError> {
        if self.rejects {
            Err(EstimateError::BadWeight {
                index: 0,
                value: f64::NAN,
            })
        } else {
            Ok(())
        }
    }
}

fn broken<F: Fn(&WeightContext<'_>) -> Vec<f64> + Send + Sync>(
    name: &'static str,
    weights: F,
) -> Broken<F> {
    Broken {
        name,
        weights,
        model_dependent: false,
        uses_noise: false,
        flat: false,
        rejects: false,
    }
}

fn ones(c: &WeightContext<'_>) -> Vec<f64> {
    vec![1.0; c.frequencies().len()]
}

fn run<C: Criterion>(criterion: C) {
    check_criterion(&criterion, 1).unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn a_well_formed_criterion_of_our_own_passes() {
    // The harness of the broken ones is not itself broken.
    run(Broken {
        flat: true,
        ..broken("ones", ones)
    });
}

#[test]
#[should_panic(expected = "criterion `negative` (Broken(\"negative\")) breaks 2 contract check(s)")]
fn negative_weights_are_caught() {
    run(broken("negative", |c| {
        let mut w = ones(c);
        w[3] = -1.0;
        w
    }));
}

#[test]
#[should_panic(expected = "w[3] = -1 is negative")]
fn negative_weights_are_named() {
    run(broken("negative", |c| {
        let mut w = ones(c);
        w[3] = -1.0;
        w
    }));
}

#[test]
#[should_panic(expected = "is not finite")]
fn nan_weights_are_caught() {
    run(broken("nan", |c| {
        let mut w = ones(c);
        w[7] = f64::NAN;
        w
    }));
}

#[test]
#[should_panic(expected = "100 weights for 101 frequencies")]
fn weights_of_the_wrong_length_are_caught() {
    run(broken("short", |c| vec![1.0; c.frequencies().len() - 1]));
}

#[test]
#[should_panic(expected = "all weights are zero")]
fn all_zero_weights_are_caught() {
    run(broken("zero", |c| vec![0.0; c.frequencies().len()]));
}

#[test]
#[should_panic(expected = "model_dependent_weights() is false, but the weights change")]
fn model_dependent_weights_that_claim_not_to_be_are_caught() {
    // |γ(f)|² moves with the jitter's parameters.
    run(broken("gamma", |c| {
        c.jitter_cf().iter().map(|g| g.norm_sqr()).collect()
    }));
}

#[test]
#[should_panic(expected = "model_dependent_weights() is false, but the weights change")]
fn weights_of_the_first_moment_that_claim_independence_are_caught() {
    run(broken("mu", |c| {
        c.model_dtft()
            .iter()
            .map(|m| 1.0 / (1.0 + m.norm_sqr()))
            .collect()
    }));
}

#[test]
#[should_panic(expected = "uses_noise_model() is false, but the weights change")]
fn noise_weights_that_claim_not_to_use_the_noise_model_are_caught() {
    run(broken("noise", |c| {
        c.noise_shape().iter().map(|h| 1.0 / h).collect()
    }));
}

#[test]
#[should_panic(expected = "flat_residuals() is true, but on the white record")]
fn a_false_claim_of_flat_residuals_is_caught() {
    // White noise weighted by 1/f is not flat.
    run(Broken {
        flat: true,
        ..broken("tilted", |c| {
            c.frequencies()
                .frequencies()
                .iter()
                .map(|f| 1.0 / (f + 0.01))
                .collect()
        })
    });
}

#[test]
#[should_panic(expected = "flat_residuals() is true, but on the coloured record")]
fn flat_residuals_with_the_noise_model_ignored_are_caught() {
    // Claims to use the noise model, but weights it the wrong way round.
    run(Broken {
        flat: true,
        uses_noise: true,
        ..broken("anti-bj", |c| c.noise_shape())
    });
}

#[test]
#[should_panic(expected = "name() is empty")]
fn an_empty_name_is_caught() {
    run(broken("", ones));
}

#[test]
#[should_panic(expected = "validate rejects the frequency set")]
fn a_validate_that_rejects_the_set_is_caught() {
    run(Broken {
        rejects: true,
        ..broken("picky", ones)
    });
}
