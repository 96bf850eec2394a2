//! The residual tests of `validate` on simulated records (the seeded small version of
//! `cargo xtask reproduce validate`): a one-pole model of 2-pole, 1-zero records is rejected,
//! and the fitted true structure of a cheap setting is rejected at the nominal rate.

use jitterid::estimate::montecarlo::run as mc_run;
use jitterid_study::experiment::{self, Experiment, Purpose};
use jitterid_study::fit::{fit_values, signal_of};
use jitterid_study::simulate::simulate_data;
use jitterid_study::validate::{check_record, RecordReport};
use jitterid_study::Watch;
use std::path::Path;

fn example(file: &str) -> Experiment {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/experiments")
        .join(file);
    experiment::read(&path, Purpose::Estimate(None)).unwrap()
}

/// Record `run` of `truth` (seed `seed`) fitted with `model` and checked at `level`.
fn checked(
    truth: &Experiment,
    model: &Experiment,
    seed: u64,
    run: u64,
    level: f64,
) -> RecordReport {
    let d = simulate_data(truth, seed, run).unwrap();
    let inputs = &d.inputs;
    let signal = signal_of(model, inputs).unwrap();
    let f = fit_values(model, signal, d.y.clone(), "record", &Watch::none()).unwrap();
    check_record(
        &f.fitted,
        &model.grid,
        &d.y,
        f.noise_std,
        inputs,
        &[],
        level,
        "record",
    )
    .unwrap()
    .0
}

/// The one-pole model leaves the second pole's and the zero's dynamics in the residuals: on
/// the study's records Ljung's S is about 200 against χ²(26), whose 99 % point is 45.6, so
/// every record is rejected.
#[test]
fn a_one_pole_model_of_two_pole_records_is_rejected() {
    let (truth, one_pole) = (
        example("validate-true.toml"),
        example("validate-one-pole.toml"),
    );
    for run in 0..4 {
        let r = checked(&truth, &one_pole, 9, run, 0.01);
        let c = r.cross_correlation.unwrap();
        assert!(!c.passed && c.p_value < 0.01, "run {run}: {c:?}");
        assert_eq!(r.removed_directions, 3, "gain, pole, jitter σ");
    }
}

/// The size of both tests on the fitted true structure in a cheap setting (the one-pole
/// model's own records, BCLS, the jitter estimated, 240 records): rejections at the 5 % level
/// must lie within 3 Monte Carlo standard errors (3 √(0.05·0.95/240) = 4.2 %) of 5 %.
#[test]
fn the_fitted_true_structure_is_rejected_at_the_nominal_rate() {
    let exp = example("validate-one-pole.toml");
    let (draws, level) = (240u64, 0.05);
    let reports = mc_run(17, 0..draws, |r, _| checked(&exp, &exp, 17, r, level));
    let se = (level * (1.0 - level) / draws as f64).sqrt();
    let rate = |f: &dyn Fn(&RecordReport) -> bool| {
        reports.iter().filter(|r| f(r)).count() as f64 / draws as f64
    };
    let white = rate(&|r| !r.whiteness.passed);
    let cross = rate(&|r| !r.cross_correlation.as_ref().unwrap().passed);
    for (what, x) in [("whiteness", white), ("cross-correlation", cross)] {
        assert!(
            (x - level).abs() < 3.0 * se,
            "{what}: rejected in {x} of records"
        );
    }
}
