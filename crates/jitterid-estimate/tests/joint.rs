//! Joint fits of several records of one system: the information of independent records adds,
//! and records of different systems are refused by name.

use jitterid_estimate::{
    check_joint, estimate_joint, fit, Bcls, EstimateError, FitOptions, MeasuredRecord,
    ModelStructure, Record,
};
use jitterid_jitter::UniformSum;
use jitterid_signal::testing::eq17;
use jitterid_signal::{simulate, Input, LtiResponse, RandomBinary, SampleGrid, Zpk};
use rand::SeedableRng;

type Structure = ModelStructure<LtiResponse<Zpk>, UniformSum>;

/// A Table 2 record of `n` samples (seed `seed`) with jitter of half-width `a`, and the OE
/// structure on its input with the noise level known, started 10 % off the truth.
fn table2(seed: u64, n: usize, a: f64) -> (Structure, MeasuredRecord) {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let u = RandomBinary::paper()
        .generate(0.0, n as f64 + 1.0, &mut rng)
        .unwrap();
    let jitter = UniformSum::new(2, a).unwrap();
    let grid = SampleGrid::new(0.0, 1.0, n).unwrap();
    let truth = LtiResponse::new(eq17(0.2, 0.5, -0.25, 0.3).unwrap(), u.clone());
    let data = simulate(&truth, &jitter, &grid, 0.01, &mut rng).unwrap();
    let start = LtiResponse::new(eq17(0.22, 0.45, -0.27, 0.33).unwrap(), u.clone());
    let record = MeasuredRecord::new(format!("seed {seed}"), Record::new(grid, data.y).unwrap())
        .with_input(Input::Piecewise(u));
    let structure = ModelStructure::oe(start, jitter)
        .with_noise_std(0.01)
        .unwrap();
    (structure, record)
}

/// `A⁻¹` of a small symmetric positive definite matrix by Gauss–Jordan elimination.
fn inverse(a: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let n = a.len();
    let mut m: Vec<Vec<f64>> = a
        .iter()
        .enumerate()
        .map(|(i, row)| {
            let mut r = row.clone();
            r.extend((0..n).map(|j| if i == j { 1.0 } else { 0.0 }));
            r
        })
        .collect();
    for c in 0..n {
        let pivot = m[c][c];
        for v in m[c].iter_mut() {
            *v /= pivot;
        }
        for r in 0..n {
            if r != c {
                let f = m[r][c];
                let row_c = m[c].clone();
                for (v, pc) in m[r].iter_mut().zip(&row_c) {
                    *v -= f * pc;
                }
            }
        }
    }
    m.into_iter().map(|r| r[n..].to_vec()).collect()
}

#[test]
fn the_joint_covariance_is_the_inverse_of_the_summed_information() {
    // Jitter far below the noise: every sample's variance is σ_v², so each record's sandwich
    // is σ_v² (JᵀJ)⁻¹ and the information of the two records adds exactly (at one θ).
    let (s1, r1) = table2(11, 200, 1e-4);
    let (s2, r2) = table2(12, 150, 1e-4);
    let options = FitOptions::default();
    let f1 = fit(&s1, r1.record(), &Bcls, &options).unwrap();
    let f2 = fit(&s2, r2.record(), &Bcls, &options).unwrap();
    let joint = estimate_joint(&[s1, s2], &[r1, r2], &Bcls, &options).unwrap();
    assert!(f1.converged && f2.converged && joint.converged);
    let c1 = f1.covariance.unwrap();
    let c2 = f2.covariance.unwrap();
    let cj = joint.covariance.unwrap();
    let (i1, i2) = (inverse(&c1), inverse(&c2));
    let summed: Vec<Vec<f64>> = i1
        .iter()
        .zip(&i2)
        .map(|(a, b)| a.iter().zip(b).map(|(x, y)| x + y).collect())
        .collect();
    let expected = inverse(&summed);
    // Each record's information is evaluated at its own estimate, the joint one at the joint
    // estimate, so the two agree to first order only (the exact identity, at one θ, is
    // `one_record_twice_halves_the_covariance_exactly`). Measured here: 1.6 % to 9.7 % larger
    // joint variances; the check allows 15 %.
    for i in 0..4 {
        let ratio = cj[i][i] / expected[i][i];
        assert!((ratio - 1.0).abs() < 0.15, "parameter {i}: ratio {ratio}");
        // More data, smaller variance than either record alone.
        assert!(cj[i][i] < c1[i][i] && cj[i][i] < c2[i][i], "parameter {i}");
    }
    // The joint estimate is the information-weighted mean of the single ones, to first order:
    // within a fifth of a joint standard error.
    let weighted: Vec<f64> = (0..4)
        .map(|i| {
            (0..4)
                .map(|j| {
                    (0..4)
                        .map(|k| {
                            expected[i][j] * (i1[j][k] * f1.params[k] + i2[j][k] * f2.params[k])
                        })
                        .sum::<f64>()
                })
                .sum()
        })
        .collect();
    for i in 0..4 {
        let se = cj[i][i].sqrt();
        assert!(
            (joint.params[i] - weighted[i]).abs() < 0.2 * se,
            "parameter {i}: joint {} vs weighted {} (se {se})",
            joint.params[i],
            weighted[i]
        );
    }
}

#[test]
fn one_record_twice_halves_the_covariance_exactly() {
    let (s1, r1) = table2(11, 200, 0.1);
    let options = FitOptions::default();
    let single = fit(&s1, r1.record(), &Bcls, &options).unwrap();
    let joint = estimate_joint(&[s1.clone(), s1], &[r1.clone(), r1], &Bcls, &options).unwrap();
    let (c1, cj) = (single.covariance.unwrap(), joint.covariance.unwrap());
    for i in 0..4 {
        // The same minimum (to the solver's tolerance) and half the covariance.
        let se = c1[i][i].sqrt();
        assert!(
            (joint.params[i] - single.params[i]).abs() < 1e-3 * se,
            "parameter {i}"
        );
        for j in 0..4 {
            let scale = (c1[i][i] * c1[j][j]).sqrt();
            assert!(
                (cj[i][j] - c1[i][j] / 2.0).abs() < 1e-3 * scale,
                "({i}, {j})"
            );
        }
    }
}

#[test]
fn records_of_different_systems_are_refused_by_name() {
    let (s1, r1) = table2(11, 200, 0.1);
    let (s2, r2) = table2(12, 150, 0.1);
    let bare = MeasuredRecord::new("no input", r2.record().clone());
    let e = check_joint(&[s1.clone(), s2.clone()], &[r1.clone(), bare]).unwrap_err();
    match &e {
        EstimateError::JointRecords { record, message } => {
            assert_eq!(record, "no input");
            assert!(message.contains("different systems"), "{message}");
        }
        other => panic!("{other:?}"),
    }
    let e = check_joint(std::slice::from_ref(&s1), &[r1.clone(), r2.clone()]).unwrap_err();
    assert!(e.to_string().contains("one structure per record"), "{e}");
    let fixed = s2.with_estimated(false, false, false);
    let e = check_joint(&[s1, fixed], &[r1, r2]).unwrap_err();
    assert!(e.to_string().contains("parameters"), "{e}");
    let none: [Structure; 0] = [];
    assert!(check_joint(&none, &[]).is_err());
}
