//! Structural integrators (`with_integrators`): the poles at the origin are held there
//! exactly and are not parameters; the model is the same system as without them, and its
//! parameter derivatives are those of the full parameterisation's remaining columns.

use jitterid_signal::{RationalModel, Root, SignalError, TransferFunction, Zpk};
use num_complex::Complex64;

fn points() -> [Complex64; 3] {
    [
        Complex64::new(0.0, 0.7),
        Complex64::new(-0.3, 2.0),
        Complex64::new(0.4, -0.1),
    ]
}

#[test]
fn a_tf_integrator_is_held_and_the_rest_estimated() {
    let full = TransferFunction::new(&[0.5, 2.0], &[1.0, 1.5, 0.7, 0.0]).unwrap();
    let g = full.with_integrators(1).unwrap();
    assert_eq!(g.integrators(), 1);
    assert_eq!(g.param_names(), ["b1", "b0", "a2", "a1"]);
    assert_eq!(g.params(), [0.5, 2.0, 1.5, 0.7]);
    // The pole at the origin is exactly 0, the others those of s² + 1.5 s + 0.7.
    assert_eq!(
        g.rational()
            .poles()
            .iter()
            .filter(|p| **p == Complex64::new(0.0, 0.0))
            .count(),
        1
    );
    let moved = g.with_params(&[0.6, 1.0, 2.5, 1.2]).unwrap();
    assert_eq!(moved.den(), [1.0, 2.5, 1.2, 0.0]);
    assert_eq!(moved.integrators(), 1);
    for s in points() {
        assert!((g.response(s) - full.response(s)).norm() < 1e-14 * full.response(s).norm());
        // The gradient: the full model's columns without a0's (coefficient order b, then a).
        let mut held = vec![Complex64::new(0.0, 0.0); 4];
        let mut all = vec![Complex64::new(0.0, 0.0); 5];
        g.rational().response_gradient(s, &mut held);
        full.rational().response_gradient(s, &mut all);
        for (h, a) in held.iter().zip(&all[..4]) {
            assert!((h - a).norm() < 1e-12 * a.norm().max(1.0), "{h} vs {a}");
        }
    }
    // The number of poles at the origin bounds the key.
    assert_eq!(
        full.with_integrators(2).unwrap_err(),
        SignalError::Integrators {
            integrators: 2,
            at_origin: 1,
            poles: 3
        }
    );
    let e = TransferFunction::new(&[1.0], &[1.0, 1.0, 0.5])
        .unwrap()
        .with_integrators(1)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`integrators` = 1") && e.contains("0 of them"),
        "{e}"
    );
}

#[test]
fn a_zpk_integrator_is_held_and_named_by_its_place() {
    let full = Zpk::new(
        0.8,
        vec![Root::Real(-2.0)],
        vec![Root::Real(0.0), Root::Pair { re: -0.5, im: 1.0 }],
    )
    .unwrap();
    let g = full.with_integrators(1).unwrap();
    assert_eq!(g.param_names(), ["gain", "zero0", "pole1.re", "pole1.im"]);
    assert_eq!(g.params(), [0.8, -2.0, -0.5, 1.0]);
    let moved = g.with_params(&[1.0, -3.0, -0.7, 0.4]).unwrap();
    assert_eq!(
        moved.poles(),
        [Root::Real(0.0), Root::Pair { re: -0.7, im: 0.4 }]
    );
    // The derivatives against central differences of with_params.
    for s in points() {
        assert!((g.response(s) - full.response(s)).norm() < 1e-14 * full.response(s).norm());
        let mut grad = vec![Complex64::new(0.0, 0.0); 4];
        g.rational().response_gradient(s, &mut grad);
        let p = g.params();
        for (j, d) in grad.iter().enumerate() {
            let h = 1e-6;
            let (mut up, mut down) = (p.clone(), p.clone());
            up[j] += h;
            down[j] -= h;
            let fd = (g.with_params(&up).unwrap().response(s)
                - g.with_params(&down).unwrap().response(s))
                / (2.0 * h);
            assert!(
                (fd - d).norm() < 1e-7 * d.norm().max(1.0),
                "{j}: {fd} vs {d}"
            );
        }
    }
    assert!(matches!(
        full.with_integrators(2),
        Err(SignalError::Integrators {
            integrators: 2,
            at_origin: 1,
            poles: 3
        })
    ));
    // Serialized with the key, and back.
    let json = serde_json::to_string(&g).unwrap();
    assert!(json.contains("\"integrators\":1"), "{json}");
    assert_eq!(serde_json::from_str::<Zpk>(&json).unwrap(), g);
}
