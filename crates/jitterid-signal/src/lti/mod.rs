//! The exact response of a rational model to a known input, and its exact jittered moments.
//!
//! Why one file of about 850 lines (a tenth of them tests): the response and its jittered first
//! moment walk the input's steps with one shared modal recursion (the carry of the steps before
//! a sample's reach); the second moment is in `squares.rs`, the parts inside the reach in
//! `reach.rs`, repeated poles in `confluent.rs`.

mod squares;
use crate::confluent::Confluent;
use crate::input::Input;
use crate::rational::{Modal, RationalModel};
use crate::reach::{InReach, Route};
use crate::signal::{Jacobian, Signal};
use crate::spectrum::{SpectralLine, Spectrum};
use crate::{SampleGrid, SignalError};
use jitterid_jitter::JitterModel;
use jitterid_numeric::budget;
use num_complex::Complex64;
use std::f64::consts::TAU;
use std::sync::OnceLock;

/// The output `s(t) = (g ∗ u)(t)` of a rational model `G` driven by a known input, exactly.
///
/// For a piecewise-constant input, written as steps `u(t) = Σ_j Δu_j H(t − t_j)`,
/// `s(t) = Σ_j Δu_j [G(0) + Σ_i (r_i/p_i) e^{p_i (t − t_j)}]` for `t ≥ t_j` (the modal form);
/// the system is at rest before the first step. For tones the response is the steady state.
///
/// The first moment `m_k = E[s(t_k + τ)]` is computed exactly and in `O(N + J)` for `N`
/// samples and `J` steps: a step that lies before the jitter's reach of a sample acts through
/// `E[e^{p_i(τ − lo)}]`, carried from sample to sample by the recursion `x ← e^{p_i T} x`; a
/// step inside a sample's reach `(t_k + lo, t_k + hi]` acts through expectations over
/// `τ ≥ t_j − t_k` that depend on `t_j − t_k` only, computed by quadrature over the jitter's
/// pieces and, for long records, tabulated once per evaluation (piecewise Chebyshev, checked
/// against the quadrature to `1e-14`). Quadrature is refined only where a modal term `e^{p x}`
/// has not yet decayed, so the cost does not grow with the jitter's reach or the poles'
/// moduli.
///
/// Serializes as `{model, input}`; deserializes through [`LtiResponse::new`] (the model and the
/// input through their own validating constructors).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(
    try_from = "LtiFields<M>",
    into = "LtiFields<M>",
    bound(
        serialize = "M: RationalModel + serde::Serialize",
        deserialize = "M: RationalModel + serde::Deserialize<'de>"
    )
)]
pub struct LtiResponse<M> {
    model: M,
    input: Input,
    steps: Vec<(f64, f64)>,
    /// The modal state right after every step, so that `s(t)` and its gradient cost
    /// `O(log J + poles)`. Built on the first evaluation in time: estimation never needs it.
    prefix: OnceLock<Prefix>,
    /// For a model without a modal form: its realisation and the state right after every
    /// step, built on the first evaluation in time.
    confluent: OnceLock<(Confluent, Vec<f64>)>,
}

impl<M: RationalModel> LtiResponse<M> {
    /// The response of `model` to `input`.
    pub fn new(model: M, input: impl Into<Input>) -> Self {
        let input = input.into();
        let steps = match &input {
            Input::Piecewise(p) => p.steps(),
            Input::Tones(_) => Vec::new(),
        };
        Self {
            model,
            input,
            steps,
            prefix: OnceLock::new(),
            confluent: OnceLock::new(),
        }
    }

    /// The realisation used where the model has no modal form ([`Confluent`]), with the
    /// state right after every step.
    fn confluent_prefix(&self) -> &(Confluent, Vec<f64>) {
        self.confluent.get_or_init(|| {
            let cf = Confluent::new(&self.model.rational().coefficients());
            let prefix = cf.prefix(&self.steps);
            (cf, prefix)
        })
    }

    /// `s(t)` with its gradient into `grad` from one state of the realisation, for a
    /// piecewise-constant input and a model without a modal form; `None` otherwise.
    fn realised_value_and_gradient(&self, t: f64, grad: &mut [f64]) -> Option<f64> {
        let (Input::Piecewise(_), None) = (&self.input, self.modal()) else {
            return None;
        };
        let (cf, prefix) = self.confluent_prefix();
        Some(cf.value_at(&self.steps, prefix, t, Some(grad)))
    }

    fn prefix_states(&self) -> Prefix {
        let poles: Vec<Complex64> = self
            .representatives()
            .iter()
            .map(|&(i, _)| self.modal_poles()[i])
            .collect();
        let np = poles.len();
        let zero = Complex64::new(0.0, 0.0);
        let (mut level, mut x, mut y) = (0.0, vec![zero; np], vec![zero; np]);
        let mut prev = f64::NEG_INFINITY;
        let mut out = Prefix {
            levels: Vec::with_capacity(self.steps.len()),
            x: Vec::with_capacity(self.steps.len() * np),
            y: Vec::with_capacity(self.steps.len() * np),
        };
        for &(tj, du) in &self.steps {
            for i in 0..np {
                if prev.is_finite() {
                    // X ← e^{pδ} X, Y ← e^{pδ} (Y + δ X): both sums move to the new origin t_j.
                    let delta = tj - prev;
                    let e = (poles[i] * delta).exp();
                    y[i] = e * (y[i] + delta * x[i]);
                    x[i] *= e;
                }
                x[i] += du;
            }
            level += du;
            prev = tj;
            out.levels.push(level);
            out.x.extend_from_slice(&x);
            out.y.extend_from_slice(&y);
        }
        out
    }

    /// The state of the linear response at `t`, for a piecewise-constant input: the input
    /// level `u(t)` and, per representative pole `p_i` (one of each conjugate pair, in the order
    /// of [`Modal::poles`] restricted to `Im p ≥ 0`), `x_i(t) = Σ_{t_j ≤ t} Δu_j e^{p_i(t − t_j)}`
    /// and `y_i(t) = Σ_{t_j ≤ t} Δu_j (t − t_j) e^{p_i(t − t_j)} = ∂x_i/∂p_i`. Then
    /// `s(t) = G(0) u(t) + Σ_i w_i Re((r_i/p_i) x_i(t))` (`w_i = 2` for a pair, 1 for a real pole).
    ///
    /// `O(log J + poles)` per instant, from states tabulated once per model at the input's
    /// steps. `None` for a tone input (whose response is a closed form in `t`) and for a
    /// model without a modal form (repeated poles, integrators: [`Rational::modal`]).
    ///
    /// [`Rational::modal`]: crate::Rational::modal
    pub fn state(&self, t: f64) -> Option<ModalState> {
        let Input::Piecewise(_) = self.input else {
            return None;
        };
        self.modal()?;
        let reps = self.representatives();
        let np = reps.len();
        let zero = Complex64::new(0.0, 0.0);
        let j = self.steps.partition_point(|s| s.0 <= t);
        if j == 0 {
            return Some(ModalState {
                level: 0.0,
                x: vec![zero; np],
                y: vec![zero; np],
            });
        }
        let prefix = self.prefix.get_or_init(|| self.prefix_states());
        let dt = t - self.steps[j - 1].0;
        let range = (j - 1) * np..j * np;
        let (x0, y0) = (&prefix.x[range.clone()], &prefix.y[range]);
        let mut state = ModalState {
            level: prefix.levels[j - 1],
            x: Vec::with_capacity(np),
            y: Vec::with_capacity(np),
        };
        for (k, &(i, _)) in reps.iter().enumerate() {
            let e = (self.modal_poles()[i] * dt).exp();
            state.x.push(e * x0[k]);
            state.y.push(e * (y0[k] + dt * x0[k]));
        }
        Some(state)
    }

    /// `s(t)` and `∂s(t)/∂θ_j` (into `grad`) together, in `O(log J + poles × params)` for a
    /// piecewise-constant input: what a composite model (a static nonlinearity of this response)
    /// needs at each instant.
    pub fn value_and_gradient(&self, t: f64, grad: &mut [f64]) -> f64 {
        if let Some(s) = self.realised_value_and_gradient(t, grad) {
            return s;
        }
        let Some(state) = self.state(t) else {
            self.value_gradient(t, grad);
            return self.value(t);
        };
        let Some(m) = self.modal() else {
            return 0.0;
        };
        let reps = self.representatives();
        let mut s = m.dc_gain * state.level;
        for (&(i, w), x) in reps.iter().zip(&state.x) {
            s += w * (m.residues[i] / m.poles[i] * x).re;
        }
        for (j, g) in grad.iter_mut().enumerate() {
            // ∂/∂θ_j of G(0)·u + Re Σ (r/p) x, with ∂x/∂θ_j = y ∂p/∂θ_j.
            let mut d = m.d_dc_gain.get(j).copied().unwrap_or(0.0) * state.level;
            for ((&(i, w), x), y) in reps.iter().zip(&state.x).zip(&state.y) {
                let (p, r) = (m.poles[i], m.residues[i]);
                let (Some(&dp), Some(&dr)) = (m.d_poles[i].get(j), m.d_residues[i].get(j)) else {
                    continue;
                };
                let d_rp = dr / p - r * dp / (p * p);
                d += w * (d_rp * x + r / p * y * dp).re;
            }
            *g = d;
        }
        s
    }

    /// `ṡ(t)` for a piecewise-constant input, away from the input's steps: `Σ_i r_i x_i(t)`
    /// (the feed-through's jumps at the steps are left out). `None` for a tone input.
    pub fn rate_at(&self, t: f64) -> Option<f64> {
        let Input::Piecewise(_) = self.input else {
            return None;
        };
        let Some(m) = self.modal() else {
            let (cf, prefix) = self.confluent_prefix();
            return Some(cf.rate_at(&self.steps, prefix, t));
        };
        let state = self.state(t)?;
        Some(
            self.representatives()
                .iter()
                .zip(&state.x)
                .map(|(&(i, w), x)| w * (m.residues[i] * x).re)
                .sum(),
        )
    }

    /// `E[ṡ(t_k + τ)]` for a piecewise-constant input, exactly: `Re Σ_i w_i r_i A_ik` plus,
    /// with a direct feed-through `D`, its jumps `D Σ_j Δu_j f_τ(t_j − t_k)` through the
    /// jitter's density `f_τ` (an atom of the jitter that meets a step makes `m_k` jump, where
    /// it has no derivative; that part is left out). `None` for a tone input.
    ///
    /// This is `∂m_k/∂t0`, what the gradient of a delayed response needs.
    pub fn expected_rates(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Option<Vec<f64>> {
        let Input::Piecewise(_) = self.input else {
            return None;
        };
        let (mut out, direct) = match self.modal() {
            Some(m) => {
                let reps = self.representatives();
                let mut out = Vec::with_capacity(grid.len());
                self.modal_expectations(grid, jitter, &reps, false, |_, a, _| {
                    out.push(
                        reps.iter()
                            .zip(a)
                            .map(|(&(i, w), a)| w * (m.residues[i] * a).re)
                            .sum(),
                    );
                });
                (out, m.direct)
            }
            None => {
                let (cf, _) = self.confluent_prefix();
                let direct = self.model.rational().num()[0];
                (cf.expected_rates(&self.steps, grid, jitter), direct)
            }
        };
        if direct != 0.0 {
            let (lo, hi) = jitter.reach();
            self.walk(grid, lo, hi, &[], false, |k, t, _, _, _, in_reach| {
                let jumps: f64 = in_reach
                    .iter()
                    .map(|&(tj, du)| du * jitter.pdf(tj - t))
                    .sum();
                out[k] += direct * jumps;
            });
        }
        Some(out)
    }

    /// The model `G`.
    pub fn model(&self) -> &M {
        &self.model
    }

    /// The input.
    pub fn input(&self) -> &Input {
        &self.input
    }

    /// The input's steps `(t_j, Δu_j)` (empty for tones).
    pub fn steps(&self) -> &[(f64, f64)] {
        &self.steps
    }

    fn modal(&self) -> Option<&Modal> {
        self.model.modal()
    }

    /// The modal form, in the routes taken only when there is one (empty without).
    fn modal_poles(&self) -> &[Complex64] {
        self.modal().map_or(&[], |m| &m.poles)
    }

    /// One representative per conjugate pair (upper half plane) and each real pole, with its
    /// multiplicity in `Re Σ`: the sum over all poles of a real quantity is `Σ w·Re(term)`.
    fn representatives(&self) -> Vec<(usize, f64)> {
        self.modal_poles()
            .iter()
            .enumerate()
            .filter_map(|(i, p)| match p.im.partial_cmp(&0.0) {
                Some(std::cmp::Ordering::Greater) => Some((i, 2.0)),
                Some(std::cmp::Ordering::Equal) => Some((i, 1.0)),
                _ => None,
            })
            .collect()
    }

    /// Visits every sample `k` in order with `C_k = E[Σ_j Δu_j 1{x ≥ 0}]` and, per
    /// representative pole, `A_ik = E[Σ_j Δu_j e^{p_i x} 1{x ≥ 0}]` and
    /// `B_ik = E[Σ_j Δu_j x e^{p_i x} 1{x ≥ 0}]`, with `x = t_k + τ − t_j` (`B` only when
    /// `with_b`, empty otherwise). Handing them to the caller sample by sample, instead of
    /// storing them, keeps the work memory of a long record at `O(poles)`.
    ///
    /// Steps past the reach go through the state recursion of [`walk`](Self::walk); a step
    /// inside it at `c = t_j − t_k` needs `P(τ ≥ c)`, `E[e^{p_i(τ−c)} 1{τ ≥ c}]` and
    /// `E[(τ−c) e^{p_i(τ−c)} 1{τ ≥ c}]`, functions of `c` alone that [`InReach`] tabulates once
    /// per evaluation when enough steps ask for them.
    fn modal_expectations(
        &self,
        grid: &SampleGrid,
        jitter: &dyn JitterModel,
        reps: &[(usize, f64)],
        with_b: bool,
        mut visit: impl FnMut(f64, &[Complex64], &[Complex64]),
    ) {
        let poles: Vec<Complex64> = reps.iter().map(|&(i, _)| self.modal_poles()[i]).collect();
        let np = poles.len();
        let (lo, hi) = jitter.reach();
        let mut queries = 0;
        self.walk(grid, lo, hi, &[], false, |_, _, _, _, _, in_reach| {
            queries += in_reach.len();
        });
        let reach = InReach::new(jitter, &poles, with_b, Route::Auto(queries));
        // E[1], E[e^{p(τ − lo)}] and E[(τ − lo) e^{p(τ − lo)}] over the whole reach: bounded
        // because Re p < 0 and τ − lo ≥ 0.
        let start = reach.at_start();
        let mass = start[0].re;
        let (m0, m1) = start[1..].split_at(np);

        let zero = Complex64::new(0.0, 0.0);
        let mut a = vec![zero; np];
        let mut b = if with_b { vec![zero; np] } else { Vec::new() };
        let mut v = vec![zero; reach.width()];
        self.walk(
            grid,
            lo,
            hi,
            &poles,
            with_b,
            |_, t, u_past, x, y, in_reach| {
                let mut c = u_past * mass;
                for i in 0..np {
                    a[i] = x[i] * m0[i];
                    if with_b {
                        b[i] = y[i] * m0[i] + x[i] * m1[i];
                    }
                }
                for &(tj, du) in in_reach {
                    reach.eval(tj - t, &mut v);
                    c += du * v[0].re;
                    for i in 0..np {
                        a[i] += du * v[1 + i];
                        if with_b {
                            b[i] += du * v[1 + np + i];
                        }
                    }
                }
                visit(c, &a, &b);
            },
        );
    }

    /// Visits every sample `k` with the state of the steps already fully past its reach,
    /// `u_past = Σ Δu_j`, `x_i = Σ Δu_j e^{p_i a_j}` and (when `with_y`)
    /// `y_i = Σ Δu_j a_j e^{p_i a_j}` with `a_j = t_k + lo − t_j ≥ 0`, and the steps inside the
    /// reach `(t_k + lo, t_k + hi)`. The state is carried by `x ← e^{p_i T} x`: `O(N + J)` in all.
    fn walk(
        &self,
        grid: &SampleGrid,
        lo: f64,
        hi: f64,
        poles: &[Complex64],
        with_y: bool,
        mut visit: impl FnMut(usize, f64, f64, &[Complex64], &[Complex64], &[(f64, f64)]),
    ) {
        let np = poles.len();
        let decay: Vec<Complex64> = poles.iter().map(|p| (p * grid.interval()).exp()).collect();
        let mut u_past = 0.0;
        let mut x = vec![Complex64::new(0.0, 0.0); np];
        let mut y = vec![Complex64::new(0.0, 0.0); np];
        let mut next_past = 0usize;
        // Both ends only move forward with `t`: O(N + J) in all, where a binary search per
        // sample would cost O(N log J) and dominate long records.
        let mut reach_end = 0usize;
        let steps = &self.steps;
        for k in 0..grid.len() {
            let t = grid.time(k);
            if k > 0 {
                for i in 0..np {
                    if with_y {
                        y[i] = decay[i] * (y[i] + grid.interval() * x[i]);
                    }
                    x[i] *= decay[i];
                }
            }
            while next_past < steps.len() && steps[next_past].0 <= t + lo {
                let (tj, du) = steps[next_past];
                let a = t + lo - tj;
                u_past += du;
                for i in 0..np {
                    let e = (poles[i] * a).exp() * du;
                    x[i] += e;
                    if with_y {
                        y[i] += e * a;
                    }
                }
                next_past += 1;
            }
            reach_end = reach_end.max(next_past);
            while reach_end < steps.len() && steps[reach_end].0 <= t + hi {
                reach_end += 1;
            }
            if budget::spent() {
                // The rest of the record is left unfinished: NaN states and no steps in reach
                // (whose rules are the expensive part), which the caller's budget reports.
                x.iter_mut()
                    .chain(y.iter_mut())
                    .for_each(|v| *v = Complex64::new(f64::NAN, 0.0));
                for k in k..grid.len() {
                    visit(k, grid.time(k), f64::NAN, &x, &y, &[]);
                }
                return;
            }
            visit(k, t, u_past, &x, &y, &steps[next_past..reach_end]);
        }
    }
}

/// The linear response's state at one instant; see [`LtiResponse::state`].
#[derive(Debug, Clone, PartialEq)]
pub struct ModalState {
    /// The input level `u(t)`.
    pub level: f64,
    /// `x_i(t) = Σ_{t_j ≤ t} Δu_j e^{p_i(t − t_j)}` per representative pole.
    pub x: Vec<Complex64>,
    /// `y_i(t) = Σ_{t_j ≤ t} Δu_j (t − t_j) e^{p_i(t − t_j)}` per representative pole.
    pub y: Vec<Complex64>,
}

/// The serialized form of an [`LtiResponse`].
#[derive(serde::Serialize, serde::Deserialize)]
struct LtiFields<M> {
    model: M,
    input: Input,
}

impl<M: RationalModel> TryFrom<LtiFields<M>> for LtiResponse<M> {
    type Error = SignalError;
    fn try_from(f: LtiFields<M>) -> Result<Self, SignalError> {
        Ok(Self::new(f.model, f.input))
    }
}

impl<M: RationalModel> From<LtiResponse<M>> for LtiFields<M> {
    fn from(r: LtiResponse<M>) -> Self {
        Self {
            model: r.model,
            input: r.input,
        }
    }
}

/// [`ModalState`] right after each input step (row-major over representative poles).
#[derive(Debug, Clone, PartialEq, Default)]
struct Prefix {
    levels: Vec<f64>,
    x: Vec<Complex64>,
    y: Vec<Complex64>,
}

impl<M: RationalModel> Signal for LtiResponse<M> {
    fn param_names(&self) -> Vec<String> {
        self.model.param_names()
    }

    fn params(&self) -> Vec<f64> {
        self.model.params()
    }

    fn with_params(&self, params: &[f64]) -> Result<Self, SignalError> {
        Ok(Self {
            model: self.model.with_params(params)?,
            input: self.input.clone(),
            steps: self.steps.clone(),
            prefix: OnceLock::new(),
            confluent: OnceLock::new(),
        })
    }

    fn value(&self, t: f64) -> f64 {
        match &self.input {
            Input::Tones(m) => m
                .tones()
                .iter()
                .map(|c| {
                    let g = self.model.frequency_response(c.frequency);
                    (g * Complex64::from_polar(c.amplitude, TAU * c.frequency * t + c.phase)).im
                })
                .sum(),
            Input::Piecewise(_) => {
                let j = self.steps.partition_point(|s| s.0 <= t);
                if j == 0 {
                    return 0.0;
                }
                let Some(m) = self.modal() else {
                    let (cf, prefix) = self.confluent_prefix();
                    return cf.value_at(&self.steps, prefix, t, None);
                };
                let reps = self.representatives();
                let prefix = self.prefix.get_or_init(|| self.prefix_states());
                let x = &prefix.x[(j - 1) * reps.len()..j * reps.len()];
                let dt = t - self.steps[j - 1].0;
                let mut s = m.dc_gain * prefix.levels[j - 1];
                for (&(i, w), xi) in reps.iter().zip(x) {
                    let (p, r) = (m.poles[i], m.residues[i]);
                    s += w * (r / p * xi * (p * dt).exp()).re;
                }
                s
            }
        }
    }

    fn value_gradient(&self, t: f64, grad: &mut [f64]) {
        grad.iter_mut().for_each(|g| *g = 0.0);
        match &self.input {
            Input::Tones(m) => {
                let mut dg = vec![Complex64::new(0.0, 0.0); grad.len()];
                for c in m.tones() {
                    let s = Complex64::new(0.0, TAU * c.frequency);
                    self.model.rational().response_gradient(s, &mut dg);
                    let e = Complex64::from_polar(c.amplitude, TAU * c.frequency * t + c.phase);
                    for (g, d) in grad.iter_mut().zip(&dg) {
                        *g += (d * e).im;
                    }
                }
            }
            Input::Piecewise(_) => {
                self.value_and_gradient(t, grad);
            }
        }
    }

    /// Without a modal form (the realisation's route), one state serves both; otherwise as
    /// provided.
    fn value_and_gradient(&self, t: f64, grad: &mut [f64]) -> f64 {
        if let Some(s) = self.realised_value_and_gradient(t, grad) {
            return s;
        }
        self.value_gradient(t, grad);
        self.value(t)
    }

    fn breakpoints(&self) -> Vec<f64> {
        self.steps.iter().map(|s| s.0).collect()
    }

    fn rate(&self) -> f64 {
        let poles = self.model.rational().poles().iter().map(|p| p.norm());
        let tones = match &self.input {
            Input::Tones(m) => m.tones().iter().map(|c| TAU * c.frequency).collect(),
            Input::Piecewise(_) => Vec::new(),
        };
        poles.chain(tones).fold(0.0, f64::max)
    }

    fn expected_squares(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Vec<f64> {
        match self.input {
            Input::Tones(_) => self.tones_squares(grid, jitter),
            Input::Piecewise(_) => self.piecewise_squares(grid, jitter),
        }
    }

    fn expected_values(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Vec<f64> {
        if let Input::Tones(_) = self.input {
            return self.tones_expectation(grid, jitter, None);
        }
        let Some(m) = self.modal() else {
            let (cf, _) = self.confluent_prefix();
            return cf.expected_values(&self.steps, grid, jitter);
        };
        let reps = self.representatives();
        let coef = value_terms(m, &reps);
        let mut out = Vec::with_capacity(grid.len());
        self.modal_expectations(grid, jitter, &reps, false, |c, a, _| {
            out.push(expected_value(m, &coef, c, a));
        });
        out
    }

    fn expected_values_gradient(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Jacobian {
        let np = self.model.params().len();
        if let Input::Tones(_) = self.input {
            let mut cols = vec![vec![0.0; grid.len()]; np];
            self.tones_expectation(grid, jitter, Some(&mut cols));
            return cols;
        }
        let Some(m) = self.modal() else {
            let (cf, _) = self.confluent_prefix();
            return cf.expected_values_and_gradient(&self.steps, grid, jitter).1;
        };
        let reps = self.representatives();
        let terms = gradient_terms(m, &reps, np);
        let mut cols: Jacobian = (0..np).map(|_| Vec::with_capacity(grid.len())).collect();
        self.modal_expectations(grid, jitter, &reps, true, |c, a, b| {
            push_gradient(m, &terms, &mut cols, c, a, b);
        });
        cols
    }

    fn expected_values_and_gradient(
        &self,
        grid: &SampleGrid,
        jitter: &dyn JitterModel,
    ) -> (Vec<f64>, Jacobian) {
        if let Input::Tones(_) = self.input {
            return (
                self.expected_values(grid, jitter),
                self.expected_values_gradient(grid, jitter),
            );
        }
        let np = self.model.params().len();
        let Some(m) = self.modal() else {
            let (cf, _) = self.confluent_prefix();
            return cf.expected_values_and_gradient(&self.steps, grid, jitter);
        };
        let reps = self.representatives();
        let coef = value_terms(m, &reps);
        let terms = gradient_terms(m, &reps, np);
        let mut values = Vec::with_capacity(grid.len());
        let mut cols: Jacobian = (0..np).map(|_| Vec::with_capacity(grid.len())).collect();
        self.modal_expectations(grid, jitter, &reps, true, |c, a, b| {
            values.push(expected_value(m, &coef, c, a));
            push_gradient(m, &terms, &mut cols, c, a, b);
        });
        (values, cols)
    }
}

/// The coefficients `(r_i/p_i, w_i)` of `m_k = G(0)·C + Re Σ_i w_i (r_i/p_i) A_i`.
fn value_terms(m: &Modal, reps: &[(usize, f64)]) -> Vec<(Complex64, f64)> {
    reps.iter()
        .map(|&(i, w)| (m.residues[i] / m.poles[i], w))
        .collect()
}

/// `m_k` from the sample's `C` and `A_i`.
fn expected_value(m: &Modal, coef: &[(Complex64, f64)], c: f64, a: &[Complex64]) -> f64 {
    m.dc_gain * c
        + coef
            .iter()
            .zip(a)
            .map(|(&(r, w), a)| w * (r * a).re)
            .sum::<f64>()
}

/// Per parameter `j`, the coefficients of `∂/∂θ_j` of `G(0)·C + Re Σ (r/p) A`, with
/// `∂A/∂p = B`.
fn gradient_terms(
    m: &Modal,
    reps: &[(usize, f64)],
    np: usize,
) -> Vec<Vec<(Complex64, Complex64, f64)>> {
    (0..np)
        .map(|j| {
            reps.iter()
                .map(|&(i, w)| {
                    let (p, r) = (m.poles[i], m.residues[i]);
                    let (dp, dr) = (m.d_poles[i][j], m.d_residues[i][j]);
                    (dr / p - r * dp / (p * p), r / p * dp, w)
                })
                .collect()
        })
        .collect()
}

/// Appends one sample's `∂m_k/∂θ_j` to every column.
fn push_gradient(
    m: &Modal,
    terms: &[Vec<(Complex64, Complex64, f64)>],
    cols: &mut Jacobian,
    c: f64,
    a: &[Complex64],
    b: &[Complex64],
) {
    for ((col, terms), d_dc) in cols.iter_mut().zip(terms).zip(&m.d_dc_gain) {
        col.push(
            d_dc * c
                + terms
                    .iter()
                    .enumerate()
                    .map(|(i, &(d_rp, rp_dp, w))| w * (d_rp * a[i] + rp_dp * b[i]).re)
                    .sum::<f64>(),
        );
    }
}

impl<M: RationalModel> Spectrum for LtiResponse<M> {
    fn density(&self, f: f64) -> Complex64 {
        match &self.input {
            Input::Piecewise(p) => self.model.frequency_response(f) * p.spectrum(f),
            Input::Tones(_) => Complex64::new(0.0, 0.0),
        }
    }

    fn density_gradient(&self, f: f64, grad: &mut [Complex64]) {
        match &self.input {
            Input::Piecewise(p) => {
                let s = Complex64::new(0.0, TAU * f);
                self.model.rational().response_gradient(s, grad);
                let u = p.spectrum(f);
                grad.iter_mut().for_each(|g| *g *= u);
            }
            Input::Tones(_) => grad.iter_mut().for_each(|g| *g = Complex64::new(0.0, 0.0)),
        }
    }

    fn lines(&self) -> Vec<SpectralLine> {
        let Input::Tones(m) = &self.input else {
            return Vec::new();
        };
        let mut out = Vec::with_capacity(2 * m.tones().len());
        for c in m.tones() {
            // A sin(θ) = (A e^{iθ} − A e^{−iθ}) / (2i), each side scaled by G at its frequency.
            let g = self.model.frequency_response(c.frequency);
            let pos = g * Complex64::from_polar(c.amplitude, c.phase) / Complex64::new(0.0, 2.0);
            out.push(SpectralLine {
                frequency: c.frequency,
                coefficient: pos,
            });
            out.push(SpectralLine {
                frequency: -c.frequency,
                coefficient: pos.conj(),
            });
        }
        out
    }

    fn lines_gradient(&self) -> Vec<Vec<(Complex64, f64)>> {
        let Input::Tones(m) = &self.input else {
            return Vec::new();
        };
        let np = self.model.params().len();
        let mut dg = vec![Complex64::new(0.0, 0.0); np];
        let mut out = Vec::new();
        for c in m.tones() {
            let s = Complex64::new(0.0, TAU * c.frequency);
            self.model.rational().response_gradient(s, &mut dg);
            let k = Complex64::from_polar(c.amplitude, c.phase) / Complex64::new(0.0, 2.0);
            out.push(dg.iter().map(|d| (d * k, 0.0)).collect());
            out.push(dg.iter().map(|d| ((d * k).conj(), 0.0)).collect());
        }
        out
    }
}
#[cfg(test)]
mod tests {
    use super::*;
    use crate::{PiecewiseConstant, Root, TransferFunction, Zpk};
    use jitterid_jitter::{ExponentialDelay, Gaussian, Laplace, Shifted, TwoPoint, UniformSum};

    /// The expanded second moment against the quadrature route, where both apply: inputs
    /// switching inside the reach (also exactly on the sample grid, on atoms and knots), direct
    /// feed-through, a complex pair and a real pole. Both are exact; the expansion rounds at
    /// `ε (|C| + Σ|a_i|)²`, which here is `≲ 1e-14` of `max E[s²]`, so `1e-12` of it is tight.
    #[test]
    fn expanded_squares_equal_quadrature() {
        let levels: Vec<f64> = (0..40)
            .map(|i| ((i * 37) % 11) as f64 / 5.0 - 1.0)
            .collect();
        let u = PiecewiseConstant::zero_order_hold(-5.0, 0.5, &levels).unwrap();
        let zpk = Zpk::new(
            1.5,
            vec![Root::Real(-2.0)],
            vec![Root::Pair { re: -0.6, im: 2.5 }, Root::Real(-1.3)],
        )
        .unwrap();
        let tf = TransferFunction::new(&[0.3, 1.0, 0.8], &[1.0, 1.5, 0.9]).unwrap();
        let grid = SampleGrid::new(0.0, 0.5, 24).unwrap();
        let jitters: Vec<Box<dyn JitterModel>> = vec![
            Box::new(UniformSum::new(0, 0.5).unwrap()),
            Box::new(UniformSum::new(3, 1.2).unwrap()),
            Box::new(Gaussian::new(0.3).unwrap()),
            Box::new(Laplace::new(0.2).unwrap()),
            Box::new(TwoPoint::new(0.5).unwrap()),
            Box::new(ExponentialDelay::new(0.25).unwrap()),
            Box::new(Shifted::new(TwoPoint::new(0.25).unwrap(), 0.25).unwrap()),
        ];
        let check = |quad: Vec<f64>, expanded: Vec<f64>, name: &str| {
            let scale = quad.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (k, (x, y)) in quad.iter().zip(&expanded).enumerate() {
                assert!(
                    (x - y).abs() <= 1e-12 * scale,
                    "{name}: E[s²][{k}] quadrature {x} vs expanded {y}"
                );
            }
        };
        for j in &jitters {
            let j = j.as_ref();
            let s = LtiResponse::new(zpk.clone(), u.clone());
            let (poles, coef) = parts_of(&s);
            check(
                s.piecewise_squares(&grid, j),
                s.squares_by_expansion(&grid, j, &poles, &coef),
                j.name(),
            );
            let s = LtiResponse::new(tf.clone(), u.clone());
            let (poles, coef) = parts_of(&s);
            check(
                s.piecewise_squares(&grid, j),
                s.squares_by_expansion(&grid, j, &poles, &coef),
                j.name(),
            );
        }
    }

    fn parts_of<M: RationalModel>(s: &LtiResponse<M>) -> (Vec<Complex64>, Vec<Complex64>) {
        let m = s.modal().unwrap();
        let reps = s.representatives();
        (
            reps.iter().map(|&(i, _)| m.poles[i]).collect(),
            reps.iter()
                .map(|&(i, w)| m.residues[i] / m.poles[i] * w)
                .collect(),
        )
    }

    #[test]
    fn fast_lightly_damped_pole_second_moment_is_cheap_and_finite() {
        // |p| = 1e12 with Re p = −0.8 (found by the fuzzer): the quadrature would need
        // |p|/|Re p| nodes per piece; the expansion needs none.
        let g = Zpk::new(
            1.0,
            vec![],
            vec![Root::Pair { re: -0.8, im: 1e12 }, Root::Real(-25.0)],
        )
        .unwrap();
        let u = PiecewiseConstant::new(vec![-3.0, 0.31, 0.6, 2.0], vec![1.0, -0.5, 0.25]).unwrap();
        let s = LtiResponse::new(g, u);
        let grid = SampleGrid::new(0.0, 0.1, 20).unwrap();
        let j = ExponentialDelay::new(0.15).unwrap();
        // Results only: the cost is timed by `cargo bench -p jitterid --bench wide_jitter`.
        let sq = s.expected_squares(&grid, &j);
        let m = s.expected_values(&grid, &j);
        for (k, (q, v)) in sq.iter().zip(&m).enumerate() {
            // E[s²] ≥ (E s)², up to rounding.
            assert!(q.is_finite() && *q >= v * v - 1e-12, "{k}: {q} vs {v}²");
        }
    }
}
