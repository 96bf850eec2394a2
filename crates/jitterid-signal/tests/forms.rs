//! Conversions between the export forms: round trips (property tests) and an independent
//! check of the state-space transfer function through `C (sI − A)⁻¹ B + D`.

use jitterid_signal::forms::{StateSpace, TfForm, ZpkForm};
use jitterid_signal::{RationalModel, Root, Zpk};
use num_complex::Complex64;
use proptest::prelude::*;

fn close(a: &[f64], b: &[f64], tol: f64) -> bool {
    let scale = a.iter().chain(b).fold(1.0_f64, |m, x| m.max(x.abs()));
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol * scale)
}

/// Conjugate-closed roots: `real` real ones and `pairs` pairs, each in a box around the origin.
fn roots(real: Vec<f64>, pairs: Vec<(f64, f64)>) -> Vec<Complex64> {
    let mut r: Vec<Complex64> = real.into_iter().map(|x| Complex64::new(x, 0.0)).collect();
    for (re, im) in pairs {
        r.push(Complex64::new(re, im));
        r.push(Complex64::new(re, -im));
    }
    r
}

/// Every root of `want` is matched by a distinct root of `got` within `tol`.
fn same_roots(got: &[Complex64], want: &[Complex64], tol: f64) -> bool {
    let mut used = vec![false; got.len()];
    got.len() == want.len()
        && want.iter().all(|w| {
            let hit = (0..got.len()).find(|&i| !used[i] && (got[i] - w).norm() <= tol);
            hit.map(|i| used[i] = true).is_some()
        })
}

fn test_points() -> [Complex64; 3] {
    [
        Complex64::new(0.0, 0.7),
        Complex64::new(0.3, -2.1),
        Complex64::new(-0.45, 5.0),
    ]
}

proptest! {
    #[test]
    fn tf_to_state_space_and_back(
        den in prop::collection::vec(-3.0..3.0f64, 1..6),
        num_len in 1usize..7,
        num_seed in prop::collection::vec(-2.0..2.0f64, 6),
    ) {
        let mut d = vec![1.0];
        d.extend(den);
        let num: Vec<f64> = num_seed[..num_len.min(d.len())].iter().map(|x| x + 0.5).collect();
        let tf = TfForm::new(&num, &d).unwrap();
        let ss = tf.to_state_space();
        prop_assert_eq!(ss.order(), d.len() - 1);
        let back = ss.to_tf().unwrap();
        prop_assert!(close(back.den(), tf.den(), 1e-12));
        prop_assert!(close(back.num(), tf.num(), 1e-12), "{:?} vs {:?}", back.num(), tf.num());
    }

    #[test]
    fn zpk_to_tf_and_back(
        gain in prop_oneof![-3.0..-0.1f64, 0.1..3.0f64],
        pole_real in prop::collection::vec(-3.0..1.0f64, 0..3),
        pole_pairs in prop::collection::vec((-2.0..0.5f64, 0.1..2.0f64), 0..2),
        zero_real in prop::collection::vec(-3.0..3.0f64, 0..2),
    ) {
        prop_assume!(!pole_real.is_empty() || !pole_pairs.is_empty());
        let poles = roots(pole_real, pole_pairs);
        let zeros = roots(zero_real, vec![]);
        prop_assume!(zeros.len() <= poles.len());
        // Well-separated roots: polynomial roots are then well conditioned.
        for list in [&poles, &zeros] {
            for (i, a) in list.iter().enumerate() {
                for b in &list[i + 1..] {
                    prop_assume!((a - b).norm() > 0.2);
                }
            }
        }
        let zpk = ZpkForm::new(gain, zeros.clone(), poles.clone()).unwrap();
        let back = zpk.to_tf().unwrap().to_zpk().unwrap();
        prop_assert!((back.gain() - gain).abs() <= 1e-12 * gain.abs());
        prop_assert!(same_roots(back.poles(), &poles, 1e-8), "{:?} vs {:?}", back.poles(), poles);
        prop_assert!(same_roots(back.zeros(), &zeros, 1e-8), "{:?} vs {:?}", back.zeros(), zeros);
    }

    /// Faddeev–LeVerrier against solving `(sI − A) x = B` for a random realisation (not a
    /// companion matrix, so the two routes share nothing).
    #[test]
    fn state_space_transfer_function_matches_resolvent(
        n in 1usize..5,
        entries in prop::collection::vec(-1.5..1.5f64, 25 + 10),
        d in -1.0..1.0f64,
    ) {
        let a: Vec<Vec<f64>> = (0..n).map(|i| entries[i * 5..i * 5 + n].to_vec()).collect();
        let b = entries[25..25 + n].to_vec();
        let c = entries[30..30 + n].to_vec();
        let ss = StateSpace::new(a, b, c, d).unwrap();
        let tf = ss.to_tf().unwrap();
        for s in test_points() {
            let (x, y) = (tf.response(s), ss.response(s));
            prop_assert!((x - y).norm() <= 1e-9 * y.norm().max(1.0), "{x} vs {y} at {s}");
        }
    }
}

#[test]
fn repeated_poles_and_integrators_need_no_special_case() {
    // 1/(s+1)², 1/(s(s+1)), (s+2)/s²: repeated, at the origin, a double integrator.
    for (num, den) in [
        (vec![1.0], vec![1.0, 2.0, 1.0]),
        (vec![1.0], vec![1.0, 1.0, 0.0]),
        (vec![1.0, 2.0], vec![1.0, 0.0, 0.0]),
    ] {
        let tf = TfForm::new(&num, &den).unwrap();
        let ss = tf.to_state_space();
        for s in test_points() {
            assert!((ss.response(s) - tf.response(s)).norm() < 1e-13);
        }
        let zpk = tf.to_zpk().unwrap();
        for s in test_points() {
            assert!((zpk.response(s) - tf.response(s)).norm() < 1e-7 * tf.response(s).norm());
        }
    }
}

#[test]
fn fitted_zpk_model_exports_its_coefficients() {
    let g = Zpk::new(
        0.2,
        vec![Root::Real(-0.5)],
        vec![Root::Pair { re: -0.25, im: 0.3 }],
    )
    .unwrap();
    let tf = TfForm::of(&g);
    assert!(close(tf.num(), &[0.2, 0.1], 1e-15));
    assert!(close(tf.den(), &[1.0, 0.5, 0.1525], 1e-15));
    for s in test_points() {
        assert!((tf.response(s) - g.response(s)).norm() < 1e-14);
    }
}

#[test]
fn display_reads_like_a_transfer_function() {
    let tf = TfForm::new(&[0.2, 0.1], &[1.0, 0.5, 0.1525]).unwrap();
    assert_eq!(
        tf.to_string(),
        "      0.2 s + 0.1\n  --------------------\n  s^2 + 0.5 s + 0.1525"
    );
    let zpk = tf.to_zpk().unwrap();
    assert_eq!(
        zpk.to_string(),
        "      0.2 (s + 0.5)\n  ----------------------\n  (s^2 + 0.5 s + 0.1525)"
    );
    let integrator = TfForm::new(&[-1.0], &[2.0, 2.0, 0.0]).unwrap();
    assert_eq!(
        format!("{:.2}", integrator.to_zpk().unwrap()),
        "    -0.5\n  ---------\n  s (s + 1)"
    );
    let json = serde_json::to_value(tf.to_state_space()).unwrap();
    assert_eq!(json["b"], serde_json::json!([[1.0], [0.0]]));
    assert_eq!(json["d"], serde_json::json!([[0.0]]));
}

#[test]
fn bad_forms_are_named() {
    let e = TfForm::new(&[1.0, 0.0, 0.0], &[1.0, 1.0]).unwrap_err();
    assert!(e.to_string().contains("improper"), "{e}");
    let e = ZpkForm::new(1.0, vec![], vec![Complex64::new(-1.0, 1.0)]).unwrap_err();
    assert!(e.to_string().contains("conjugate"), "{e}");
    let e = StateSpace::new(vec![vec![1.0, 0.0]], vec![1.0], vec![1.0], 0.0).unwrap_err();
    assert!(e.to_string().contains("`a`"), "{e}");
}
