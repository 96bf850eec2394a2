//! A discrete-time pulse response `g(t) = Σ_l h_l δ(t − l·T_s)` driven by a piecewise-constant
//! input: `s(t) = Σ_l h_l u(t − l·T_s)`, itself piecewise constant.

use crate::error::{all_finite, positive, SignalError};
use crate::{Jacobian, PiecewiseConstant, SampleGrid, Signal, Spectrum};
use jitterid_jitter::{JitterModel, QuadratureRule};
use num_complex::Complex64;
use std::f64::consts::TAU;

/// A pulse response `h_0, …, h_{L−1}` at spacing `T_s` driven by a piecewise-constant input:
/// `s(t) = Σ_l h_l u(t − l·T_s)`, with parameters `θ = [h_0, …, h_{L−1}]` (named `"h0"`,
/// `"h1"`, …).
///
/// `S_c(f) = H(f) U(f)` with `H(f) = Σ_l h_l e^{-i2πf l T_s}`; `s` is linear in `θ`. Because
/// `s` is piecewise constant, its jittered mean is exact in the jitter's distribution function:
/// `E[u(t + τ)] = Σ_j Δu_j P(τ ≥ t_j − t)` over the input's steps `(t_j, Δu_j)`.
///
/// Deserializes through [`PulseResponse::new`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "PulseFields")]
pub struct PulseResponse {
    coefficients: Vec<f64>,
    interval: f64,
    input: PiecewiseConstant,
}

impl PulseResponse {
    /// At least one coefficient, all finite, and `interval > 0`.
    pub fn new(
        coefficients: Vec<f64>,
        interval: f64,
        input: PiecewiseConstant,
    ) -> Result<Self, SignalError> {
        if coefficients.is_empty() {
            return Err(SignalError::TooFew {
                name: "coefficients",
                min: 1,
                value: 0,
            });
        }
        all_finite("coefficients", &coefficients)?;
        positive("interval", interval)?;
        Ok(Self {
            coefficients,
            interval,
            input,
        })
    }

    /// The pulse response `h_0, …, h_{L−1}`.
    pub fn coefficients(&self) -> &[f64] {
        &self.coefficients
    }

    /// The spacing `T_s` of the pulses (s).
    pub fn interval(&self) -> f64 {
        self.interval
    }

    /// The driving input.
    pub fn input(&self) -> &PiecewiseConstant {
        &self.input
    }

    /// `l·T_s`.
    fn shift(&self, l: usize) -> f64 {
        l as f64 * self.interval
    }

    /// `ū[k][l] = E[u(t_k − l·T_s + τ)]` for every instant and shift: `m_k = Σ_l h_l ū[k][l]`
    /// and `∂m_k/∂h_l = ū[k][l]`.
    ///
    /// A step at jitter time `c = t_j − (t_k − l·T_s)` adds `Δu_j P(τ ≥ c)`: fully when `c` is at
    /// or before the jitter's reach (`c ≤ lo`), not at all after it (`c > hi`), and in between
    /// through one quadrature rule per instant cut at all such `c`, so that no node straddles a
    /// step and `P(τ ≥ c)` is a sum of node masses. An atom of the jitter exactly at `c` counts
    /// as `τ ≥ c`, as `u` is right-continuous (it takes the new level at the edge itself).
    /// Cost `O(N · (L log J + steps within the reach))`.
    fn smoothed_inputs(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Vec<Vec<f64>> {
        let steps = self.input.steps();
        let times: Vec<f64> = steps.iter().map(|s| s.0).collect();
        // full[j] = Σ_{i<j} Δu_i: the input once the first j steps have all happened.
        let mut full = Vec::with_capacity(steps.len() + 1);
        full.push(0.0);
        let mut acc = 0.0;
        for &(_, du) in &steps {
            acc += du;
            full.push(acc);
        }
        let (lo, hi) = jitter.reach();
        let num = self.coefficients.len();
        let mut ranges = Vec::with_capacity(num);
        let mut breaks = Vec::new();
        grid.times()
            .map(|t| {
                ranges.clear();
                breaks.clear();
                for l in 0..num {
                    let x = t - self.shift(l);
                    // `tj − x` is non-decreasing in `tj`, so both cuts are partition points.
                    let a = times.partition_point(|&tj| tj - x <= lo);
                    let b = times.partition_point(|&tj| tj - x <= hi);
                    breaks.extend(times[a..b].iter().map(|&tj| tj - x));
                    ranges.push((a, b, x));
                }
                let tail = (!breaks.is_empty()).then(|| Tail::new(&jitter.rule(&breaks, 0.0)));
                ranges
                    .iter()
                    .map(|&(a, b, x)| {
                        let partial: f64 = match &tail {
                            Some(tail) => steps[a..b]
                                .iter()
                                .map(|&(tj, du)| du * tail.at_least(tj - x))
                                .sum(),
                            None => 0.0,
                        };
                        full[a] + partial
                    })
                    .collect()
            })
            .collect()
    }
}

/// The serialized form of a [`PulseResponse`], validated on the way in.
#[derive(serde::Deserialize)]
struct PulseFields {
    coefficients: Vec<f64>,
    interval: f64,
    input: PiecewiseConstant,
}

impl TryFrom<PulseFields> for PulseResponse {
    type Error = SignalError;
    fn try_from(p: PulseFields) -> Result<Self, SignalError> {
        Self::new(p.coefficients, p.interval, p.input)
    }
}

/// Upper-tail masses `P(τ ≥ c)` of a quadrature rule, for `c` among the rule's cuts.
struct Tail {
    /// Nodes in increasing order.
    nodes: Vec<f64>,
    /// `suffix[i]` = total weight of nodes `i..`.
    suffix: Vec<f64>,
}

impl Tail {
    fn new(rule: &QuadratureRule) -> Self {
        let mut pairs: Vec<(f64, f64)> = rule
            .nodes
            .iter()
            .copied()
            .zip(rule.weights.iter().copied())
            .collect();
        // Atoms come after the pieces in a rule; order everything by position.
        pairs.sort_by(|p, q| p.0.total_cmp(&q.0));
        let mut suffix = vec![0.0; pairs.len() + 1];
        for (i, &(_, w)) in pairs.iter().enumerate().rev() {
            suffix[i] = suffix[i + 1] + w;
        }
        Self {
            nodes: pairs.into_iter().map(|p| p.0).collect(),
            suffix,
        }
    }

    /// Mass of the nodes at or above `c`.
    fn at_least(&self, c: f64) -> f64 {
        self.suffix[self.nodes.partition_point(|&n| n < c)]
    }
}

impl Signal for PulseResponse {
    fn param_names(&self) -> Vec<String> {
        (0..self.coefficients.len())
            .map(|l| format!("h{l}"))
            .collect()
    }

    fn params(&self) -> Vec<f64> {
        self.coefficients.clone()
    }

    fn with_params(&self, params: &[f64]) -> Result<Self, SignalError> {
        if params.len() != self.coefficients.len() {
            return Err(SignalError::WrongParamCount {
                expected: self.coefficients.len(),
                got: params.len(),
            });
        }
        Self::new(params.to_vec(), self.interval, self.input.clone())
    }

    fn value(&self, t: f64) -> f64 {
        self.coefficients
            .iter()
            .enumerate()
            .map(|(l, h)| h * self.input.value(t - self.shift(l)))
            .sum()
    }

    fn value_gradient(&self, t: f64, grad: &mut [f64]) {
        for (l, g) in grad.iter_mut().enumerate().take(self.coefficients.len()) {
            *g = self.input.value(t - self.shift(l));
        }
    }

    fn breakpoints(&self) -> Vec<f64> {
        let edges = self.input.edges();
        let mut out: Vec<f64> = (0..self.coefficients.len())
            .flat_map(|l| edges.iter().map(move |&e| e + self.shift(l)))
            .collect();
        out.sort_by(f64::total_cmp);
        // Shifted edges that coincide (an input on a T_s grid) differ by rounding only; one cut
        // serves both, and a sliver between two would only add quadrature nodes.
        out.dedup_by(|b, a| (*b - *a).abs() <= 4.0 * f64::EPSILON * a.abs().max(b.abs()));
        out
    }

    /// Zero: `s` is constant between its breakpoints, so quadrature needs no refinement.
    fn rate(&self) -> f64 {
        0.0
    }

    fn expected_values(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Vec<f64> {
        self.smoothed_inputs(grid, jitter)
            .iter()
            .map(|row| row.iter().zip(&self.coefficients).map(|(u, h)| h * u).sum())
            .collect()
    }

    fn expected_values_gradient(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Jacobian {
        let rows = self.smoothed_inputs(grid, jitter);
        (0..self.coefficients.len())
            .map(|l| rows.iter().map(|row| row[l]).collect())
            .collect()
    }
}

impl Spectrum for PulseResponse {
    fn density(&self, f: f64) -> Complex64 {
        let h: Complex64 = self
            .coefficients
            .iter()
            .enumerate()
            .map(|(l, &h)| Complex64::from_polar(h, -TAU * f * self.shift(l)))
            .sum();
        h * self.input.spectrum(f)
    }

    fn density_gradient(&self, f: f64, grad: &mut [Complex64]) {
        let u = self.input.spectrum(f);
        for (l, g) in grad.iter_mut().enumerate().take(self.coefficients.len()) {
            *g = Complex64::cis(-TAU * f * self.shift(l)) * u;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn zoh_input() -> PiecewiseConstant {
        PiecewiseConstant::zero_order_hold(0.0, 0.5, &[1.0, -0.5, 2.0, 0.0, 0.75, 1.5]).unwrap()
    }

    fn pulse() -> PulseResponse {
        PulseResponse::new(vec![0.6, 0.3, -0.15], 0.5, zoh_input()).unwrap()
    }

    #[test]
    fn constructor_validates() {
        let u = zoh_input();
        assert_eq!(
            PulseResponse::new(vec![], 1.0, u.clone()),
            Err(SignalError::TooFew {
                name: "coefficients",
                min: 1,
                value: 0
            })
        );
        assert!(matches!(
            PulseResponse::new(vec![1.0, f64::NAN], 1.0, u.clone()),
            Err(SignalError::NotFinite {
                name: "coefficients",
                ..
            })
        ));
        assert!(matches!(
            PulseResponse::new(vec![1.0], 0.0, u.clone()),
            Err(SignalError::NotPositive {
                name: "interval",
                ..
            })
        ));
        let p = pulse();
        assert_eq!(p.param_names(), vec!["h0", "h1", "h2"]);
        assert_eq!(
            p.with_params(&[1.0]),
            Err(SignalError::WrongParamCount {
                expected: 3,
                got: 1
            })
        );
        assert_eq!(
            p.with_params(&[1.0, 2.0, 3.0]).unwrap().params(),
            [1.0, 2.0, 3.0]
        );
    }

    #[test]
    fn value_is_the_discrete_convolution() {
        // Input on the pulse grid: on [kT_s, (k+1)T_s), s = Σ_l h_l u_{k−l}.
        let p = pulse();
        let u = zoh_input();
        let h = p.coefficients();
        let levels = u.levels();
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        for _ in 0..200 {
            // A small xorshift: random instants without pulling an RNG into unit tests.
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let t = -1.0 + 6.0 * (state >> 11) as f64 / (1u64 << 53) as f64;
            let k = (t / 0.5).floor() as i64;
            let direct: f64 = h
                .iter()
                .enumerate()
                .map(|(l, hl)| {
                    let i = k - l as i64;
                    if i >= 0 && (i as usize) < levels.len() {
                        hl * levels[i as usize]
                    } else {
                        0.0
                    }
                })
                .sum();
            assert!((p.value(t) - direct).abs() < 1e-15, "t={t}");
            let mut g = [0.0; 3];
            p.value_gradient(t, &mut g);
            let lin: f64 = g.iter().zip(h).map(|(g, h)| g * h).sum();
            assert!((lin - p.value(t)).abs() < 1e-15);
        }
    }

    #[test]
    fn breakpoints_are_sorted_and_distinct() {
        let b = pulse().breakpoints();
        // Edges 0, 0.5, …, 3 shifted by 0, 0.5, 1: the grid 0, 0.5, …, 4.
        assert_eq!(b.len(), 9);
        for (i, x) in b.iter().enumerate() {
            assert!((x - 0.5 * i as f64).abs() < 1e-15);
        }
    }

    #[test]
    fn density_is_the_integral_of_the_pieces() {
        // s is constant between its breakpoints and zero outside them, so
        // S_c(f) = Σ s_i (e^{-i2πfa} − e^{-i2πfb})/(i2πf) exactly; a non-grid T_s makes the
        // pieces uneven.
        let p = PulseResponse::new(vec![0.6, 0.3, -0.15], 0.37, zoh_input()).unwrap();
        let b = p.breakpoints();
        for &f in &[0.0, 0.013, 0.4, 1.7, -2.3] {
            let direct: Complex64 = b
                .windows(2)
                .map(|w| {
                    let level = p.value(0.5 * (w[0] + w[1]));
                    if f == 0.0 {
                        Complex64::new(level * (w[1] - w[0]), 0.0)
                    } else {
                        level * (Complex64::cis(-TAU * f * w[0]) - Complex64::cis(-TAU * f * w[1]))
                            / Complex64::new(0.0, TAU * f)
                    }
                })
                .sum();
            let d = p.density(f);
            assert!((d - direct).norm() < 1e-13, "f={f}: {d} vs {direct}");
            let mut g = [Complex64::new(0.0, 0.0); 3];
            p.density_gradient(f, &mut g);
            let lin: Complex64 = g.iter().zip(p.coefficients()).map(|(g, h)| g * h).sum();
            assert!((lin - d).norm() < 1e-14);
        }
    }
}
