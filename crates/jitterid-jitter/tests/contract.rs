//! Every built-in family against the full contract of `testing::check_contract`.

use jitterid_jitter::testing::{check_closed_forms, check_contract};
use jitterid_jitter::{
    ExponentialDelay, Gaussian, JitterModel, Laplace, NoJitter, Shifted, TwoPoint, UniformSum,
};
use proptest::prelude::*;
use proptest::test_runner::RngSeed;

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
