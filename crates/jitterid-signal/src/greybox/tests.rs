//! Oracles of the grey-box route: the equivalent transfer function (values, expectations under
//! jitter, spectrum), finite differences (gradients), the signal contract.

use super::*;
use crate::testing::{binary, check_contract, mass_spring_damper};
use crate::{LtiResponse, PiecewiseConstant, TransferFunction};
use jitterid_jitter::{Gaussian, UniformSum};

/// The mass–spring–damper's matrices as written, to edit in the refusal tests.
fn msd_written() -> WrittenMatrices {
    let rows = |m: &[Vec<String>]| -> Vec<Vec<Entry>> {
        m.iter()
            .map(|r| r.iter().map(|t| Entry::Text(t.clone())).collect())
            .collect()
    };
    let [a, b, c, d] = mass_spring_damper().texts();
    WrittenMatrices {
        a: rows(&a),
        b: rows(&b),
        c: rows(&c),
        d: Some(rows(&d)),
    }
}

fn names(n: &[&str]) -> Vec<String> {
    n.iter().map(|s| s.to_string()).collect()
}

fn msd(theta: [f64; 3], input: &PiecewiseConstant) -> GreyBox<ExprModel> {
    GreyBox::new(mass_spring_damper(), theta.to_vec(), input.clone()).unwrap()
}

/// `1/(m s² + damp s + k)` as coefficients: `(1/m)/(s² + (damp/m)s + k/m)`.
fn msd_tf([m, damp, k]: [f64; 3], input: &PiecewiseConstant) -> LtiResponse<TransferFunction> {
    let tf = TransferFunction::new(&[1.0 / m], &[1.0, damp / m, k / m]).unwrap();
    LtiResponse::new(tf, input.clone())
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + b.abs())
}

/// The Jacobian of `(b0, a1, a0) = (1/m, damp/m, k/m)` with respect to `(m, damp, k)`, to
/// carry the transfer function's gradient to the physical parameters.
fn chain([m, damp, k]: [f64; 3], g: &[f64]) -> [f64; 3] {
    let (gb0, ga1, ga0) = (g[0], g[1], g[2]);
    [
        gb0 * (-1.0 / (m * m)) + ga1 * (-damp / (m * m)) + ga0 * (-k / (m * m)),
        ga1 / m,
        ga0 / m,
    ]
}

#[test]
fn response_and_gradient_equal_the_transfer_function_route() {
    let input = binary(3, 4.0, 0.0, 60.0).unwrap();
    // Underdamped, overdamped and critically damped (a repeated pole: the tf's confluent
    // route).
    for theta in [[1.0, 0.4, 2.0], [0.5, 3.0, 1.0], [1.0, 2.0, 1.0]] {
        let g = msd(theta, &input);
        let tf = msd_tf(theta, &input);
        let mut gg = [0.0; 3];
        let mut gt = [0.0; 3];
        for t in [0.3, 5.7, 17.2, 33.3, 59.1, 70.0] {
            let y = g.value_and_gradient(t, &mut gg);
            let yt = tf.value_and_gradient(t, &mut gt);
            assert!(close(y, yt, 1e-10), "{theta:?} t = {t}: {y} vs {yt}");
            let want = chain(theta, &gt);
            for j in 0..3 {
                assert!(
                    close(gg[j], want[j], 1e-8),
                    "{theta:?} t = {t} θ_{j}: {} vs {}",
                    gg[j],
                    want[j]
                );
            }
        }
    }
}

#[test]
fn gradient_equals_finite_differences() {
    let input = binary(5, 3.0, 0.0, 40.0).unwrap();
    let theta = [1.3, 0.7, 2.5];
    let g = msd(theta, &input);
    let mut grad = [0.0; 3];
    for t in [1.1, 9.9, 25.4] {
        g.value_gradient(t, &mut grad);
        for j in 0..3 {
            let h = 1e-6 * theta[j];
            let (mut up, mut down) = (theta, theta);
            up[j] += h;
            down[j] -= h;
            let fd = (msd(up, &input).value(t) - msd(down, &input).value(t)) / (2.0 * h);
            assert!(
                close(grad[j], fd, 1e-6),
                "t = {t} θ_{j}: {} vs {fd}",
                grad[j]
            );
        }
    }
}

#[test]
fn jittered_moments_equal_the_transfer_function_route() {
    let input = binary(8, 4.0, -10.0, 110.0).unwrap();
    let grid = SampleGrid::new(0.0, 1.0, 100).unwrap();
    let jitters: Vec<Box<dyn JitterModel>> = vec![
        Box::new(UniformSum::new(2, 0.2887).unwrap()),
        Box::new(UniformSum::new(0, 0.5).unwrap()),
        Box::new(Gaussian::new(1.0 / 6.0).unwrap()),
    ];
    for theta in [[1.0, 0.4, 2.0], [1.0, 2.0, 1.0]] {
        let g = msd(theta, &input);
        let tf = msd_tf(theta, &input);
        for jitter in &jitters {
            let (m, cols) = g.expected_values_and_gradient(&grid, jitter.as_ref());
            let (mt, colst) = tf.expected_values_and_gradient(&grid, jitter.as_ref());
            let sq = g.expected_squares(&grid, jitter.as_ref());
            let sqt = tf.expected_squares(&grid, jitter.as_ref());
            for k in 0..grid.len() {
                assert!(
                    close(m[k], mt[k], 1e-10),
                    "{theta:?} {jitter:?} k = {k}: {} vs {}",
                    m[k],
                    mt[k]
                );
                assert!(
                    close(sq[k], sqt[k], 1e-9),
                    "{theta:?} {jitter:?} k = {k}: {} vs {}",
                    sq[k],
                    sqt[k]
                );
                let want = chain(theta, &[colst[0][k], colst[1][k], colst[2][k]]);
                for j in 0..3 {
                    assert!(
                        close(cols[j][k], want[j], 1e-8),
                        "k = {k} θ_{j}: {} vs {}",
                        cols[j][k],
                        want[j]
                    );
                }
            }
        }
    }
}

#[test]
fn spectrum_equals_the_transfer_function_and_its_differences() {
    let input = binary(2, 4.0, 0.0, 50.0).unwrap();
    let theta = [1.0, 0.4, 2.0];
    let g = msd(theta, &input);
    let tf = msd_tf(theta, &input);
    let mut grad = [Complex64::new(0.0, 0.0); 3];
    for f in [0.0, 0.05, 0.23, 0.5, 3.0] {
        let (a, b) = (g.density(f), tf.density(f));
        assert!(
            (a - b).norm() <= 1e-12 * (1.0 + b.norm()),
            "f = {f}: {a} vs {b}"
        );
        g.density_gradient(f, &mut grad);
        for j in 0..3 {
            let h = 1e-6;
            let (mut up, mut down) = (theta, theta);
            up[j] += h;
            down[j] -= h;
            let fd = (msd(up, &input).density(f) - msd(down, &input).density(f)) / (2.0 * h);
            assert!(
                (grad[j] - fd).norm() <= 1e-6 * (1.0 + fd.norm()),
                "f = {f} θ_{j}: {} vs {fd}",
                grad[j]
            );
        }
    }
    let tfg = g.transfer_function().unwrap();
    let want = tf.model();
    for (a, b) in tfg.den().iter().zip(want.den()) {
        assert!(close(*a, *b, 1e-14));
    }
    assert!(close(*tfg.num().last().unwrap(), want.num()[0], 1e-14));
}

/// A parameter that only scales the output (a sensor gain in `C`) and a feed-through in `D`:
/// no sensitivity block for it, and still the right gradient; the signal contract (values,
/// breakpoints, expectations against references and Monte Carlo) holds.
#[test]
fn output_only_parameter_and_the_signal_contract() {
    let written = WrittenMatrices {
        a: vec![vec!["-1/tau".into()]],
        b: vec![vec!["1/tau".into()]],
        c: vec![vec!["g".into()]],
        d: Some(vec![vec!["0.1*g".into()]]),
    };
    let model = ExprModel::new(&names(&["tau", "g"]), &[], &[], &written).unwrap();
    let input = binary(4, 3.0, 0.0, 30.0).unwrap();
    let s = GreyBox::new(model, vec![0.8, 2.0], input.clone()).unwrap();
    assert_eq!(s.realised().dim(), 3, "one block for tau, none for g");
    let tf = LtiResponse::new(
        TransferFunction::new(&[0.2, 2.0 / 0.8 + 0.2 / 0.8], &[1.0, 1.0 / 0.8]).unwrap(),
        input,
    );
    for t in [0.5, 7.7, 20.0] {
        assert!(close(s.value(t), tf.value(t), 1e-12));
    }
    let grid = SampleGrid::new(0.0, 1.0, 30).unwrap();
    check_contract(&s, &UniformSum::new(1, 0.3).unwrap(), &grid, 7).unwrap();
    let dc = GreyBox::new(
        ExprModel::new(&names(&["m", "damp", "k"]), &[], &[], &msd_written()).unwrap(),
        vec![1.0, 0.4, 2.0],
        binary(9, 4.0, 0.0, 30.0).unwrap(),
    )
    .unwrap();
    check_contract(&dc, &Gaussian::new(0.2).unwrap(), &grid, 11).unwrap();
}

#[test]
fn refusals_are_typed() {
    let input = binary(1, 4.0, 0.0, 20.0).unwrap();
    let model = ExprModel::new(
        &names(&["m", "damp", "k"]),
        &[],
        &[("m".into(), (0.0, 1e3))],
        &msd_written(),
    )
    .unwrap();
    let e = GreyBox::new(model.clone(), vec![-1.0, 0.4, 2.0], input.clone()).unwrap_err();
    assert_eq!(e.key(), Some("params"));
    assert!(
        e.to_string()
            .contains("m = -1 is outside its bounds [0, 1000]"),
        "{e}"
    );
    // m = 0 divides by zero: a non-finite matrix.
    assert!(GreyBox::new(model.clone(), vec![0.0, 0.4, 2.0], input.clone()).is_err());
    // Negative damping is unstable.
    assert!(matches!(
        GreyBox::new(model.clone(), vec![1.0, -0.4, 2.0], input.clone()),
        Err(SignalError::Unstable { .. })
    ));
    assert!(GreyBox::new(model.clone(), vec![1.0], input.clone()).is_err());
    let tones = crate::Multisine::sine(0.1, 1.0, 0.0).unwrap();
    assert!(GreyBox::new(model, vec![1.0, 0.4, 2.0], tones).is_err());
    let n = names(&["m", "damp", "k"]);
    let mut w = msd_written();
    w.b = vec![vec![0.0.into()]];
    let e = ExprModel::new(&n, &[], &[], &w).unwrap_err();
    assert_eq!(e.key(), Some("b"));
    assert!(e.to_string().contains("expected 2 row(s), got 1"), "{e}");
    let mut w = msd_written();
    w.a[1][0] = "-k/(m".into();
    let e = ExprModel::new(&n, &[], &[], &w).unwrap_err();
    assert_eq!(e.key(), Some("a"));
    assert!(
        e.to_string().contains("row 2, column 1") && e.to_string().contains("\"-k/(m\""),
        "{e}"
    );
    let e = ExprModel::new(&n, &[], &[("mass".into(), (0.0, 1.0))], &msd_written()).unwrap_err();
    assert_eq!(e.key(), Some("bounds"));
    let e = ExprModel::new(&names(&["m", "sin", "k"]), &[], &[], &msd_written()).unwrap_err();
    assert_eq!(e.key(), Some("params"));
    let e = ExprModel::new(&n, &[("k".into(), 1.0)], &[], &msd_written()).unwrap_err();
    assert_eq!(e.key(), Some("fixed"));
    assert!(e.to_string().contains("given twice"));
}

/// A model with closed-form derivatives gives the same signal as the forward-mode default.
#[test]
fn closed_form_derivatives_equal_the_forward_mode_ones() {
    #[derive(Debug, Clone)]
    struct FirstOrder;
    impl StateSpaceModel for FirstOrder {
        fn param_names(&self) -> Vec<String> {
            names(&["tau"])
        }
        fn matrices<R: Real>(&self, th: &[R]) -> StateMatrices<R> {
            let one = R::constant(1.0);
            StateMatrices {
                a: vec![vec![-one / th[0]]],
                b: vec![one / th[0]],
                c: vec![one],
                d: R::constant(0.0),
            }
        }
    }
    #[derive(Debug, Clone)]
    struct Explicit;
    impl StateSpaceModel for Explicit {
        fn param_names(&self) -> Vec<String> {
            names(&["tau"])
        }
        fn matrices<R: Real>(&self, th: &[R]) -> StateMatrices<R> {
            FirstOrder.matrices(th)
        }
        fn derivatives(&self, th: &[f64]) -> Vec<StateMatrices<f64>> {
            let d = 1.0 / (th[0] * th[0]);
            vec![StateMatrices {
                a: vec![vec![d]],
                b: vec![-d],
                c: vec![0.0],
                d: 0.0,
            }]
        }
    }
    let input = binary(6, 2.0, 0.0, 20.0).unwrap();
    let a = GreyBox::new(FirstOrder, vec![0.7], input.clone()).unwrap();
    let b = GreyBox::new(Explicit, vec![0.7], input).unwrap();
    // Equal to rounding (the dual quotient rule and 1/τ² round differently).
    assert!(close(
        a.derivatives()[0].a[0][0],
        b.derivatives()[0].a[0][0],
        1e-15
    ));
    let (mut ga, mut gb) = ([0.0], [0.0]);
    let (ya, yb) = (
        a.value_and_gradient(4.2, &mut ga),
        b.value_and_gradient(4.2, &mut gb),
    );
    assert!(
        close(ya, yb, 1e-15) && close(ga[0], gb[0], 1e-13),
        "{ga:?} {gb:?}"
    );
}

/// Where both routes exist (distinct poles) the modal one and the augmented matrix exponential
/// give the same response, gradients and jittered moments; a repeated pole has no modal route.
#[test]
fn the_modal_and_augmented_routes_agree() {
    let input = binary(12, 4.0, -10.0, 110.0).unwrap();
    let grid = SampleGrid::new(0.0, 1.0, 100).unwrap();
    let jitter = UniformSum::new(2, 0.35).unwrap();
    let modal = msd([1.0, 0.4, 2.0], &input);
    assert!(modal.is_modal());
    assert!(!msd([1.0, 2.0, 1.0], &input).is_modal(), "a double pole");
    let aug = modal.clone().augmented_only();
    let (m, cols) = modal.expected_values_and_gradient(&grid, &jitter);
    let (ma, colsa) = aug.expected_values_and_gradient(&grid, &jitter);
    let (sq, sqa) = (
        modal.expected_squares(&grid, &jitter),
        aug.expected_squares(&grid, &jitter),
    );
    for k in 0..grid.len() {
        assert!(close(m[k], ma[k], 1e-10), "k = {k}: {} vs {}", m[k], ma[k]);
        assert!(
            close(sq[k], sqa[k], 1e-9),
            "k = {k}: {} vs {}",
            sq[k],
            sqa[k]
        );
        for j in 0..3 {
            assert!(close(cols[j][k], colsa[j][k], 1e-8), "k = {k} θ_{j}");
        }
    }
    let (mut g, mut ga) = ([0.0; 3], [0.0; 3]);
    for t in [3.3, 47.0, 101.5] {
        let (y, ya) = (
            modal.value_and_gradient(t, &mut g),
            aug.value_and_gradient(t, &mut ga),
        );
        assert!(close(y, ya, 1e-11));
        for j in 0..3 {
            assert!(
                close(g[j], ga[j], 1e-9),
                "t = {t} θ_{j}: {} vs {}",
                g[j],
                ga[j]
            );
        }
    }
}
