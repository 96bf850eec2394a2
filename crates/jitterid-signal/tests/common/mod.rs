//! What the signal crate's integration tests share: an independent fine-step integration.

use jitterid_signal::PiecewiseConstant;

/// `y(t)` of `N(s)/A(s)` (`A` monic, `num` padded to `den`'s length) driven by `u`, at each of
/// `times` (increasing, after `u`'s first edge; at an edge, the left limit), by classical RK4 on
/// the controllable canonical form `ẋ = A_c x + B u`, `y = C x + D u`, `C_i = b_i − D a_i`, with
/// steps of at most `h` that land exactly on every edge, so that the input is constant within
/// each step.
pub fn ode_response(
    num: &[f64],
    den: &[f64],
    u: &PiecewiseConstant,
    times: &[f64],
    h: f64,
) -> Vec<f64> {
    let n = den.len() - 1;
    let d = num[0];
    let c: Vec<f64> = (0..n).map(|i| num[i + 1] - d * den[i + 1]).collect();
    let deriv = |x: &[f64], uval: f64| -> Vec<f64> {
        // x[0] is the highest-order state: ẋ_0 = −Σ a_{i+1} x_i + u, ẋ_i = x_{i−1}.
        let mut dx = vec![0.0; n];
        dx[0] = uval - (0..n).map(|i| den[i + 1] * x[i]).sum::<f64>();
        dx[1..n].copy_from_slice(&x[..n - 1]);
        dx
    };
    let mut x = vec![0.0; n];
    let mut out = Vec::with_capacity(times.len());
    let mut marks: Vec<f64> = u.edges().iter().chain(times).copied().collect();
    marks.sort_by(f64::total_cmp);
    marks.dedup();
    let mut next = 0;
    for w in marks.windows(2) {
        let (a, b) = (w[0], w[1]);
        let uval = u.value(0.5 * (a + b));
        let steps = ((b - a) / h).ceil() as usize;
        let hh = (b - a) / steps as f64;
        for _ in 0..steps {
            let k1 = deriv(&x, uval);
            let x2: Vec<f64> = x.iter().zip(&k1).map(|(x, k)| x + 0.5 * hh * k).collect();
            let k2 = deriv(&x2, uval);
            let x3: Vec<f64> = x.iter().zip(&k2).map(|(x, k)| x + 0.5 * hh * k).collect();
            let k3 = deriv(&x3, uval);
            let x4: Vec<f64> = x.iter().zip(&k3).map(|(x, k)| x + hh * k).collect();
            let k4 = deriv(&x4, uval);
            for i in 0..n {
                x[i] += hh / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
        }
        while next < times.len() && times[next] == b {
            let y = c.iter().zip(&x).map(|(c, x)| c * x).sum::<f64>() + d * uval;
            out.push(y);
            next += 1;
        }
    }
    out
}
