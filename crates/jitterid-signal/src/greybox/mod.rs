//! Grey-box continuous-time state space: `ẋ = A(θ)x + B(θ)u`, `y = C(θ)x + D(θ)u` with named
//! physical parameters `θ`, driven by a known piecewise-constant input, with exact jittered
//! moments and analytic parameter gradients.
//!
//! # Routes
//!
//! Two exact routes, as for a transfer function (modal form where it exists, a realisation
//! where it breaks down), chosen at construction:
//!
//! * **Distinct poles**: the transfer function `C adj(sI − A) B / det(sI − A) + D` with the
//!   exact derivatives of its coefficients with respect to `θ` (forward-mode
//!   Faddeev–LeVerrier, `rational.rs`) goes through the modal form of
//!   [`LtiResponse`]: a grey-box fit then costs what the coefficient fit
//!   costs. The augmented realisation below costs 6.5× the modal form for `m_k` and its
//!   gradient (`docs/performance.md`), which a fit pays at every evaluation.
//! * **Repeated poles, integrators** (no modal form), and wherever the coefficients cannot be
//!   rooted: the augmented matrix exponential below. Tests hold the two routes equal where both
//!   exist.
//!
//! The parameter sensitivities of a linear system are the states of a larger linear system.
//! Differentiating `ẋ = Ax + Bu` with respect to `θ_j` gives
//! `d/dt ∂x/∂θ_j = A_j x + A ∂x/∂θ_j + B_j u` (`A_j = ∂A/∂θ_j`, `B_j = ∂B/∂θ_j`), so the state
//! `z = [x; ∂x/∂θ_1; …; ∂x/∂θ_p; u]` (the input level a state of its own, constant between
//! steps) obeys `ż = Mz` with
//!
//! ```text
//!       ⎡ A    0  …  0   B   ⎤
//!   M = ⎢ A_1  A  …  0   B_1 ⎥        y        = C x + D u
//!       ⎢ ⋮       ⋱      ⋮   ⎥        ∂y/∂θ_j  = C_j x + C ∂x/∂θ_j + D_j u
//!       ⎢ A_p  0  …  A   B_p ⎥
//!       ⎣ 0    0  …  0   0   ⎦
//! ```
//!
//! and the response and every `∂y/∂θ_j` are readouts of `z` — the linear readout system that
//! the confluent route of rational models already evaluates, jittered moments included (see
//! `confluent.rs`). A parameter that enters only `C` or `D` needs no sensitivity block
//! (`∂x/∂θ_j = 0`) and gets none, so the state is as small as the model allows. No finite
//! difference over `θ` is taken anywhere: `A_j, B_j, C_j, D_j` come from the model, by default
//! by forward-mode differentiation of the matrices ([`Dual`] numbers, one pass per parameter).
//!
//! The spectrum is `G(i2πf) U(f)` with `G(s) = C(sI − A)⁻¹B + D` and
//! `∂G/∂θ_j = C_j R B + C R A_j R B + C R B_j + D_j`, `R = (sI − A)⁻¹`, by two small complex
//! solves per frequency.

mod expressions;
mod rational;

pub use rational::GreyTf;

pub use expressions::{Entry, ExprModel, WrittenMatrices, GREY_BOX};

use crate::confluent::Confluent;
use crate::forms::{StateSpace, TfForm};
use crate::input::Input;
use crate::signal::{Jacobian, Signal};
use crate::spectrum::Spectrum;
use crate::{LtiResponse, RationalModel, SampleGrid, SignalError};
use jitterid_jitter::JitterModel;
use jitterid_numeric::dual::{Dual, Real};
use num_complex::Complex64;
use std::f64::consts::TAU;
use std::fmt;
use std::sync::OnceLock;

/// The matrices of a single-input single-output state-space model: `A` (`n × n`, by rows),
/// `B` (the column, `n` entries), `C` (the row, `n` entries) and `D`.
#[derive(Debug, Clone, PartialEq)]
pub struct StateMatrices<R> {
    /// `A`, by rows.
    pub a: Vec<Vec<R>>,
    /// `B`, the input column.
    pub b: Vec<R>,
    /// `C`, the output row.
    pub c: Vec<R>,
    /// `D`, the feed-through.
    pub d: R,
}

impl<R: Real> StateMatrices<R> {
    /// Every entry's value (the derivative dropped).
    pub fn values(&self) -> StateMatrices<f64> {
        StateMatrices {
            a: self
                .a
                .iter()
                .map(|r| r.iter().map(|x| x.value()).collect())
                .collect(),
            b: self.b.iter().map(|x| x.value()).collect(),
            c: self.c.iter().map(|x| x.value()).collect(),
            d: self.d.value(),
        }
    }
}

impl StateMatrices<Dual> {
    /// Every entry's derivative.
    fn derivatives(&self) -> StateMatrices<f64> {
        StateMatrices {
            a: self
                .a
                .iter()
                .map(|r| r.iter().map(|x| x.derivative).collect())
                .collect(),
            b: self.b.iter().map(|x| x.derivative).collect(),
            c: self.c.iter().map(|x| x.derivative).collect(),
            d: self.d.derivative,
        }
    }
}

/// A grey-box state-space model: the matrices `A(θ), B(θ), C(θ), D(θ)` as functions of named
/// parameters. Implement [`matrices`](Self::matrices) once, generically over [`Real`], and the
/// derivatives come by forward-mode differentiation; a model that knows its derivatives in
/// closed form overrides [`derivatives`](Self::derivatives).
///
/// ```
/// use jitterid_numeric::dual::Real;
/// use jitterid_signal::greybox::{GreyBox, StateMatrices, StateSpaceModel};
/// use jitterid_signal::{PiecewiseConstant, Signal};
///
/// /// Mass–spring–damper: force in, position out; θ = [m, damp, k].
/// #[derive(Debug, Clone)]
/// struct Msd;
/// impl StateSpaceModel for Msd {
///     fn param_names(&self) -> Vec<String> {
///         vec!["m".into(), "damp".into(), "k".into()]
///     }
///     fn matrices<R: Real>(&self, th: &[R]) -> StateMatrices<R> {
///         let (m, damp, k) = (th[0], th[1], th[2]);
///         let (zero, one) = (R::constant(0.0), R::constant(1.0));
///         StateMatrices {
///             a: vec![vec![zero, one], vec![-k / m, -damp / m]],
///             b: vec![zero, one / m],
///             c: vec![one, zero],
///             d: zero,
///         }
///     }
/// }
/// let input = PiecewiseConstant::new(vec![0.0, 5.0], vec![1.0]).unwrap();
/// let g = GreyBox::new(Msd, vec![1.0, 0.4, 2.0], input).unwrap();
/// assert_eq!(g.param_names(), ["m", "damp", "k"]);
/// let mut grad = [0.0; 3];
/// let y = g.value_and_gradient(3.0, &mut grad);
/// assert!(y > 0.0 && grad.iter().all(|g| g.is_finite()));
/// ```
pub trait StateSpaceModel: fmt::Debug + Clone + Send + Sync {
    /// The parameters' names, in order.
    fn param_names(&self) -> Vec<String>;

    /// The matrices at `θ` (one entry of `theta` per name). Their shapes are checked by
    /// [`GreyBox::new`].
    fn matrices<R: Real>(&self, theta: &[R]) -> StateMatrices<R>;

    /// Refuses parameters outside the model's domain (a negative mass); accepts all by default.
    ///
    /// # Errors
    ///
    /// A typed error naming the parameter.
    fn check(&self, theta: &[f64]) -> Result<(), SignalError> {
        let _ = theta;
        Ok(())
    }

    /// `∂(A, B, C, D)/∂θ_j` for every parameter. Provided: one forward-mode pass of
    /// [`matrices`](Self::matrices) per parameter, exact to rounding.
    fn derivatives(&self, theta: &[f64]) -> Vec<StateMatrices<f64>> {
        (0..theta.len())
            .map(|j| {
                let seeded: Vec<Dual> = theta
                    .iter()
                    .enumerate()
                    .map(|(i, &x)| Dual::seeded(x, i == j))
                    .collect();
                self.matrices(&seeded).derivatives()
            })
            .collect()
    }
}

/// The response of a [`StateSpaceModel`] at parameters `θ` to a known piecewise-constant
/// input, from rest, exactly; see the [module documentation](self).
#[derive(Clone)]
pub struct GreyBox<M> {
    model: M,
    theta: Vec<f64>,
    input: Input,
    steps: Vec<(f64, f64)>,
    mats: StateMatrices<f64>,
    derivs: Vec<StateMatrices<f64>>,
    poles: Vec<Complex64>,
    /// The modal route, when the transfer function has a modal form.
    modal: Option<LtiResponse<GreyTf<M>>>,
    /// The augmented realisation, built on the first evaluation.
    realised: OnceLock<Confluent>,
    /// Its state right after every step, for evaluations in time.
    prefix: OnceLock<Vec<f64>>,
}

impl<M: fmt::Debug> fmt::Debug for GreyBox<M> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("GreyBox")
            .field("model", &self.model)
            .field("theta", &self.theta)
            .field("matrices", &self.mats)
            .finish()
    }
}

impl<M: StateSpaceModel> GreyBox<M> {
    /// The response of `model` at `theta` to `input` (piecewise constant).
    ///
    /// # Errors
    ///
    /// A parameter count that is not the model's, a parameter the model's
    /// [`check`](StateSpaceModel::check) refuses, matrices of inconsistent shapes or with a
    /// non-finite entry, a pole right of the imaginary axis, tones as the input.
    pub fn new(model: M, theta: Vec<f64>, input: impl Into<Input>) -> Result<Self, SignalError> {
        let input = input.into();
        let names = model.param_names();
        if theta.len() != names.len() {
            return Err(SignalError::WrongParamCount {
                expected: names.len(),
                got: theta.len(),
            });
        }
        crate::error::all_finite("theta", &theta)?;
        model.check(&theta)?;
        let steps = match &input {
            Input::Piecewise(p) => p.steps(),
            Input::Tones(_) => {
                return Err(SignalError::NeedsSteps {
                    what: "a grey-box state-space model",
                })
            }
        };
        let (mats, derivs) = validated(&model, &theta)?;
        let poles = eigenvalues(&mats.a).ok_or(SignalError::Roots { name: "a" })?;
        let scale = poles.iter().map(|p| p.norm()).fold(1.0, f64::max);
        // The same tolerance as a transfer function's roots: a pole found a rounding error
        // right of the axis (an integrator) is on it.
        if let Some(p) = poles.iter().find(|p| p.re > 1e-12 * scale) {
            return Err(SignalError::Unstable { re: p.re, im: p.im });
        }
        // No modal form (repeated poles, integrators) or no rational form at all: the
        // augmented realisation serves alone.
        let modal = GreyTf::new(model.clone(), theta.clone(), &mats, &derivs)
            .ok()
            .filter(|g| g.rational().modal().is_some())
            .map(|g| LtiResponse::new(g, input.clone()));
        Ok(Self {
            model,
            theta,
            input,
            steps,
            mats,
            derivs,
            poles,
            modal,
            realised: OnceLock::new(),
            prefix: OnceLock::new(),
        })
    }

    /// The model.
    pub fn model(&self) -> &M {
        &self.model
    }

    /// The input.
    pub fn input(&self) -> &Input {
        &self.input
    }

    /// The matrices at the current parameters.
    pub fn matrices(&self) -> &StateMatrices<f64> {
        &self.mats
    }

    /// The matrices' derivatives, one per parameter.
    pub fn derivatives(&self) -> &[StateMatrices<f64>] {
        &self.derivs
    }

    /// The eigenvalues of `A` (the poles of the transfer function before any cancellation).
    pub fn poles(&self) -> &[Complex64] {
        &self.poles
    }

    /// The response through the model's transfer function ([`GreyTf`]): the same response
    /// and the same parameters, on the route of a `tf` system (modal where the poles are
    /// distinct, the realisation of the coefficients where they repeat), whose gradient is
    /// exact by the coefficients' forward-mode derivatives. An input delay and a free response
    /// are built on it.
    ///
    /// # Errors
    ///
    /// The coefficients cannot be rooted.
    pub fn transfer_response(&self) -> Result<LtiResponse<GreyTf<M>>, SignalError> {
        let tf = GreyTf::new(
            self.model.clone(),
            self.theta.clone(),
            &self.mats,
            &self.derivs,
        )?;
        Ok(LtiResponse::new(tf, self.input.clone()))
    }

    /// The realisation `(A, B, C, D)` at the current parameters, for export.
    pub fn state_space(&self) -> StateSpace {
        let m = &self.mats;
        StateSpace::from_parts(m.a.clone(), m.b.clone(), m.c.clone(), m.d)
    }

    /// The transfer function `C(sI − A)⁻¹B + D` (not reduced: a non-minimal model keeps its
    /// cancelling pole–zero pairs).
    ///
    /// # Errors
    ///
    /// A coefficient overflows.
    pub fn transfer_function(&self) -> Result<TfForm, SignalError> {
        self.state_space().to_tf()
    }

    /// `G(s)`.
    pub fn response(&self, s: Complex64) -> Complex64 {
        let m = &self.mats;
        let x = solve(&shifted(&m.a, s, false), &complex(&m.b));
        dot_c(&complex(&m.c), &x) + m.d
    }

    /// `∂G(s)/∂θ_j` into `grad`: `C_j R B + C R A_j R B + C R B_j + D_j`, `R = (sI − A)⁻¹`.
    pub fn response_gradient(&self, s: Complex64, grad: &mut [Complex64]) {
        let m = &self.mats;
        let rb = solve(&shifted(&m.a, s, false), &complex(&m.b));
        // (C R)ᵀ = R ᵀCᵀ: the transposed solve.
        let cr = solve(&shifted(&m.a, s, true), &complex(&m.c));
        for (g, d) in grad.iter_mut().zip(&self.derivs) {
            let a_rb: Vec<Complex64> =
                d.a.iter()
                    .map(|row| row.iter().zip(&rb).map(|(a, x)| x * a).sum())
                    .collect();
            *g = dot_c(&complex(&d.c), &rb) + dot_c(&cr, &a_rb) + dot_c(&cr, &complex(&d.b)) + d.d;
        }
    }

    /// `G(i2πf)`.
    pub fn frequency_response(&self, f: f64) -> Complex64 {
        self.response(Complex64::new(0.0, TAU * f))
    }

    /// The same model without its modal route: the augmented realisation alone (the tests'
    /// second route).
    #[cfg(test)]
    fn augmented_only(mut self) -> Self {
        self.modal = None;
        self
    }

    /// Whether the modal route serves this model.
    pub fn is_modal(&self) -> bool {
        self.modal.is_some()
    }

    /// The augmented realisation ([module documentation](self)).
    fn realised(&self) -> &Confluent {
        self.realised.get_or_init(|| {
            let m = &self.mats;
            let n = m.a.len();
            // Parameters that move the state (a nonzero A_j or B_j) get a sensitivity block.
            let moving: Vec<usize> = (0..self.derivs.len())
                .filter(|&j| {
                    let d = &self.derivs[j];
                    d.a.iter().flatten().any(|x| *x != 0.0) || d.b.iter().any(|x| *x != 0.0)
                })
                .collect();
            let dim = n * (moving.len() + 1) + 1;
            let level = dim - 1;
            let mut gen = vec![0.0; dim * dim];
            let put_a = |gen: &mut [f64], row0: usize, col0: usize, a: &[Vec<f64>]| {
                for (i, r) in a.iter().enumerate() {
                    for (k, x) in r.iter().enumerate() {
                        gen[(row0 + i) * dim + col0 + k] = *x;
                    }
                }
            };
            put_a(&mut gen, 0, 0, &m.a);
            for (i, b) in m.b.iter().enumerate() {
                gen[i * dim + level] = *b;
            }
            for (block, &j) in moving.iter().enumerate() {
                let row0 = n * (block + 1);
                put_a(&mut gen, row0, 0, &self.derivs[j].a);
                put_a(&mut gen, row0, row0, &m.a);
                for (i, b) in self.derivs[j].b.iter().enumerate() {
                    gen[(row0 + i) * dim + level] = *b;
                }
            }
            let mut value = vec![0.0; dim];
            value[..n].copy_from_slice(&m.c);
            value[level] = m.d;
            let grads = (0..self.derivs.len())
                .map(|j| {
                    let d = &self.derivs[j];
                    let mut row = vec![0.0; dim];
                    row[..n].copy_from_slice(&d.c);
                    if let Some(block) = moving.iter().position(|&i| i == j) {
                        let row0 = n * (block + 1);
                        row[row0..row0 + n].copy_from_slice(&m.c);
                    }
                    row[level] = d.d;
                    row
                })
                .collect();
            Confluent::linear(gen, value, grads, &self.poles)
        })
    }

    fn prefix(&self) -> &[f64] {
        self.prefix
            .get_or_init(|| self.realised().prefix(&self.steps))
    }
}

impl<M: StateSpaceModel> Signal for GreyBox<M> {
    fn param_names(&self) -> Vec<String> {
        self.model.param_names()
    }

    fn params(&self) -> Vec<f64> {
        self.theta.clone()
    }

    fn with_params(&self, params: &[f64]) -> Result<Self, SignalError> {
        GreyBox::new(self.model.clone(), params.to_vec(), self.input.clone())
    }

    fn value(&self, t: f64) -> f64 {
        if let Some(r) = &self.modal {
            return r.value(t);
        }
        self.realised()
            .value_at(&self.steps, self.prefix(), t, None)
    }

    fn value_gradient(&self, t: f64, grad: &mut [f64]) {
        self.value_and_gradient(t, grad);
    }

    fn value_and_gradient(&self, t: f64, grad: &mut [f64]) -> f64 {
        if let Some(r) = &self.modal {
            return r.value_and_gradient(t, grad);
        }
        self.realised()
            .value_at(&self.steps, self.prefix(), t, Some(grad))
    }

    fn breakpoints(&self) -> Vec<f64> {
        self.steps.iter().map(|s| s.0).collect()
    }

    fn rate(&self) -> f64 {
        self.poles.iter().map(|p| p.norm()).fold(0.0, f64::max)
    }

    fn num_params(&self) -> usize {
        self.theta.len()
    }

    fn expected_values(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Vec<f64> {
        if let Some(r) = &self.modal {
            return r.expected_values(grid, jitter);
        }
        self.realised().expected_values(&self.steps, grid, jitter)
    }

    fn expected_values_gradient(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Jacobian {
        self.expected_values_and_gradient(grid, jitter).1
    }

    fn expected_values_and_gradient(
        &self,
        grid: &SampleGrid,
        jitter: &dyn JitterModel,
    ) -> (Vec<f64>, Jacobian) {
        if let Some(r) = &self.modal {
            return r.expected_values_and_gradient(grid, jitter);
        }
        self.realised()
            .expected_values_and_gradient(&self.steps, grid, jitter)
    }

    fn expected_squares(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Vec<f64> {
        if let Some(r) = &self.modal {
            return r.expected_squares(grid, jitter);
        }
        self.realised().expected_squares(&self.steps, grid, jitter)
    }
}

impl<M: StateSpaceModel> Spectrum for GreyBox<M> {
    fn density(&self, f: f64) -> Complex64 {
        match &self.input {
            Input::Piecewise(p) => self.frequency_response(f) * p.spectrum(f),
            Input::Tones(_) => Complex64::new(0.0, 0.0),
        }
    }

    fn density_gradient(&self, f: f64, grad: &mut [Complex64]) {
        match &self.input {
            Input::Piecewise(p) => {
                self.response_gradient(Complex64::new(0.0, TAU * f), grad);
                let u = p.spectrum(f);
                grad.iter_mut().for_each(|g| *g *= u);
            }
            Input::Tones(_) => grad.iter_mut().for_each(|g| *g = Complex64::new(0.0, 0.0)),
        }
    }
}

/// The matrices and their derivatives at `theta`, shapes and finiteness checked (a model's
/// own derivatives could break them), so that no later index is out of range.
fn validated<M: StateSpaceModel>(
    model: &M,
    theta: &[f64],
) -> Result<(StateMatrices<f64>, Vec<StateMatrices<f64>>), SignalError> {
    let mats = model.matrices(theta);
    StateSpace::new(mats.a.clone(), mats.b.clone(), mats.c.clone(), mats.d)?;
    let derivs = model.derivatives(theta);
    if derivs.len() != theta.len() {
        return Err(SignalError::WrongLength {
            name: "derivatives",
            expected: theta.len(),
            got: derivs.len(),
        });
    }
    for d in &derivs {
        StateSpace::new(d.a.clone(), d.b.clone(), d.c.clone(), d.d)?;
        if d.a.len() != mats.a.len() {
            return Err(SignalError::WrongLength {
                name: "derivative of a",
                expected: mats.a.len(),
                got: d.a.len(),
            });
        }
    }
    Ok((mats, derivs))
}

/// The eigenvalues of a small real matrix, near-real ones snapped onto the axis.
fn eigenvalues(a: &[Vec<f64>]) -> Option<Vec<Complex64>> {
    let n = a.len();
    let m = faer::Mat::<f64>::from_fn(n, n, |i, j| a[i][j]);
    let mut ev = m.eigenvalues().ok()?;
    let scale = ev.iter().map(|z| z.norm()).fold(1.0, f64::max);
    for z in ev.iter_mut() {
        if z.im.abs() <= 1e-12 * scale {
            z.im = 0.0;
        }
    }
    ev.iter().all(|z| z.is_finite()).then_some(ev)
}

fn complex(v: &[f64]) -> Vec<Complex64> {
    v.iter().map(|&x| Complex64::new(x, 0.0)).collect()
}

fn dot_c(a: &[Complex64], b: &[Complex64]) -> Complex64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

/// `sI − A` (or its transpose), by rows.
fn shifted(a: &[Vec<f64>], s: Complex64, transpose: bool) -> Vec<Vec<Complex64>> {
    let n = a.len();
    (0..n)
        .map(|i| {
            (0..n)
                .map(|j| {
                    let x = if transpose { a[j][i] } else { a[i][j] };
                    let diag = if i == j { s } else { Complex64::new(0.0, 0.0) };
                    diag - x
                })
                .collect()
        })
        .collect()
}

/// `X⁻¹ v` by Gaussian elimination with partial pivoting (a singular `X`, `s` at a pole,
/// gives non-finite entries, as `G` is infinite there).
fn solve(x: &[Vec<Complex64>], v: &[Complex64]) -> Vec<Complex64> {
    let n = v.len();
    let mut m: Vec<Vec<Complex64>> = x
        .iter()
        .zip(v)
        .map(|(r, b)| {
            let mut r = r.clone();
            r.push(*b);
            r
        })
        .collect();
    for col in 0..n {
        let pivot = (col..n)
            .max_by(|&i, &j| m[i][col].norm().total_cmp(&m[j][col].norm()))
            .unwrap_or(col);
        m.swap(col, pivot);
        let (top, below) = m.split_at_mut(col + 1);
        let pivot_row = &top[col];
        for row in below.iter_mut() {
            let f = row[col] / pivot_row[col];
            for (x, p) in row[col..].iter_mut().zip(&pivot_row[col..]) {
                *x -= f * p;
            }
        }
    }
    let mut out = vec![Complex64::new(0.0, 0.0); n];
    for i in (0..n).rev() {
        let tail: Complex64 = (i + 1..n).map(|j| m[i][j] * out[j]).sum();
        out[i] = (m[i][n] - tail) / m[i][i];
    }
    out
}

#[cfg(test)]
mod tests;
