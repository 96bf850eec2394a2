//! The first moment two ways: route (a), the literal frequency-domain integral (14b), against
//! route (b), the DTFT of `m_k = E[s(t_k + τ)]`.

mod common;

use common::{ExpPulse, GaussPulse, Sum, Tones};
use jitterid_jitter::{Gaussian, JitterModel, NoJitter, Shifted, UniformSum};
use jitterid_signal::{
    LtiResponse, PiecewiseConstant, SampleGrid, Signal, Spectrum, TransferFunction,
};
use jitterid_window::{
    dtft, first_moment, first_moment_integral, DirichletWindow, FrequencySet, HannWindow,
    IntegralOptions, Window, WindowError,
};
use proptest::prelude::*;

/// Checks |a − b| ≤ bound_a + 1e-13·scale at every frequency (the second term is route (b)'s
/// own quadrature and rounding error) and returns the largest |a − b| / scale.
fn compare<S: Spectrum + ?Sized>(
    label: &str,
    signal: &S,
    jitter: &dyn JitterModel,
    grid: &SampleGrid,
    window: &dyn Window,
    freqs: &FrequencySet,
    options: &IntegralOptions,
) -> f64 {
    let b = first_moment(signal, jitter, grid, window, freqs);
    let a = first_moment_integral(signal, jitter, grid, window, freqs, options)
        .unwrap_or_else(|e| panic!("{label}: {e}"));
    let scale = b.iter().fold(0.0_f64, |m, z| m.max(z.norm()));
    assert!(scale > 0.0, "{label}: zero moment");
    let mut worst = 0.0_f64;
    for (j, ((x, y), bound)) in a.values.iter().zip(&b).zip(&a.error_bounds).enumerate() {
        let d = (x - y).norm();
        assert!(
            d <= bound + 1e-13 * scale,
            "{label}, f = {}: route (a) {x} vs route (b) {y}, |diff| {d:e} > bound {bound:e}",
            freqs.frequencies()[j]
        );
        assert!(*bound <= options.rel_tol * scale * (1.0 + 1e-9) + options.abs_tol);
        worst = worst.max(d / scale);
    }
    worst
}

fn grids(n: usize) -> [SampleGrid; 2] {
    [
        SampleGrid::new(0.0, 1.0, n).unwrap(),
        SampleGrid::new(3.7, 1.0, n).unwrap(),
    ]
}

fn off_grid(grid: &SampleGrid) -> FrequencySet {
    FrequencySet::list(grid, vec![0.0, 0.013, 0.1234, 0.25, 0.3777, 0.5, 0.9]).unwrap()
}

#[test]
fn routes_agree_with_uniform_sum_jitter_on_a_pulse_with_jumps() {
    // |S_c γ| ~ |ψ|^-4 for n = 2: the tail needs ~2000 aliases for 1e-9.
    let jitter = UniformSum::new(2, 0.5 / 3f64.sqrt()).unwrap();
    let options = IntegralOptions {
        rel_tol: 1e-9,
        ..IntegralOptions::default()
    };
    let mut worst = 0.0_f64;
    for grid in grids(64) {
        let pulse = ExpPulse {
            alpha: 0.15,
            start: grid.start() + 5.0, // on a sample: the jump is smoothed by the jitter
            len: 30.25,
        };
        for window in [&DirichletWindow as &dyn Window, &HannWindow] {
            for freqs in [FrequencySet::dft(&grid), off_grid(&grid)] {
                worst = worst.max(compare(
                    "uniform-sum n=2, pulse",
                    &pulse,
                    &jitter,
                    &grid,
                    window,
                    &freqs,
                    &options,
                ));
            }
        }
    }
    // Observed: largest |a − b| ≈ 1.1e-14 · max|μ_Y|, while route (a) reports bounds up to
    // 7.6e-10 · max|μ_Y| (M = 1024–2048 aliases, Q = 256): the tail estimate is pessimistic.
    assert!(worst < 1e-9, "{worst:e}");
}

#[test]
fn routes_agree_with_gaussian_jitter() {
    let jitter = Gaussian::new(0.1).unwrap();
    let options = IntegralOptions::default();
    let mut worst = 0.0_f64;
    for grid in grids(64) {
        let pulse = ExpPulse {
            alpha: 0.3,
            start: grid.start() + 2.5,
            len: 40.0,
        };
        let tones = Tones {
            tones: vec![(0.7, 0.21, 0.3), (0.2, 1.37, -1.0)],
        };
        let both = Sum(pulse.clone(), tones.clone());
        for window in [&DirichletWindow as &dyn Window, &HannWindow] {
            for freqs in [FrequencySet::dft(&grid), off_grid(&grid)] {
                worst = worst.max(compare(
                    "gaussian, pulse",
                    &pulse,
                    &jitter,
                    &grid,
                    window,
                    &freqs,
                    &options,
                ));
                worst = worst.max(compare(
                    "gaussian, pulse + tones",
                    &both,
                    &jitter,
                    &grid,
                    window,
                    &freqs,
                    &options,
                ));
            }
        }
    }
    // Observed: largest |a − b| ≈ 1.9e-14 · max|μ_Y| (M = 32, Q = 256, bounds ≤ 1.6e-13).
    assert!(worst < 1e-10, "{worst:e}");
}

#[test]
fn routes_agree_without_jitter_on_smooth_signals_and_lines() {
    // Without jitter the integral only converges absolutely for spectra decaying faster than
    // 1/ψ: a smooth pulse and pure lines.
    let jitter = NoJitter::new();
    let options = IntegralOptions::default();
    let mut worst = 0.0_f64;
    for grid in grids(64) {
        let pulse = GaussPulse {
            amplitude: 1.3,
            centre: grid.start() + 20.3,
            width: 4.0,
        };
        let tones = Tones {
            tones: vec![(1.0, 0.1, 0.0), (0.5, 0.333, 2.0), (0.1, 1.6, 0.0)],
        };
        for window in [&DirichletWindow as &dyn Window, &HannWindow] {
            for freqs in [FrequencySet::dft(&grid), off_grid(&grid)] {
                worst = worst.max(compare(
                    "no jitter, gauss pulse",
                    &pulse,
                    &jitter,
                    &grid,
                    window,
                    &freqs,
                    &options,
                ));
                worst = worst.max(compare(
                    "no jitter, tones",
                    &tones,
                    &jitter,
                    &grid,
                    window,
                    &freqs,
                    &options,
                ));
            }
        }
    }
    // Observed: largest |a − b| ≈ 3.6e-15 · max|μ_Y| (the Gaussian spectrum needs no alias).
    assert!(worst < 1e-10, "{worst:e}");
}

#[test]
fn routes_agree_with_wider_uniform_sum_jitter() {
    // n = 4 (|γ| ~ |ψ|^-5), a = 0.5 T, on a pulse that starts before the record and ends after
    // it, with the default 1e-10 target.
    let jitter = UniformSum::new(4, 0.5).unwrap();
    let options = IntegralOptions::default();
    let grid = SampleGrid::new(-2.3, 0.5, 100).unwrap();
    let pulse = ExpPulse {
        alpha: 0.05,
        start: -10.0,
        len: 70.0,
    };
    let mut worst = 0.0_f64;
    for window in [&DirichletWindow as &dyn Window, &HannWindow] {
        for freqs in [FrequencySet::dft(&grid), off_grid(&grid)] {
            worst = worst.max(compare(
                "uniform-sum n=4, long pulse",
                &pulse,
                &jitter,
                &grid,
                window,
                &freqs,
                &options,
            ));
        }
    }
    // Observed: largest |a − b| ≈ 5.1e-15 · max|μ_Y| (M = 64, Q = 400, bounds ≤ 1.1e-11).
    assert!(worst < 1e-10, "{worst:e}");
}

#[test]
fn without_jitter_route_b_is_the_dtft_of_the_samples() {
    let jitter = NoJitter::new();
    for grid in grids(50) {
        let pulse = ExpPulse {
            alpha: 0.2,
            start: grid.start() + 3.0, // a sample sits on the jump: s(t) there is 1
            len: 20.0,
        };
        let s: Vec<f64> = grid.times().map(|t| pulse.value(t)).collect();
        for freqs in [FrequencySet::dft(&grid), off_grid(&grid)] {
            let b = first_moment(&pulse, &jitter, &grid, &DirichletWindow, &freqs);
            let d = dtft(&grid, &s, None, freqs.frequencies()).unwrap();
            for (x, y) in b.iter().zip(&d) {
                assert!((x - y).norm() <= 1e-13, "{x} vs {y}");
            }
            let w = HannWindow.weights(grid.len());
            let b = first_moment(&pulse, &jitter, &grid, &HannWindow, &freqs);
            let d = dtft(&grid, &s, Some(&w), freqs.frequencies()).unwrap();
            for (x, y) in b.iter().zip(&d) {
                assert!((x - y).norm() <= 1e-13, "{x} vs {y}");
            }
        }
    }
}

#[test]
fn the_start_time_enters_as_exp_i2pi_psi_t0() {
    // A single line c e^{i2πf1 t} with no jitter: μ_Y(f) = c e^{i2πf1 t0} Γ_N(f − f1).
    let f1 = 0.2;
    let tones = Tones {
        tones: vec![(2.0, f1, 0.0)],
    };
    let grid = SampleGrid::new(1.25, 1.0, 16).unwrap();
    let freqs = FrequencySet::list(&grid, vec![f1]).unwrap();
    let a = first_moment_integral(
        &tones,
        &NoJitter::new(),
        &grid,
        &DirichletWindow,
        &freqs,
        &IntegralOptions::default(),
    )
    .unwrap();
    let b = first_moment(&tones, &NoJitter::new(), &grid, &DirichletWindow, &freqs);
    // The +f1 line gives 16 e^{i2π 0.2 1.25} = 16 e^{iπ/2} = 16i; the −f1 line adds
    // e^{-iπ/2} Γ_16(0.4), small.
    let minus = num_complex::Complex64::from_polar(1.0, -std::f64::consts::FRAC_PI_2)
        * jitterid_window::dirichlet(&grid, 2.0 * f1);
    let want = num_complex::Complex64::new(0.0, 16.0) + minus;
    assert!((a.values[0] - want).norm() < 1e-12, "{}", a.values[0]);
    assert!((b[0] - want).norm() < 1e-12, "{}", b[0]);
}

#[test]
fn jumps_without_jitter_are_reported_not_converged() {
    let grid = SampleGrid::new(0.0, 1.0, 32).unwrap();
    let pulse = ExpPulse {
        alpha: 0.2,
        start: 3.5,
        len: 10.0,
    };
    let options = IntegralOptions {
        max_aliases: 256,
        ..IntegralOptions::default()
    };
    let err = first_moment_integral(
        &pulse,
        &NoJitter::new(),
        &grid,
        &DirichletWindow,
        &FrequencySet::dft(&grid),
        &options,
    )
    .unwrap_err();
    match err {
        WindowError::NotConverged {
            error_bound,
            target,
            aliases,
            ..
        } => {
            assert!(error_bound > target);
            assert_eq!(aliases, 256);
        }
        other => panic!("unexpected {other}"),
    }
}

#[test]
fn invalid_options_are_rejected() {
    let grid = SampleGrid::new(0.0, 1.0, 8).unwrap();
    let options = IntegralOptions {
        rel_tol: f64::NAN,
        ..IntegralOptions::default()
    };
    let r = first_moment_integral(
        &Tones { tones: vec![] },
        &NoJitter::new(),
        &grid,
        &DirichletWindow,
        &FrequencySet::dft(&grid),
        &options,
    );
    assert!(matches!(
        r,
        Err(WindowError::InvalidOption {
            name: "rel_tol",
            ..
        })
    ));
}

#[test]
fn routes_agree_with_asymmetric_jitter() {
    // A shifted Gaussian has a complex γ: this checks γ(-ψ) (not γ(ψ)) in eq. (14b).
    let jitter = Shifted::new(Gaussian::new(0.1).unwrap(), 0.3).unwrap();
    let options = IntegralOptions::default();
    let mut worst = 0.0_f64;
    for grid in grids(48) {
        let both = Sum(
            ExpPulse {
                alpha: 0.2,
                start: grid.start() + 4.0,
                len: 25.0,
            },
            Tones {
                tones: vec![(0.5, 0.17, 1.0)],
            },
        );
        for window in [&DirichletWindow as &dyn Window, &HannWindow] {
            for freqs in [FrequencySet::dft(&grid), off_grid(&grid)] {
                worst = worst.max(compare(
                    "shifted gaussian, pulse + tone",
                    &both,
                    &jitter,
                    &grid,
                    window,
                    &freqs,
                    &options,
                ));
            }
        }
    }
    // Observed: largest |a − b| ≈ 2.8e-15 · max|μ_Y|.
    assert!(worst < 1e-10, "{worst:e}");
}

/// The paper's Table-2 setting: `G(s) = 0.2 (s + 0.5) / ((s + 0.25)² + 0.3²)`, a 0/1 input with
/// 25 switches, `N = 200`, `T = 1`, uniform-sum jitter `n = 2`, `a = 1/(2√3)`, the 101 default
/// frequencies.
#[test]
fn routes_agree_on_the_table_2_case() {
    let model = TransferFunction::new(&[0.2, 0.1], &[1.0, 0.5, 0.1525]).unwrap();
    let mut edges = vec![0.0];
    let mut t = 0.0;
    for j in 0..25 {
        t += 3.1 + 7.7 * ((j * 7 % 11) as f64 / 11.0);
        edges.push(t);
    }
    edges.push(200.0);
    let levels: Vec<f64> = (0..edges.len() - 1).map(|j| (j % 2) as f64).collect();
    let input = PiecewiseConstant::new(edges, levels).unwrap();
    let signal = LtiResponse::new(model, input);
    let jitter = UniformSum::new(2, 0.5 / 3f64.sqrt()).unwrap();
    let grid = SampleGrid::new(0.0, 1.0, 200).unwrap();
    let freqs = FrequencySet::dft(&grid);
    let worst = compare(
        "table 2",
        &signal,
        &jitter,
        &grid,
        &DirichletWindow,
        &freqs,
        &IntegralOptions::default(),
    );
    // Observed: largest |a − b| ≈ 1.6e-14 · max|μ_Y|, bounds ≤ 8.7e-12 · max|μ_Y|, with
    // M = 256 aliases and Q = 800 intervals. The cost of route (a) is timed by
    // `cargo bench -p jitterid --bench table2`, not here.
    assert!(worst < 1e-10, "{worst:e}");
}

proptest! {
    // Fixed seed and no persistence: the same cases on every run (CI must not depend on luck).
    #![proptest_config(ProptestConfig {
        cases: 8,
        failure_persistence: None,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x6d6f6d65),
        ..ProptestConfig::default()
    })]

    #[test]
    fn routes_agree_on_random_pulses(
        t0 in -5.0f64..5.0,
        t in 0.2f64..2.0,
        sigma in 0.05f64..0.5,
        alpha in 0.05f64..1.0,
        offset in -3.0f64..10.0,
        len in 1.0f64..30.0,
        hann in any::<bool>(),
    ) {
        let grid = SampleGrid::new(t0, t, 32).unwrap();
        let jitter = Gaussian::new(sigma * t).unwrap();
        let pulse = ExpPulse { alpha: alpha / t, start: t0 + offset * t, len: len * t };
        let window: &dyn Window = if hann { &HannWindow } else { &DirichletWindow };
        let worst = compare(
            "random pulse",
            &pulse,
            &jitter,
            &grid,
            window,
            &FrequencySet::dft(&grid),
            &IntegralOptions::default(),
        );
        prop_assert!(worst < 1e-10);
    }
}

/// An output offset `y₀` is a line at `f = 0`: route (a) takes it in closed form
/// (`y₀ γ(0) Γ_N(f)`), route (b) as `y₀ + m_k`; they agree on and off the DFT grid, and on the
/// DFT grid the offset moves only the bin `f = 0`, by `N y₀`.
#[test]
fn routes_agree_on_an_output_offset() {
    let jitter = Gaussian::new(0.1).unwrap();
    let options = IntegralOptions::default();
    for grid in grids(64) {
        let pulse = ExpPulse {
            alpha: 0.3,
            start: grid.start() + 2.5,
            len: 40.0,
        };
        let y0 = 0.75;
        let moved = jitterid_signal::Offset::new(pulse.clone(), y0, true).unwrap();
        for freqs in [FrequencySet::dft(&grid), off_grid(&grid)] {
            let worst = compare(
                "gaussian, pulse + offset",
                &moved,
                &jitter,
                &grid,
                &DirichletWindow,
                &freqs,
                &options,
            );
            assert!(worst < 1e-10, "{worst:e}");
        }
        let dft = FrequencySet::dft(&grid);
        let with = first_moment(&moved, &jitter, &grid, &DirichletWindow, &dft);
        let without = first_moment(&pulse, &jitter, &grid, &DirichletWindow, &dft);
        let n = grid.len() as f64;
        for (j, (a, b)) in with.iter().zip(&without).enumerate() {
            let want = if j == 0 { n * y0 } else { 0.0 };
            assert!(((a - b).re - want).abs() < 1e-12 * n && (a - b).im.abs() < 1e-12 * n);
        }
    }
}
