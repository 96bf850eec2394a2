//! A grey-box fit in physical parameters is the coefficient fit mapped to them: the
//! mass–spring–damper `1/(m s² + damp s + k)` fitted by BCLS as a grey-box state-space model
//! (`m, damp, k`) and as a transfer function `b0/(s² + a1 s + a0)` on the same seeded
//! records. The map `(b0, a1, a0) = (1/m, damp/m, k/m)` is one-to-one, so both searches find
//! the same model: the grey-box estimate equals the mapped coefficient estimate to the
//! optimiser's tolerance, and its standard errors equal the coefficient fit's carried through
//! the map's Jacobian (the delta method is exact for a reparameterisation at one optimum).

use jitterid_estimate::montecarlo::realization_rng;
use jitterid_estimate::{fit, Bcls, Fit, FitOptions, ModelStructure, Record};
use jitterid_jitter::UniformSum;
use jitterid_signal::greybox::{ExprModel, GreyBox};
use jitterid_signal::testing::mass_spring_damper;
use jitterid_signal::{simulate, LtiResponse, RandomBinary, SampleGrid, TransferFunction};
use rand::rngs::StdRng;
use rand::Rng;

const SEED: u64 = 20_261_128;
const TRUTH: [f64; 3] = [1.0, 0.4, 2.0];

fn model() -> ExprModel {
    mass_spring_damper()
}

fn jitter() -> UniformSum {
    UniformSum::new(2, 0.25).expect("jitter")
}

#[test]
fn greybox_fit_is_the_coefficient_fit_mapped_to_physical_parameters() {
    for r in 0..4 {
        let mut rng: StdRng = realization_rng(SEED, r);
        let u = RandomBinary::new(4.0, 0.0, 1.0)
            .and_then(|b| b.generate(0.0, 201.0, &mut rng))
            .expect("input");
        let grid = SampleGrid::new(0.0, 0.5, 400).expect("grid");
        let truth = GreyBox::new(model(), TRUTH.to_vec(), u.clone()).expect("truth");
        let y = simulate(&truth, &jitter(), &grid, 0.01, &mut rng)
            .expect("simulate")
            .y;
        let record = Record::new(grid, y).expect("record");
        let start: Vec<f64> = TRUTH
            .iter()
            .map(|x| x * (1.0 + rng.random_range(-0.2..=0.2)))
            .collect();
        let [m, damp, k] = [start[0], start[1], start[2]];
        let options = FitOptions::default();
        let grey: Fit = fit(
            &ModelStructure::oe(
                GreyBox::new(model(), start.clone(), u.clone()).expect("start"),
                jitter(),
            ),
            &record,
            &Bcls,
            &options,
        )
        .expect("grey-box fit");
        let tf = TransferFunction::new(&[1.0 / m], &[1.0, damp / m, k / m]).expect("tf start");
        let coef: Fit = fit(
            &ModelStructure::oe(LtiResponse::new(tf, u), jitter()),
            &record,
            &Bcls,
            &options,
        )
        .expect("tf fit");
        assert!(grey.converged && coef.converged, "record {r}");
        assert_eq!(grey.names, ["m", "damp", "k"]);
        let [b0, a1, a0] = [coef.params[0], coef.params[1], coef.params[2]];
        let mapped = [1.0 / b0, a1 / b0, a0 / b0];
        for (i, want) in mapped.iter().enumerate() {
            let rel = (grey.params[i] - want).abs() / want;
            assert!(
                rel < 1e-5,
                "record {r}, {}: {} vs {}",
                grey.names[i],
                grey.params[i],
                want
            );
        }
        // The delta method: Σ_θ = J Σ_c Jᵀ with J = ∂(m, damp, k)/∂(b0, a1, a0).
        let jac = [
            [-1.0 / (b0 * b0), 0.0, 0.0],
            [-a1 / (b0 * b0), 1.0 / b0, 0.0],
            [-a0 / (b0 * b0), 0.0, 1.0 / b0],
        ];
        let cov = coef.covariance.as_ref().expect("tf covariance");
        let se = grey.std_errors.as_ref().expect("grey-box standard errors");
        for (i, row) in jac.iter().enumerate() {
            let var: f64 = (0..3)
                .flat_map(|a| (0..3).map(move |b| (a, b)))
                .map(|(a, b)| row[a] * cov[a][b] * row[b])
                .sum();
            let rel = (se[i] - var.sqrt()).abs() / var.sqrt();
            assert!(
                rel < 1e-3,
                "record {r}, se of {}: {} vs {}",
                grey.names[i],
                se[i],
                var.sqrt()
            );
        }
    }
}
