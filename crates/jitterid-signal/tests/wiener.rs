//! A Wiener model, `tanh` of a first-order response, written against the public API only: its
//! gradient uses the linear response's state at `O(log J)` per instant, and it passes the
//! signal contract.

use jitterid_jitter::{Gaussian, UniformSum};
use jitterid_signal::testing::{binary, check_contract};
use jitterid_signal::{
    LtiResponse, RationalModel, SampleGrid, Signal, SignalError, TransferFunction,
};

/// `s(t) = tanh(x(t))`, `x` the response of `b/(s + a)` to a known input; parameters `[b, a]`.
#[derive(Debug, Clone)]
struct Wiener(LtiResponse<TransferFunction>);

impl Signal for Wiener {
    fn param_names(&self) -> Vec<String> {
        self.0.param_names()
    }
    fn params(&self) -> Vec<f64> {
        self.0.params()
    }
    fn with_params(&self, params: &[f64]) -> Result<Self, SignalError> {
        self.0.with_params(params).map(Wiener)
    }
    fn value(&self, t: f64) -> f64 {
        self.0.value(t).tanh()
    }
    fn value_gradient(&self, t: f64, grad: &mut [f64]) {
        // One O(log J) look-up for the value and the gradient of the linear part.
        let x = self.0.value_and_gradient(t, grad);
        let slope = 1.0 - x.tanh().powi(2);
        grad.iter_mut().for_each(|g| *g *= slope);
    }
    fn breakpoints(&self) -> Vec<f64> {
        self.0.breakpoints()
    }
    fn rate(&self) -> f64 {
        self.0.rate()
    }
}

fn wiener(len: f64) -> Wiener {
    let g = TransferFunction::new(&[1.5], &[1.0, 0.8]).unwrap();
    Wiener(LtiResponse::new(g, binary(9, 4.0, -5.0, len).unwrap()))
}

#[test]
fn wiener_model_passes_the_contract() {
    let s = wiener(45.0);
    let grid = SampleGrid::new(0.0, 1.0, 40).unwrap();
    check_contract(&s, &UniformSum::new(2, 0.2887).unwrap(), &grid, 3).unwrap();
    check_contract(&s, &Gaussian::new(0.1).unwrap(), &grid, 4).unwrap();
}

#[test]
fn state_gradient_equals_the_sum_over_steps() {
    // The O(log J) gradient against the direct sum over every earlier step of the modal form.
    let s = wiener(1000.0).0;
    let m = s.model().modal().unwrap().clone();
    let mut grad = [0.0; 2];
    for t in [0.3, 17.9, 250.0, 999.5] {
        let v = s.value_and_gradient(t, &mut grad);
        assert!((v - s.value(t)).abs() <= 1e-12, "{t}");
        let mut direct = [0.0; 2];
        for &(tj, du) in s.steps().iter().take_while(|(tj, _)| *tj <= t) {
            let x = t - tj;
            for (j, d) in direct.iter_mut().enumerate() {
                let (p, r, dp, dr) = (
                    m.poles[0],
                    m.residues[0],
                    m.d_poles[0][j],
                    m.d_residues[0][j],
                );
                let e = (p * x).exp();
                *d +=
                    du * (m.d_dc_gain[j] + (dr / p - r * dp / (p * p)) * e + r / p * x * e * dp).re;
            }
        }
        for j in 0..2 {
            assert!(
                (grad[j] - direct[j]).abs() <= 1e-12 * direct[j].abs().max(1.0),
                "{t} {j}: {} vs {}",
                grad[j],
                direct[j]
            );
        }
        let state = s.state(t).unwrap();
        assert_eq!(state.x.len(), 1);
    }
}
