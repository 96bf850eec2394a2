//! Every built-in family against the full contract of `testing::check_contract`, at chosen and
//! at seeded random parameters, and every override of a provided method against its default.

use jitterid_jitter::registry::JitterRegistry;
use jitterid_jitter::serde_json::json;
use jitterid_jitter::testing::{
    check_closed_forms, check_contract, check_distribution, check_overrides, ProvidedDefaults,
};
use jitterid_jitter::{
    AnyJitter, ExponentialDelay, Gaussian, JitterModel, Laplace, Mixture, NoJitter, Periodic,
    Shifted, Sum, TwoPoint, UniformSum,
};
use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

fn assert_contract<J: JitterModel + Clone>(model: &J, seed: u64) {
    if let Err(e) = check_contract(model, seed) {
        panic!("{e}");
    }
}

#[test]
fn no_jitter() {
    assert_contract(&NoJitter::new(), 1);
}

#[test]
fn uniform_sum() {
    let mut seed = 100;
    for n in [0, 1, 2, 5, 20, 50] {
        for a in [1e-6, 0.2887, 0.5, 5.0] {
            seed += 1;
            assert_contract(&UniformSum::new(n, a).unwrap(), seed);
        }
    }
}

#[test]
fn gaussian() {
    for (k, sigma) in [1e-9, 1.0 / 6.0, 1.0, 40.0].into_iter().enumerate() {
        assert_contract(&Gaussian::new(sigma).unwrap(), 200 + k as u64);
    }
}

#[test]
fn laplace() {
    for (k, b) in [1e-7, 0.05, 1.0, 30.0].into_iter().enumerate() {
        assert_contract(&Laplace::new(b).unwrap(), 300 + k as u64);
    }
}

#[test]
fn two_point() {
    for (k, d) in [1e-8, 0.1, 0.5, 7.0].into_iter().enumerate() {
        assert_contract(&TwoPoint::new(d).unwrap(), 400 + k as u64);
    }
}

#[test]
fn exponential_delay() {
    for (k, mean) in [1e-6, 0.01, 0.3, 12.0].into_iter().enumerate() {
        assert_contract(&ExponentialDelay::new(mean).unwrap(), 500 + k as u64);
    }
}

#[test]
fn shifted() {
    assert_contract(&Shifted::new(NoJitter::new(), 0.25).unwrap(), 600);
    assert_contract(&Shifted::new(NoJitter::new(), 0.0).unwrap(), 601);
    assert_contract(
        &Shifted::new(UniformSum::new(2, 0.2887).unwrap(), -0.1).unwrap(),
        602,
    );
    assert_contract(
        &Shifted::new(UniformSum::new(20, 1e-3).unwrap(), 0.0).unwrap(),
        603,
    );
    assert_contract(
        &Shifted::new(Gaussian::new(0.01).unwrap(), 0.05).unwrap(),
        604,
    );
    assert_contract(
        &Shifted::new(ExponentialDelay::new(0.2).unwrap(), -0.2).unwrap(),
        605,
    );
    assert_contract(&Shifted::new(Laplace::new(2.0).unwrap(), 3.0).unwrap(), 606);
    assert_contract(
        &Shifted::new(TwoPoint::new(0.3).unwrap(), 0.1).unwrap(),
        607,
    );
    // Nested: two offsets and an inner family.
    let nested = Shifted::new(
        Shifted::new(Gaussian::new(0.5).unwrap(), 1.0).unwrap(),
        -0.75,
    )
    .unwrap();
    assert_contract(&nested, 608);
}

#[test]
fn periodic() {
    for (k, a) in [1e-7, 0.04, 0.37, 9.0].into_iter().enumerate() {
        assert_contract(&Periodic::new(a).unwrap(), 700 + k as u64);
    }
}

#[test]
fn sum() {
    assert_contract(
        &Sum::new(Gaussian::new(0.03).unwrap(), TwoPoint::new(0.11).unwrap()),
        800,
    );
    assert_contract(
        &Sum::new(Periodic::new(0.07).unwrap(), TwoPoint::new(0.023).unwrap()),
        801,
    );
    assert_contract(
        &Sum::new(
            Shifted::new(Laplace::new(0.013).unwrap(), 0.2).unwrap(),
            TwoPoint::new(0.05).unwrap(),
        ),
        802,
    );
}

#[test]
fn mixture() {
    // Asymmetric weights and arbitrary (not round) parameters, of one family and of several.
    let g = |s: f64| Gaussian::new(s).unwrap();
    let two = Mixture::new(vec![g(0.0137), g(0.0561)], vec![0.3, 0.7]).unwrap();
    assert_contract(&two, 900);
    assert_contract(&two.with_fixed_weights(), 901);
    fn wrap<T: JitterModel + Clone + PartialEq + 'static>(label: &str, t: T) -> AnyJitter {
        AnyJitter::new(label.to_string(), t, |_| Default::default())
    }
    let mixed = Mixture::new(
        vec![
            wrap(
                "shifted",
                Shifted::new(ExponentialDelay::new(0.043).unwrap(), -0.061).unwrap(),
            ),
            wrap("laplace", Laplace::new(0.029).unwrap()),
        ],
        vec![0.3, 0.7],
    )
    .unwrap();
    assert_contract(&mixed, 902);
    let three = Mixture::new(
        vec![
            wrap("uniform-sum", UniformSum::new(3, 0.071).unwrap()),
            wrap("two-point", TwoPoint::new(0.019).unwrap()),
            wrap("periodic", Periodic::new(0.087).unwrap()),
        ],
        vec![0.17, 0.52, 0.31],
    )
    .unwrap();
    assert_contract(&three, 903);
}

/// Log-uniform value in `[10^lo, 10^hi]`.
fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    (lo..hi).prop_map(|e| 10f64.powf(e))
}

proptest! {
    // Fixed seed: the checks are deterministic, and so is the choice of cases.
    #![proptest_config(ProptestConfig {
        cases: 64,
        rng_seed: RngSeed::Fixed(0x6a69_7474_6572),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn uniform_sum_closed_forms_hold_for_random_parameters(
        n in 0u32..=60,
        a in log_uniform(-8.0, 3.0),
    ) {
        let m = UniformSum::new(n, a).unwrap();
        prop_assert!(check_closed_forms(&m).is_ok(), "{}", check_closed_forms(&m).unwrap_err());
    }

    #[test]
    fn continuous_families_hold_for_random_parameters(
        scale in log_uniform(-8.0, 3.0),
        offset in -3.0..3.0f64,
        family in 0usize..4,
    ) {
        // The offset is in units of the scale, so that it never swamps the spread.
        let c = offset * scale;
        let r = match family {
            0 => check_closed_forms(&Shifted::new(Gaussian::new(scale).unwrap(), c).unwrap()),
            1 => check_closed_forms(&Shifted::new(Laplace::new(scale).unwrap(), c).unwrap()),
            2 => check_closed_forms(&Shifted::new(ExponentialDelay::new(scale).unwrap(), c).unwrap()),
            _ => check_closed_forms(&Shifted::new(TwoPoint::new(scale).unwrap(), c).unwrap()),
        };
        prop_assert!(r.is_ok(), "{}", r.unwrap_err());
    }
}

/// Every shipped family, with parameters drawn from `seed`: log-uniform scales over eleven
/// decades, asymmetric offsets and weights, structural choices (the uniform sum's `n`, which
/// terms a sum or mixture has) drawn too. Each comes with a label for messages and whether
/// its density is a convolution of two continuous laws (expensive: a quadrature per value).
fn shipped_families(seed: u64) -> Vec<(String, AnyJitter, bool)> {
    let mut rng = StdRng::seed_from_u64(seed);
    let scale = |rng: &mut StdRng| 10f64.powf(rng.random_range(-8.0..3.0));
    let s = scale(&mut rng);
    let ratio = |rng: &mut StdRng| 10f64.powf(rng.random_range(-1.0..1.0));
    let offset = |rng: &mut StdRng, s: f64| rng.random_range(-3.0..3.0) * s;
    // Weights with unequal, arbitrary values (not round decimals), summing to 1.
    let weights = |rng: &mut StdRng, k: usize| {
        let raw: Vec<f64> = (0..k).map(|_| rng.random_range(0.05..1.0)).collect();
        let total: f64 = raw.iter().sum();
        raw.iter().map(|w| w / total).collect::<Vec<f64>>()
    };
    fn wrap<T: JitterModel + Clone + PartialEq + 'static>(label: &str, t: T) -> AnyJitter {
        AnyJitter::new(label.to_string(), t, |_| Default::default())
    }
    let n = rng.random_range(0..=12u32);
    let g = |s: f64| Gaussian::new(s).unwrap();
    let u = UniformSum::new(n, s * ratio(&mut rng)).unwrap();
    let e = ExponentialDelay::new(s * ratio(&mut rng)).unwrap();
    let l = Laplace::new(s * ratio(&mut rng)).unwrap();
    let t = TwoPoint::new(s * ratio(&mut rng)).unwrap();
    let p = Periodic::new(s * ratio(&mut rng)).unwrap();
    let mix2 = Mixture::new(vec![g(s), g(s * ratio(&mut rng))], weights(&mut rng, 2)).unwrap();
    let parts = vec![
        wrap("shifted", Shifted::new(g(s), offset(&mut rng, s)).unwrap()),
        wrap("exponential", e),
        wrap("periodic", p),
    ];
    let mix3 = Mixture::new(parts, weights(&mut rng, 3)).unwrap();
    let mut out = vec![
        ("none".to_string(), wrap("none", NoJitter::new()), false),
        (format!("uniform-sum n={n}"), wrap("uniform-sum", u), false),
        ("gaussian".into(), wrap("gaussian", g(s)), false),
        ("laplace".into(), wrap("laplace", l), false),
        ("two-point".into(), wrap("two-point", t), false),
        ("exponential".into(), wrap("exponential", e), false),
        ("periodic".into(), wrap("periodic", p), false),
        (
            "shifted uniform-sum".into(),
            wrap("shifted", Shifted::new(u, offset(&mut rng, s)).unwrap()),
            false,
        ),
        (
            "shifted exponential".into(),
            wrap("shifted", Shifted::new(e, offset(&mut rng, s)).unwrap()),
            false,
        ),
        (
            "shifted periodic".into(),
            wrap("shifted", Shifted::new(p, offset(&mut rng, s)).unwrap()),
            false,
        ),
        (
            "shifted two-point".into(),
            wrap("shifted", Shifted::new(t, offset(&mut rng, s)).unwrap()),
            false,
        ),
        (
            "sum gaussian + two-point".into(),
            wrap("sum", Sum::new(g(s), t)),
            false,
        ),
        (
            "sum two-point + periodic".into(),
            wrap("sum", Sum::new(t, p)),
            false,
        ),
        (
            "sum uniform-sum + exponential".into(),
            wrap("sum", Sum::new(u, e)),
            true,
        ),
        (
            "mixture of two gaussians".into(),
            wrap("mixture", mix2.clone()),
            false,
        ),
        (
            "mixture with fixed weights".into(),
            wrap("mixture", mix2.with_fixed_weights()),
            false,
        ),
        (
            "mixture of three families".into(),
            wrap("mixture", mix3),
            false,
        ),
    ];
    // The same models through the registry's run-time type, built from spec tables.
    let registry = JitterRegistry::builtin();
    let w = weights(&mut rng, 2);
    let spec = json!({"family": "mixture", "weights": w, "offset": offset(&mut rng, s), "terms": [
        {"family": "laplace", "scale": s}, {"family": "uniform-sum", "n": n, "a": s * ratio(&mut rng)}]});
    out.push((
        format!("registry {spec}"),
        registry.build(spec.as_object().unwrap()).unwrap(),
        false,
    ));
    out
}

/// Runs `check` on every shipped family for several seeds, and reports all failures at once.
fn for_every_family(
    seeds: std::ops::Range<u64>,
    check: impl Fn(&str, &AnyJitter, bool, u64) -> Result<(), String>,
) {
    let mut fails = Vec::new();
    for seed in seeds {
        for (label, model, convolution) in shipped_families(seed) {
            if let Err(e) = check(&label, &model, convolution, seed) {
                fails.push(format!("seed {seed}, {label}: {e}"));
            }
        }
    }
    assert!(fails.is_empty(), "{}", fails.join("\n"));
}

#[test]
fn every_shipped_family_meets_the_contract_at_random_parameters() {
    for_every_family(0..4, |_, m, _, seed| check_contract(m, 1000 + seed));
}

#[test]
fn with_params_of_params_rebuilds_every_shipped_family_exactly() {
    // Independent of Debug output (which check_contract compares): the parameters themselves
    // round-trip to the bit, and so does every closed form at a few points.
    for_every_family(0..16, |_, m, _, _| {
        let again = m.with_params(&m.params()).map_err(|e| e.to_string())?;
        let (p, q) = (m.params(), again.params());
        let same = p.len() == q.len() && p.iter().zip(&q).all(|(a, b)| a.to_bits() == b.to_bits());
        let s = m.std_dev().max(1e-300);
        let values_same = [0.1, 1.0, 3.0].iter().all(|c| {
            let f = c / s;
            m.cf(f) == again.cf(f) && m.pdf(c * s) == again.pdf(c * s)
        }) && m.variance() == again.variance();
        if same && values_same && format!("{m:?}") == format!("{again:?}") {
            Ok(())
        } else {
            Err(format!(
                "params {p:?} rebuilt as {q:?} ({m:?} vs {again:?})"
            ))
        }
    });
}

#[test]
fn every_override_agrees_with_the_provided_default() {
    // The convolution of two continuous laws is left to its closed-form checks: its density
    // is a quadrature, so the Kolmogorov–Smirnov test's distribution function (a rule over
    // its 256 pieces at each of 200 points) and the default sampler's inversion cost minutes.
    for_every_family(0..3, |_, m, convolution, seed| {
        if convolution {
            return Ok(());
        }
        check_overrides(m, 2000 + seed)
    });
}

#[test]
fn the_provided_defaults_meet_the_contract() {
    // The family with mgf, cf_gradient and sample replaced by the trait's defaults. (The
    // convolution of two continuous laws is skipped, as in the test above: the default
    // sampler rebuilds the pieces' masses at every draw, a quadrature per density value.)
    for_every_family(0..2, |_, m, convolution, seed| {
        if convolution {
            return Ok(());
        }
        check_contract(&ProvidedDefaults(m.clone()), 3000 + seed)
    });
}

#[test]
fn the_default_sampler_passes_a_kolmogorov_smirnov_test_alone() {
    // `sample` itself (not a sampler built once) for two families with atoms and pieces.
    let mixed = Mixture::new(
        vec![
            AnyJitter::new("two-point", TwoPoint::new(0.3).unwrap(), |_| {
                Default::default()
            }),
            AnyJitter::new("periodic", Periodic::new(0.2).unwrap(), |_| {
                Default::default()
            }),
        ],
        vec![0.35, 0.65],
    )
    .unwrap();
    check_distribution(&ProvidedDefaults(mixed), 41).unwrap();
    let skewed = Shifted::new(ExponentialDelay::new(0.02).unwrap(), -0.01).unwrap();
    check_distribution(&ProvidedDefaults(skewed), 42).unwrap();
}

#[test]
fn a_wrong_sampler_fails_the_kolmogorov_smirnov_test() {
    // Uniform draws on the uniform sum's support have the right support and mean but the
    // wrong law: the test must see it.
    #[derive(Debug, Clone, PartialEq)]
    struct Flat(UniformSum);
    impl JitterModel for Flat {
        fn name(&self) -> &'static str {
            "flat"
        }
        fn param_names(&self) -> Vec<String> {
            self.0.param_names()
        }
        fn params(&self) -> Vec<f64> {
            self.0.params()
        }
        fn with_params(&self, p: &[f64]) -> Result<Self, jitterid_jitter::JitterError> {
            self.0.with_params(p).map(Flat)
        }
        fn cf(&self, f: f64) -> jitterid_jitter::num_complex::Complex64 {
            self.0.cf(f)
        }
        fn pdf(&self, t: f64) -> f64 {
            self.0.pdf(t)
        }
        fn pieces(&self) -> Vec<(f64, f64)> {
            self.0.pieces()
        }
        fn mean(&self) -> f64 {
            self.0.mean()
        }
        fn variance(&self) -> f64 {
            self.0.variance()
        }
        fn sample(&self, rng: &mut dyn rand::RngCore) -> f64 {
            rng.random_range(-self.0.a()..self.0.a())
        }
    }
    let err = check_distribution(&Flat(UniformSum::new(2, 0.5).unwrap()), 5).unwrap_err();
    assert!(err.contains("Kolmogorov–Smirnov"), "{err}");
}
