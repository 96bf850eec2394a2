//! Validation of fitted models: responses and their gradients against finite differences,
//! residual whiteness on true and wrong-order models, delta-method bands against the Monte
//! Carlo spread of fitted models.

use jitterid_estimate::{fit, Bcls, FitOptions, ModelStructure, Record};
use jitterid_jitter::UniformSum;
use jitterid_likelihood::validation::{
    bode, cross_correlation, default_max_lag, fit_initial_state, log_response_gradient,
    residual_projection, standardized_residuals, step_response, step_value_and_gradient, whiteness,
    DEFAULT_LEVEL,
};
use jitterid_signal::{
    simulate, Input, LtiResponse, PiecewiseConstant, RandomBinary, RationalModel, Root, SampleGrid,
    Signal, TransferFunction, WithInitialState, Zpk,
};
use rand::SeedableRng;

fn third_order() -> Zpk {
    Zpk::new(
        0.2,
        vec![Root::Real(-1.5)],
        vec![Root::Real(-0.5), Root::Pair { re: -0.25, im: 0.3 }],
    )
    .unwrap()
}

/// `∂f/∂θ_j` by central differences of `f(with_params(θ ± h e_j))`.
fn central<M: RationalModel>(model: &M, j: usize, f: impl Fn(&M) -> f64) -> f64 {
    let theta = model.params();
    let h = 1e-6 * theta[j].abs().max(1e-2);
    let at = |d: f64| {
        let mut p = theta.clone();
        p[j] += d;
        f(&model.with_params(&p).unwrap())
    };
    (at(h) - at(-h)) / (2.0 * h)
}

fn check_gradients<M: RationalModel>(model: &M) {
    for f in [0.01, 0.05, 0.2, 0.7] {
        let (_, dlog) = log_response_gradient(model, f);
        for (j, d) in dlog.iter().enumerate() {
            let s = |m: &M| {
                let g = m.frequency_response(f);
                (g.norm().ln(), g.arg())
            };
            let fd_mag = central(model, j, |m| s(m).0);
            let fd_phase = central(model, j, |m| s(m).1);
            assert!(
                (d.re - fd_mag).abs() < 1e-6 * (1.0 + fd_mag.abs()),
                "f {f} θ{j}: ln|G| {} vs {fd_mag}",
                d.re
            );
            assert!(
                (d.im - fd_phase).abs() < 1e-6 * (1.0 + fd_phase.abs()),
                "f {f} θ{j}: arg G {} vs {fd_phase}",
                d.im
            );
        }
    }
    for t in [0.0, 0.5, 3.0, 12.0] {
        let (_, grad) = step_value_and_gradient(model, t);
        for (j, g) in grad.iter().enumerate() {
            let fd = central(model, j, |m| step_value_and_gradient(m, t).0);
            assert!(
                (g - fd).abs() < 1e-6 * (1.0 + fd.abs()),
                "t {t} θ{j}: {g} vs {fd}"
            );
        }
    }
}

#[test]
fn response_gradients_match_finite_differences() {
    check_gradients(&third_order());
    check_gradients(&TransferFunction::new(&[0.5, 1.0], &[1.0, 0.8, 0.3]).unwrap());
}

#[test]
fn step_response_settles_at_the_static_gain_and_starts_at_the_feed_through() {
    let z = third_order();
    let s = step_response(&z, &[0.0, 200.0], None).unwrap();
    let g0 = z.frequency_response(0.0).re;
    assert!(
        s[0].value.abs() < 1e-12,
        "strictly proper: y(0) = 0, got {}",
        s[0].value
    );
    assert!((s[1].value - g0).abs() < 1e-9);
    // An independent route: the library's own LTI response to a unit step at 0, on [0, 10].
    let step = Input::Piecewise(
        jitterid_signal::PiecewiseConstant::new(vec![0.0, 1000.0], vec![1.0]).unwrap(),
    );
    let lti = LtiResponse::new(z.clone(), step);
    for t in [0.3, 1.0, 4.0, 9.0] {
        let v = step_response(&z, &[t], None).unwrap()[0].value;
        assert!(
            (v - lti.value(t)).abs() < 1e-10,
            "t {t}: {v} vs {}",
            lti.value(t)
        );
    }
    let b = bode(&z, &[0.0, 0.1], None).unwrap();
    assert!((b[0].magnitude_db - 20.0 * g0.abs().log10()).abs() < 1e-12);
    assert!(b[0].magnitude_db_lo.is_none());
}

struct Setup {
    grid: SampleGrid,
    jitter: UniformSum,
    noise: f64,
}

fn setup(n: usize) -> Setup {
    Setup {
        grid: SampleGrid::new(0.0, 1.0, n).unwrap(),
        jitter: UniformSum::new(2, 0.5 / 3f64.sqrt()).unwrap(),
        noise: 0.01,
    }
}

/// A record of `truth` driven by a fresh random-binary input; the input and the samples.
fn record<M: RationalModel>(
    s: &Setup,
    truth: &M,
    seed: u64,
) -> (jitterid_signal::PiecewiseConstant, Vec<f64>) {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let end = s.grid.time(s.grid.len() - 1) + 1.0;
    let u = RandomBinary::paper().generate(-5.0, end, &mut rng).unwrap();
    let sim = simulate(
        &LtiResponse::new(truth.clone(), u.clone()),
        &s.jitter,
        &s.grid,
        s.noise,
        &mut rng,
    )
    .unwrap();
    (u, sim.y)
}

/// Whiteness and cross-correlation verdicts of `model` on the record.
fn verdicts<M: RationalModel + 'static>(
    s: &Setup,
    model: M,
    u: &jitterid_signal::PiecewiseConstant,
    y: &[f64],
) -> (bool, bool) {
    let structure = ModelStructure::oe(LtiResponse::new(model, u.clone()), s.jitter);
    let e = standardized_residuals(&structure, &s.grid, y, s.noise)
        .unwrap()
        .standardized;
    let m = default_max_lag(y.len());
    let us: Vec<f64> = s.grid.times().map(|t| u.value(t)).collect();
    (
        whiteness(&e, m, 0, DEFAULT_LEVEL).unwrap().passed,
        cross_correlation(
            &e,
            &us,
            m,
            &residual_projection(&[], y.len()),
            DEFAULT_LEVEL,
        )
        .unwrap()
        .passed,
    )
}

#[test]
fn whiteness_passes_at_the_truth_and_fails_for_a_wrong_order() {
    // At the truth the standardised residuals are independent with unit variance; each test
    // fails by chance in at most 1 % of records (0.2 % for 25 independent lags), so two or
    // more failures among 10 seeds × 2 tests has probability below 2 %.
    let s = setup(400);
    let truth = third_order();
    let mut failures = 0;
    for seed in 0..10 {
        let (u, y) = record(&s, &truth, 1000 + seed);
        let (white, cross) = verdicts(&s, truth.clone(), &u, &y);
        failures += usize::from(!white) + usize::from(!cross);
    }
    assert!(failures <= 1, "{failures} false alarms in 20 tests");

    // A first-order model fitted to the same third-order data leaves structure in its
    // residuals.
    let (u, y) = record(&s, &truth, 77);
    let start = Zpk::new(0.3, vec![], vec![Root::Real(-0.4)]).unwrap();
    let structure = ModelStructure::oe(LtiResponse::new(start.clone(), u.clone()), s.jitter);
    let data = Record::new(s.grid, y.clone()).unwrap();
    let fit = fit(&structure, &data, &Bcls, &FitOptions::default()).unwrap();
    let fitted = start.with_params(&fit.params).unwrap();
    let (white, cross) = verdicts(&s, fitted, &u, &y);
    assert!(
        !(white && cross),
        "a first-order model of third-order data passed both tests"
    );
}

#[test]
fn delta_method_band_matches_the_monte_carlo_spread() {
    // 64 records of a first-order system, each fitted with BCLS; the spread of the fitted
    // 20 log10 |G(i2πf)| against the delta-method σ from each fit's covariance. The sample
    // standard deviation of 64 values has a relative standard error of 1/√(2·63) = 8.9 %;
    // the test allows 3 of them (27 %).
    let s = Setup {
        grid: SampleGrid::new(0.0, 1.0, 200).unwrap(),
        jitter: UniformSum::new(2, 0.5 / 3f64.sqrt()).unwrap(),
        noise: 0.05,
    };
    let truth = Zpk::new(0.5, vec![], vec![Root::Real(-0.5)]).unwrap();
    let f = 0.1;
    let runs = 64;
    let mut mags = Vec::new();
    let mut sigmas = Vec::new();
    for seed in 0..runs {
        let (u, y) = record(&s, &truth, 5000 + seed);
        let structure = ModelStructure::oe(LtiResponse::new(truth.clone(), u), s.jitter)
            .with_noise_std(s.noise)
            .unwrap();
        let data = Record::new(s.grid, y).unwrap();
        let fit = fit(&structure, &data, &Bcls, &FitOptions::default()).unwrap();
        assert!(fit.converged, "seed {seed}: {}", fit.termination);
        let fitted = truth.with_params(&fit.params).unwrap();
        let cov = fit.covariance.clone().unwrap();
        let b = &bode(&fitted, &[f], Some(&cov)).unwrap()[0];
        mags.push(b.magnitude_db);
        sigmas.push((b.magnitude_db_hi.unwrap() - b.magnitude_db) / 2.0);
    }
    let n = mags.len() as f64;
    let mean = mags.iter().sum::<f64>() / n;
    let spread = (mags.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    let delta = sigmas.iter().sum::<f64>() / n;
    let rel_se = 1.0 / (2.0 * (n - 1.0)).sqrt();
    assert!(
        (delta / spread - 1.0).abs() < 3.0 * rel_se,
        "delta-method σ {delta:.4} dB vs Monte Carlo spread {spread:.4} dB"
    );
}

/// A third-order response on 120 samples from an initial state `q`, under uniform-sum jitter.
fn free_response_case(q: Vec<f64>) -> (SampleGrid, WithInitialState<LtiResponse<Zpk>>, UniformSum) {
    let grid = SampleGrid::new(0.0, 1.0, 120).unwrap();
    let input =
        PiecewiseConstant::new(vec![0.0, 7.5, 23.2, 41.0, 130.0], vec![1.0, -0.5, 0.8, 0.2])
            .unwrap();
    let response = LtiResponse::new(third_order(), input);
    let signal = WithInitialState::new(response, 0.0, q).unwrap();
    (grid, signal, UniformSum::new(2, 0.4).unwrap())
}

#[test]
fn a_records_own_initial_state_is_recovered_from_its_expected_samples() {
    let q = vec![0.7, -1.1, 0.4];
    let (grid, truth, jitter) = free_response_case(q.clone());
    let y = truth.expected_values(&grid, &jitter);
    // The model as fitted on another record: same system, another state.
    let (_, other, _) = free_response_case(vec![-2.0, 0.5, 3.0]);
    let fitted = fit_initial_state(&ModelStructure::oe(other, jitter), &grid, &y).unwrap();
    let got = fitted.signal.initial();
    for (g, w) in got.iter().zip(&q) {
        assert!((g - w).abs() < 1e-9, "initial state {got:?}, truth {q:?}");
    }
    // The system's own parameters are held.
    assert_eq!(
        fitted.signal.response().model().params(),
        truth.response().model().params()
    );
}

#[test]
fn the_fitted_initial_state_minimises_the_residual_sum_of_squares() {
    let (grid, truth, jitter) = free_response_case(vec![0.7, -1.1, 0.4]);
    let mut rng = rand::rngs::StdRng::seed_from_u64(7);
    let y = simulate(&truth, &jitter, &grid, 0.05, &mut rng).unwrap().y;
    let s = ModelStructure::oe(truth.clone(), jitter);
    let fitted = fit_initial_state(&s, &grid, &y).unwrap();
    let rss = |q: &[f64]| {
        let sig = WithInitialState::new(truth.response().clone(), 0.0, q.to_vec()).unwrap();
        let m = sig.expected_values(&grid, &s.jitter);
        y.iter().zip(&m).map(|(y, m)| (y - m).powi(2)).sum::<f64>()
    };
    let q = fitted.signal.initial().to_vec();
    let best = rss(&q);
    // Any step away from the least-squares state raises the sum (the normal equations are
    // well conditioned: every mode is visible over the first 20 samples).
    for j in 0..q.len() {
        for h in [-1e-3, 1e-3] {
            let mut p = q.clone();
            p[j] += h;
            assert!(rss(&p) > best, "q_{j} {h:+}: {} ≤ {best}", rss(&p));
        }
    }
}

#[test]
fn a_signal_without_a_free_response_is_returned_unchanged() {
    let (grid, truth, jitter) = free_response_case(vec![0.7, -1.1, 0.4]);
    let s = ModelStructure::oe(truth.response().clone(), jitter);
    let y = s.signal.expected_values(&grid, &s.jitter);
    assert_eq!(fit_initial_state(&s, &grid, &y).unwrap(), s);
    assert!(matches!(
        fit_initial_state(&s, &grid, &y[1..]),
        Err(jitterid_estimate::EstimateError::DataLength { .. })
    ));
}

#[test]
fn a_delay_turns_the_phase_and_shifts_the_step_and_bad_delays_are_named() {
    use jitterid_likelihood::validation::{delayed_bode, delayed_step_response};
    let g = third_order();
    let p = g.params().len();
    let freqs = [0.01, 0.1, 0.3];
    let plain = bode(&g, &freqs, None).unwrap();
    let late = delayed_bode(&g, 2.5, &freqs, None).unwrap();
    for (a, b) in late.iter().zip(&plain) {
        assert!((a.phase_deg - (b.phase_deg - 360.0 * a.f_hz * 2.5)).abs() < 1e-9);
        assert_eq!(a.magnitude_db, b.magnitude_db);
    }
    // With the delay's variance alone the phase band is ±2 · 360 f σ_D and the magnitude has
    // none.
    let mut c = vec![vec![0.0; p + 1]; p + 1];
    c[p][p] = 0.04;
    for q in delayed_bode(&g, 2.5, &freqs, Some(&c)).unwrap() {
        let half = q.phase_deg_hi.unwrap() - q.phase_deg;
        assert!((half - 2.0 * 360.0 * q.f_hz * 0.2).abs() < 1e-9, "{q:?}");
        assert_eq!(q.magnitude_db_hi, Some(q.magnitude_db));
    }
    let times = [0.0, 1.0, 2.5, 4.0, 9.0];
    let shifted = delayed_step_response(&g, 2.5, &times, None).unwrap();
    let own = step_response(&g, &[0.0, 1.5, 6.5], None).unwrap();
    assert_eq!((shifted[0].value, shifted[1].value), (0.0, 0.0));
    for (a, b) in shifted[2..].iter().zip(&own) {
        assert!((a.value - b.value).abs() < 1e-12);
    }
    for bad in [-1.0, f64::NAN] {
        assert!(matches!(
            delayed_bode(&g, bad, &freqs, None),
            Err(jitterid_estimate::EstimateError::BadArgument { name: "delay", .. })
        ));
        assert!(delayed_step_response(&g, bad, &times, None).is_err());
    }
    // A covariance without the delay's row is refused, not read as G's alone.
    let short = vec![vec![0.0; p]; p];
    assert!(delayed_bode(&g, 2.5, &freqs, Some(&short)).is_err());
}
