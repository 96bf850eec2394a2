//! Shared fixtures of the cross-crate tests (in `tests/`).

use jitterid::jitter::{
    ExponentialDelay, Gaussian, JitterModel, Laplace, NoJitter, Shifted, TwoPoint, UniformSum,
};
use jitterid::signal::{testing, LtiResponse, PiecewiseConstant, Root, Zpk};
use proptest::prelude::*;
use std::sync::Arc;

/// The paper's eq. (17) system `k0 (s + z) / ((s − pr)² + pi²)` (valid arguments only).
pub fn eq17(k0: f64, z: f64, pr: f64, pi: f64) -> Zpk {
    testing::eq17(k0, z, pr, pi).expect("valid")
}

/// A random binary input on `[start, end)` from a seed (valid arguments only).
pub fn binary(seed: u64, dwell: f64, start: f64, end: f64) -> PiecewiseConstant {
    testing::binary(seed, dwell, start, end).expect("valid")
}

/// A stable zero–pole–gain model with distinct poles.
pub fn arb_system() -> impl Strategy<Value = Zpk> {
    (
        0.1f64..3.0,
        prop::option::of(-3.0f64..3.0),
        -3.0f64..-0.1,
        prop::option::of((-2.0f64..-0.1, 0.1f64..3.0)),
    )
        .prop_filter_map("distinct poles", |(k, zero, real, pair)| {
            let zeros = zero.map(Root::Real).into_iter().collect();
            let mut poles = vec![Root::Real(real)];
            poles.extend(pair.map(|(re, im)| Root::Pair { re, im }));
            Zpk::new(k, zeros, poles).ok()
        })
}

/// A jitter model from every family, with random parameters.
pub fn arb_jitter() -> impl Strategy<Value = Arc<dyn JitterModel>> {
    prop_oneof![
        Just(Arc::new(NoJitter) as Arc<dyn JitterModel>),
        (0u32..6, 0.01f64..0.8)
            .prop_map(|(n, a)| Arc::new(UniformSum::new(n, a).unwrap()) as Arc<dyn JitterModel>),
        (0.01f64..0.3).prop_map(|s| Arc::new(Gaussian::new(s).unwrap()) as Arc<dyn JitterModel>),
        (0.01f64..0.1).prop_map(|b| Arc::new(Laplace::new(b).unwrap()) as Arc<dyn JitterModel>),
        (0.01f64..0.5).prop_map(|d| Arc::new(TwoPoint::new(d).unwrap()) as Arc<dyn JitterModel>),
        (0.01f64..0.1)
            .prop_map(|m| Arc::new(ExponentialDelay::new(m).unwrap()) as Arc<dyn JitterModel>),
        (-0.3f64..0.3, 0.01f64..0.4).prop_map(|(c, a)| {
            Arc::new(Shifted::new(UniformSum::new(1, a).unwrap(), c).unwrap())
                as Arc<dyn JitterModel>
        }),
    ]
}

/// The response of a random system to a random binary input that covers `[-2, end)`.
pub fn arb_response(end: f64) -> impl Strategy<Value = LtiResponse<Zpk>> {
    (arb_system(), any::<u64>(), 0.5f64..10.0)
        .prop_map(move |(g, seed, dwell)| LtiResponse::new(g, binary(seed, dwell, -2.0, end)))
}

/// A strictly proper stable model (fewer zeros than poles), so `s(t)` has no jumps.
pub fn arb_strict_system() -> impl Strategy<Value = Zpk> {
    (
        0.1f64..3.0,
        -3.0f64..-0.1,
        prop::option::of((-2.0f64..-0.1, 0.1f64..3.0)),
        -3.0f64..3.0,
    )
        .prop_filter_map("distinct poles", |(k, real, pair, zero)| {
            let mut poles = vec![Root::Real(real)];
            poles.extend(pair.map(|(re, im)| Root::Pair { re, im }));
            let zeros = if poles.len() > 1 {
                vec![Root::Real(zero)]
            } else {
                vec![]
            };
            Zpk::new(k, zeros, poles).ok()
        })
}

/// A jitter model with a density whose characteristic function decays at least like `1/f²`
/// (where the frequency integral of route (a) converges for a signal with kinks).
pub fn arb_smooth_jitter() -> impl Strategy<Value = Arc<dyn JitterModel>> {
    prop_oneof![
        (1u32..6, 0.05f64..0.8)
            .prop_map(|(n, a)| Arc::new(UniformSum::new(n, a).unwrap()) as Arc<dyn JitterModel>),
        (0.03f64..0.3).prop_map(|s| Arc::new(Gaussian::new(s).unwrap()) as Arc<dyn JitterModel>),
        (0.03f64..0.1).prop_map(|b| Arc::new(Laplace::new(b).unwrap()) as Arc<dyn JitterModel>),
        (-0.3f64..0.3, 0.05f64..0.4).prop_map(|(c, a)| {
            Arc::new(Shifted::new(UniformSum::new(1, a).unwrap(), c).unwrap())
                as Arc<dyn JitterModel>
        }),
    ]
}
