use super::*;
use jitterid_estimate::{ModelStructure, Record};
use jitterid_jitter::{Gaussian, TwoPoint, UniformSum};
use jitterid_signal::{simulate, LtiResponse, RandomBinary, Root, Zpk};
use rand::rngs::StdRng;
use rand::SeedableRng;
use std::cell::Cell;

thread_local! {
    /// Samples that took the 16- and the 32-point shortcut on this thread.
    static TAKEN: Cell<[usize; 2]> = const { Cell::new([0; 2]) };
}

pub(super) fn note_shortcut(points: usize) {
    TAKEN.with(|c| {
        let mut v = c.get();
        v[usize::from(points == 32)] += 1;
        c.set(v);
    });
}

#[test]
fn wide_moments_agree_with_a_rule_of_twice_the_panels() {
    // The 32 moments from the rule of WIDE_MOMENT_PANELS panels against one of twice as
    // many, and their first 16 against the narrow moments (a rule without panels).
    let jitters: Vec<Box<dyn JitterModel>> = vec![
        Box::new(UniformSum::new(0, 0.5).unwrap()),
        Box::new(UniformSum::new(1, 0.5).unwrap()),
        Box::new(UniformSum::new(3, 0.7).unwrap()),
        Box::new(UniformSum::new(9, 1.2).unwrap()),
        Box::new(Gaussian::new(0.17).unwrap()),
        Box::new(TwoPoint::new(0.3).unwrap()),
    ];
    for j in &jitters {
        let (lo, hi) = j.reach();
        let rate = WIDE_MOMENT_PANELS * MAX_RATE_WIDTH / (hi - lo);
        let wide: [f64; 32] = chebyshev_moments(&j.rule(&[], rate), lo, hi);
        let finer: [f64; 32] = chebyshev_moments(&j.rule(&[], 2.0 * rate), lo, hi);
        let narrow: [f64; CHEB_POINTS] = chebyshev_moments(&j.rule(&[], 0.0), lo, hi);
        for k in 0..32 {
            assert!(
                (wide[k] - finer[k]).abs() <= 1e-14,
                "{j:?}: μ_{k} {} vs {}",
                wide[k],
                finer[k]
            );
        }
        for k in 0..CHEB_POINTS {
            assert!(
                (wide[k] - narrow[k]).abs() <= 1e-14,
                "{j:?}: μ_{k} {} vs {}",
                wide[k],
                narrow[k]
            );
        }
    }
}

#[test]
fn both_shortcuts_agree_with_the_general_rule() {
    // The Table 1 system: long flat stretches (the 16-point shortcut), the tails of its
    // step responses (the 32-point one) and steps inside the reach (the general rule).
    let g = Zpk::new(1.0, vec![], vec![Root::Real(-2.0)]).unwrap();
    let n = 200;
    let grid = jitterid_signal::SampleGrid::new(0.0, 1.0, n).unwrap();
    let mut rng = StdRng::seed_from_u64(11);
    let u = RandomBinary::paper()
        .generate(0.0, n as f64 + 1.0, &mut rng)
        .unwrap();
    let signal = LtiResponse::new(g, u);
    check(UniformSum::new(0, 0.5).unwrap(), &signal, grid, &mut rng);
    check(UniformSum::new(3, 0.6).unwrap(), &signal, grid, &mut rng);
    check(Gaussian::new(0.17).unwrap(), &signal, grid, &mut rng);
}

/// The per-sample `log p` with and without the shortcuts, which must agree, and the
/// shortcuts must both have been taken.
fn check<J: JitterModel + Clone>(
    j: J,
    signal: &LtiResponse<Zpk>,
    grid: jitterid_signal::SampleGrid,
    rng: &mut StdRng,
) {
    let sigma = 0.01;
    let serial = |shortcut| ExactMl {
        shortcut,
        parallel: false,
        ..ExactMl::default()
    };
    let data = simulate(signal, &j, &grid, sigma, rng).unwrap();
    let record = Record::new(grid, data.y).unwrap();
    let structure = ModelStructure::oe(signal.clone(), j)
        .with_noise_std(sigma)
        .unwrap();
    TAKEN.with(|c| c.set([0; 2]));
    let fast = serial(true)
        .log_likelihoods(&structure, &record, sigma)
        .unwrap();
    let taken = TAKEN.with(Cell::get);
    let general = serial(false)
        .log_likelihoods(&structure, &record, sigma)
        .unwrap();
    let name = format!("{:?}", structure.jitter);
    // Both are accurate to about 1e-13 of p(y_k).
    for (k, (a, b)) in fast.iter().zip(&general).enumerate() {
        assert!((a - b).abs() <= 1e-11, "{name}, sample {k}: {a} vs {b}");
    }
    assert!(
        taken[0] > 0 && taken[1] > 0,
        "{name}: shortcuts taken (16, 32 points): {taken:?}"
    );
}
