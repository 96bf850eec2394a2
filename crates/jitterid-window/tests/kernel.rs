//! Kernels: the Dirichlet closed form against the direct sum, the Hann closed form against
//! `Σ w_k e^{-i2πνkT}`.

mod common;

use common::reference_dtft;
use jitterid_signal::SampleGrid;
use jitterid_window::{dirichlet, DirichletWindow, HannWindow, Window};
use num_complex::Complex64;
use proptest::prelude::*;
use rand::{rngs::StdRng, Rng, SeedableRng};

fn direct_dirichlet(n: usize, t: f64, nu: f64) -> Complex64 {
    reference_dtft(&vec![1.0; n], nu, t)
}

/// The generic `O(N)` kernel of a window, bypassing any closed form.
#[derive(Debug)]
struct Generic<W>(W);
impl<W: Window> Window for Generic<W> {
    fn weight(&self, k: usize, n: usize) -> f64 {
        self.0.weight(k, n)
    }
}

#[test]
fn dirichlet_is_exactly_n_at_multiples_of_the_sampling_rate() {
    for &(n, t) in &[(1, 1.0), (2, 0.5), (200, 1.0), (1000, 0.25), (12345, 2.0)] {
        let grid = SampleGrid::new(0.0, t, n).unwrap();
        for m in [-3i32, 0, 1, 7, 1000] {
            let nu = m as f64 / t; // exact for these T
            let k = dirichlet(&grid, nu);
            assert_eq!(k, Complex64::new(n as f64, 0.0), "N={n} T={t} m={m}");
        }
    }
}

#[test]
fn dirichlet_matches_the_direct_sum_at_random_frequencies() {
    let mut rng = StdRng::seed_from_u64(7);
    for _ in 0..200 {
        let n = rng.random_range(1..3000usize);
        let t = rng.random_range(0.01..3.0);
        let grid = SampleGrid::new(rng.random_range(-5.0..5.0), t, n).unwrap();
        let nu = rng.random_range(-20.0..20.0) / t;
        let a = dirichlet(&grid, nu);
        let b = direct_dirichlet(n, t, nu);
        assert!(
            (a - b).norm() <= 1e-12 * n as f64,
            "N={n} T={t} ν={nu}: {a} vs {b}"
        );
    }
}

#[test]
fn dirichlet_is_accurate_near_multiples_of_the_sampling_rate() {
    // T = 0.1 is not exact in binary, so m/T is close to, not at, a multiple; and explicit
    // offsets from 1e-300 up to 1e-3 of the bin width straddle the series threshold.
    for &(n, t) in &[(7usize, 0.1), (200, 1.0), (4096, 0.3)] {
        let grid = SampleGrid::new(1.5, t, n).unwrap();
        for m in [-2i32, 0, 1, 5] {
            let centre = m as f64 / t;
            for off in [
                0.0, 1e-300, 1e-200, 1e-15, 1e-12, 1e-9, 3e-7, 1e-6, 1e-5, 1e-4, 1e-3,
            ] {
                for sign in [1.0, -1.0] {
                    let nu = centre + sign * off / (n as f64 * t);
                    let a = dirichlet(&grid, nu);
                    let b = direct_dirichlet(n, t, nu);
                    assert!(
                        (a - b).norm() <= 1e-12 * n as f64,
                        "N={n} T={t} m={m} off={off}: {a} vs {b}"
                    );
                    assert!(a.re.is_finite() && a.im.is_finite());
                }
            }
        }
    }
}

#[test]
fn dirichlet_window_kernel_is_the_closed_form_and_generic_agrees() {
    let grid = SampleGrid::new(0.0, 0.5, 333).unwrap();
    for nu in [0.0, 0.013, 0.77, 1.999_999, 2.0, -3.1] {
        let a = DirichletWindow.kernel(&grid, nu);
        assert_eq!(a, dirichlet(&grid, nu));
        let b = Generic(DirichletWindow).kernel(&grid, nu);
        assert!((a - b).norm() <= 1e-12 * 333.0, "ν={nu}: {a} vs {b}");
    }
    assert!(DirichletWindow.is_rectangular());
    assert!(!HannWindow.is_rectangular());
    assert!(!Generic(DirichletWindow).is_rectangular());
}

#[test]
fn non_finite_frequency_gives_nan_not_a_panic() {
    let grid = SampleGrid::new(0.0, 1.0, 10).unwrap();
    assert!(dirichlet(&grid, f64::NAN).re.is_nan());
    assert!(HannWindow.kernel(&grid, f64::INFINITY).re.is_nan());
    assert!(Generic(HannWindow).kernel(&grid, f64::NAN).re.is_nan());
}

#[test]
fn hann_weights_are_the_periodic_variant() {
    let w = HannWindow.weights(8);
    let expect = [
        0.0,
        0.146_446_609_406_726_24,
        0.5,
        0.853_553_390_593_273_8,
        1.0,
    ];
    for (k, e) in expect.iter().enumerate() {
        assert!((w[k] - e).abs() < 1e-15, "w[{k}] = {}", w[k]);
        if k > 0 {
            assert!((w[8 - k] - e).abs() < 1e-15);
        }
    }
    assert_eq!(HannWindow.weight(8, 8), 0.0);
    assert_eq!(HannWindow.weights(1), vec![0.0]);
    assert!(HannWindow.weights(0).is_empty());
}

#[test]
fn hann_kernel_matches_the_weighted_sum() {
    let mut rng = StdRng::seed_from_u64(11);
    for _ in 0..200 {
        let n = rng.random_range(1..2000usize);
        let t = rng.random_range(0.05..2.0);
        let grid = SampleGrid::new(0.0, t, n).unwrap();
        let nu = if rng.random_bool(0.3) {
            // on or next to the DFT grid, where the shifted kernels hit their peaks
            rng.random_range(0..n) as f64 / (n as f64 * t)
        } else {
            rng.random_range(-10.0..10.0) / t
        };
        let a = HannWindow.kernel(&grid, nu);
        let b = reference_dtft(&HannWindow.weights(n), nu, t);
        let c = Generic(HannWindow).kernel(&grid, nu);
        assert!(
            (a - b).norm() <= 1e-12 * n as f64,
            "N={n} ν={nu}: {a} vs {b}"
        );
        assert!(
            (c - b).norm() <= 1e-12 * n as f64,
            "N={n} ν={nu}: {c} vs {b}"
        );
    }
}

proptest! {
    // Fixed seed and no persistence: the same cases on every run (CI must not depend on luck).
    #![proptest_config(ProptestConfig {
        cases: 64,
        failure_persistence: None,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x6b65726e),
        ..ProptestConfig::default()
    })]

    #[test]
    fn dirichlet_is_periodic_and_bounded(
        n in 1usize..500,
        t in 0.01f64..10.0,
        x in -3.0f64..3.0,
        m in -5i32..5,
    ) {
        let grid = SampleGrid::new(0.0, t, n).unwrap();
        let nu = x / t;
        let a = dirichlet(&grid, nu);
        let b = dirichlet(&grid, nu + m as f64 / t);
        prop_assert!(a.norm() <= n as f64 * (1.0 + 1e-14));
        prop_assert!((a - b).norm() <= 1e-12 * n as f64);
        let c = direct_dirichlet(n, t, nu);
        prop_assert!((a - c).norm() <= 1e-12 * n as f64);
    }
}

/// Options read with serde go through the same validation as `first_moment_integral`, and no
/// JSON value makes a read of a window-crate type panic.
#[test]
fn deserialized_options_are_validated() {
    use jitterid_window::{DirichletWindow, HannWindow, IntegralOptions};
    let ok = serde_json::json!({"rel_tol": 1e-10, "abs_tol": 0.0, "max_aliases": 8, "max_refinements": 2});
    assert!(serde_json::from_value::<IntegralOptions>(ok).is_ok());
    for bad in [
        serde_json::json!({"rel_tol": -1.0, "abs_tol": 0.0, "max_aliases": 8, "max_refinements": 2}),
        serde_json::json!({"rel_tol": 0.0, "abs_tol": 0.0, "max_aliases": 8, "max_refinements": 2}),
        serde_json::json!({"rel_tol": 1e-10, "abs_tol": 0.0, "max_aliases": 0, "max_refinements": 2}),
        serde_json::json!({"rel_tol": "x"}),
        serde_json::json!([1, 2]),
    ] {
        assert!(
            serde_json::from_value::<IntegralOptions>(bad.clone()).is_err(),
            "{bad}"
        );
        let _ = serde_json::from_value::<DirichletWindow>(bad.clone());
        let _ = serde_json::from_value::<HannWindow>(bad);
    }
}
