//! The exact likelihood's analytic gradient in the system's parameters against central
//! differences of its value, and its independence of the number of threads.

use jitterid_estimate::Objective;
use jitterid_estimate::{ModelStructure, Record};
use jitterid_jitter::UniformSum;
use jitterid_likelihood::{ExactMl, LikelihoodObjective};
use jitterid_signal::{simulate, LtiResponse, RandomBinary, Root, SampleGrid, Signal, Zpk};
use rand::rngs::StdRng;
use rand::SeedableRng;

/// The LS-bias system `2(s+1)/((s+1)² + 4)` driven by a fast random binary input (a switch
/// every 2 s on average, so that many samples see a switch within the jitter's reach), with
/// its four parameters estimated and `σ_v` estimated too.
fn setup(samples: usize) -> (ModelStructure<LtiResponse<Zpk>, UniformSum>, Record) {
    let g = Zpk::new(
        2.0,
        vec![Root::Real(-1.0)],
        vec![Root::Pair { re: -1.0, im: 2.0 }],
    )
    .unwrap();
    let mut rng = StdRng::seed_from_u64(17);
    let u = RandomBinary::new(2.0, 0.0, 1.0)
        .unwrap()
        .generate(0.0, samples as f64 + 1.0, &mut rng)
        .unwrap();
    let signal = LtiResponse::new(g, u);
    let grid = SampleGrid::new(0.0, 1.0, samples).unwrap();
    let jitter = UniformSum::new(0, 0.35).unwrap();
    let data = simulate(&signal, &jitter, &grid, 0.01, &mut rng).unwrap();
    let record = Record::new(grid, data.y).unwrap();
    let structure = ModelStructure::oe(signal, jitter).with_estimated(true, false, false);
    (structure, record)
}

#[test]
fn system_gradient_matches_central_differences() {
    let (structure, record) = setup(150);
    let criterion = ExactMl::default();
    let objective = LikelihoodObjective::new(&structure, &criterion, &record);
    // Away from the optimum (every parameter 3 % off, σ_v 20 % high) so the gradient is large.
    let theta = [2.06, -1.03, -0.97, 2.06, 0.012];
    let (f, g) = objective.cost_gradient(&theta);
    assert!(f.is_finite());
    let scale = g.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    for j in 0..theta.len() {
        // Central differences: truncation O(h²·f''') and rounding O(ε|f|/h); with
        // h = 1e-6·|θ_j|, |f| ~ 1e3 and curvatures ~ 1e7 both stay below 1e-6 of the
        // gradient's scale (~1e4), which is the tolerance.
        let h = 1e-6 * theta[j].abs();
        let mut p = theta.to_vec();
        p[j] = theta[j] + h;
        let up = objective.cost(&p);
        p[j] = theta[j] - h;
        let down = objective.cost(&p);
        let numeric = (up - down) / (2.0 * h);
        assert!(
            (g[j] - numeric).abs() <= 1e-6 * scale,
            "∂/∂θ{j}: analytic {} vs central difference {numeric} (scale {scale})",
            g[j]
        );
    }
}

#[test]
fn value_and_gradient_are_bit_identical_for_any_thread_count() {
    let (structure, record) = setup(400);
    let criterion = ExactMl::default();
    let objective = LikelihoodObjective::new(&structure, &criterion, &record);
    let theta = [2.06, -1.03, -0.97, 2.06, 0.012];
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| (objective.cost(&theta), objective.cost_gradient(&theta)))
    };
    let (c1, (f1, g1)) = run(1);
    let (c2, (f2, g2)) = run(2);
    assert_eq!(c1.to_bits(), c2.to_bits());
    assert_eq!(f1.to_bits(), f2.to_bits());
    assert_eq!(
        c1.to_bits(),
        f1.to_bits(),
        "the value does not depend on the gradient"
    );
    let bits = |g: &[f64]| g.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&g1), bits(&g2));
    // And the serial path gives the same numbers.
    let serial = ExactMl {
        parallel: false,
        ..ExactMl::default()
    };
    let o = LikelihoodObjective::new(&structure, &serial, &record);
    let (fs, gs) = o.cost_gradient(&theta);
    assert_eq!(fs.to_bits(), f1.to_bits());
    assert_eq!(bits(&gs), bits(&g1));
}

#[test]
fn signal_value_gradient_matches_central_differences() {
    // The O(log J) gradient of the response from the step states, against differences of the
    // response itself, at instants before, on and between steps.
    let (structure, _) = setup(60);
    let signal = &structure.signal;
    let theta = signal.params();
    let mut g = vec![0.0; theta.len()];
    for k in 0..600 {
        let t = -1.0 + 0.1 * k as f64;
        signal.value_gradient(t, &mut g);
        for j in 0..theta.len() {
            let h = 1e-6 * theta[j].abs();
            let mut p = theta.clone();
            p[j] += h;
            let up = signal.with_params(&p).unwrap().value(t);
            p[j] -= 2.0 * h;
            let down = signal.with_params(&p).unwrap().value(t);
            let numeric = (up - down) / (2.0 * h);
            // Truncation O(h²) and rounding O(ε/h) of a response of size ~1: below 1e-8.
            assert!(
                (g[j] - numeric).abs() <= 1e-8 * (1.0 + numeric.abs()),
                "t = {t}, ∂s/∂θ{j}: {} vs {numeric}",
                g[j]
            );
        }
    }
}
