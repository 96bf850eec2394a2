//! Levenberg–Marquardt as an argmin [`Solver`](argmin::core::Solver).
//!
//! argmin ships no Levenberg–Marquardt, so [`LevenbergMarquardt`] implements argmin's solver
//! trait itself (`init` / `next_iter` / `terminate`) and can run under argmin's [`Executor`]
//! with observers, checkpointing and timeouts. It also implements this crate's
//! [`Solver`](super::Solver) trait, which runs the executor for you.
//!
//! # Requirements on the optimization problem
//!
//! The problem is required to implement argmin's [`Operator`] (the residual vector, `Param =
//! Vec<f64>`, `Output = Vec<f64>`) and [`NormalEquationsOperator`] (`JᵀJ` and `Jᵀr`; the
//! Jacobian itself is never stored, so a fit's memory does not grow with `m × n`).
//! [`ArgminProblem`] provides both for every [`LeastSquares`] problem.
//!
//! The state is argmin's [`IterState`] ([`LmState`]): `param` is the current point, `cost` is
//! `½ Σ rᵢ²`, and `gradient` (`Jᵀr`) holds the value at `param`; its Jacobian slot stays empty.
//! `residuals` hold the values at `param` after an accepted step; they are released while a
//! trial point is evaluated (on a long record they are as large as the data), so a final
//! iteration that stops without an accepted step leaves the slot empty.
//!
//! # Algorithm
//!
//! Each iteration solves the damped normal equations `(JᵀJ + μD) h = −Jᵀr` by Cholesky (faer's
//! LLT; `JᵀJ` may be replaced by a better model of the Hessian, below) and tries `θ + h`. The step is accepted if the gain ratio
//! `ρ = (V(θ) − V(θ + h)) / (L(0) − L(h))` of actual to predicted (the quadratic model's) reduction is
//! positive; then `μ ← μ · max(1/3, 1 − (2ρ − 1)³)`, otherwise `μ ← μν`, `ν ← 2ν` and the step is
//! recomputed within the same iteration (Nielsen's update; Madsen, Nielsen & Tingleff, *Methods
//! for non-linear least squares problems*, 2004, §3.2). One argmin iteration is therefore one
//! *accepted* step (except the last, which may end on a stopping test without one). A trial point with non-finite residuals or Jacobian, and a damped matrix that
//! is not numerically positive definite, are treated as rejections.
//!
//! The quadratic model ([`LmModel`]). With [`LmModel::GaussNewton`] the matrix is `JᵀJ`, which
//! leaves out the second-order term `Σ rᵢ ∇²rᵢ` of the cost's Hessian: right for small
//! residuals, and for large ones a model that mispredicts every step, so that the damping stays
//! high and the search creeps (only linearly convergent). [`LmModel::Adaptive`], the default,
//! is Dennis, Gay & Welsch's adaptive model (NL2SOL; *An adaptive nonlinear least-squares
//! algorithm*, ACM TOMS 7, 1981) inside the damped iteration: a secant estimate `S` of the
//! second-order term (zero at the start) gets their sized symmetric update after every accepted
//! step `s`, with `y = g₊ − g` and `y# = y − ½(JᵀJ + J₊ᵀJ₊) s` (the gradient's change that
//! Gauss–Newton's matrices, by the trapezoidal rule along the step, do not explain; only the
//! normal equations are needed). The steps solve `(JᵀJ + S + μD) h = −Jᵀr` instead after three
//! consecutive accepted steps whose gain ratio Gauss–Newton's model missed by more than ¼ and
//! whose reduction the secant model predicted better (Madsen, Nielsen & Tingleff's hybrid
//! method, op. cit. §3.4, also waits for three). They go back to `JᵀJ` after a secant step that
//! Gauss–Newton's model would have predicted better, and a refused secant step (or an
//! indefinite `JᵀJ + S + μD`) is retried as Gauss–Newton's at the same damping; only a
//! Gauss–Newton step is small enough to stop the search. Where Gauss–Newton predicts well (zero
//! residual) the steps are the plain method's.
//!
//! `D` is the identity ([`Scaling::Identity`]) or the running maximum of `diag(JᵀJ)`
//! ([`Scaling::Marquardt`], Moré's variant, which makes the iteration invariant to rescaling the
//! parameters).
//!
//! Stopping tests (see [`LmOptions`]): relative step `‖h‖ ≤ xtol (‖θ‖ + xtol)`; relative cost
//! reduction (actual and predicted both `≤ ftol · V`); gradient, as the largest cosine between
//! `r` and a column of `J`, `≤ gtol` (MINPACK's scale-free test); iteration limit; wall-clock
//! budget ([`LmOptions::max_seconds`], checked between iterations and damping retries, so one
//! evaluation may overrun it). The reason is
//! available from [`LevenbergMarquardt::termination`] and, coarsely, from argmin's
//! [`TerminationReason`]: convergence tests map to `SolverConverged`, the iteration limit to
//! `MaxItersReached`, everything else to `SolverExit(text)`.
//!
//! # Observers
//!
//! Run the solver through argmin's [`Executor`] and attach any [`Observe`](argmin::core::observers::Observe) implementation; each
//! iteration's key-value log carries the damping `lambda` (μ), the last accepted step's gain
//! ratio `rho`, and `secant`, whether the next step uses the secant model.
//!
//! ```
//! use argmin::core::observers::{Observe, ObserverMode};
//! use argmin::core::{Error, Executor, State, KV};
//! use jitterid_optim::lm::{LevenbergMarquardt, LmState};
//! use jitterid_optim::{ArgminProblem, LeastSquares, SolverError};
//! use std::sync::{Arc, Mutex};
//!
//! struct Rosenbrock;
//! impl LeastSquares for Rosenbrock {
//!     fn num_params(&self) -> usize { 2 }
//!     fn num_residuals(&self) -> usize { 2 }
//!     fn residuals(&self, p: &[f64]) -> Result<Vec<f64>, SolverError> {
//!         Ok(vec![10.0 * (p[1] - p[0] * p[0]), 1.0 - p[0]])
//!     }
//! }
//!
//! /// Records the cost of every iteration.
//! struct CostTrace(Arc<Mutex<Vec<f64>>>);
//! impl Observe<LmState> for CostTrace {
//!     fn observe_iter(&mut self, state: &LmState, _kv: &KV) -> Result<(), Error> {
//!         self.0.lock().map_err(|_| Error::msg("poisoned"))?.push(state.get_cost());
//!         Ok(())
//!     }
//! }
//!
//! let trace = Arc::new(Mutex::new(Vec::new()));
//! let result = Executor::new(ArgminProblem::new(&Rosenbrock), LevenbergMarquardt::default())
//!     .configure(|state| state.param(vec![-1.2, 1.0]).max_iters(100))
//!     .add_observer(CostTrace(trace.clone()), ObserverMode::Always)
//!     .run()?;
//! let best = result.state.get_best_param().expect("a parameter vector");
//! assert!((best[0] - 1.0).abs() < 1e-8);
//! assert!(result.solver.termination().is_some_and(|t| t.is_convergence()));
//! let costs = trace.lock().unwrap();
//! assert!(costs.windows(2).all(|w| w[1] <= w[0])); // accepted steps never increase the cost
//! # Ok::<(), Error>(())
//! ```

use super::error::check_option;
use super::normal::{NormalEquations, NormalEquationsOperator};
use super::problem::{first_non_finite, half_sum_sq, validate_start, ArgminProblem, LeastSquares};
use super::progress::{ProgressHook, ProgressObserver};
use super::{from_argmin_reason, SolverError, SolverReport, Termination};
use argmin::core::observers::ObserverMode;
use argmin::core::{
    Error, Executor, IterState, Operator, Problem, State, TerminationReason, TerminationStatus, KV,
};
use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// argmin state used by [`LevenbergMarquardt`]: parameters, gradient and residuals as
/// `Vec<f64>`, no Hessian, `f64` cost (the Jacobian slot, typed `faer::Mat<f64>`, is unused).
pub type LmState = IterState<Vec<f64>, Vec<f64>, Mat<f64>, (), Vec<f64>, f64>;

/// Damped rejections within one iteration before giving up. With Nielsen's doubling of `ν`,
/// `μ` grows by `2^{k(k+1)/2}` after `k` rejections, so the step is negligible long before this.
const MAX_REJECTIONS: usize = 100;

/// [`LmModel::Adaptive`] switches models after a step whose gain ratio is off 1 by more than this
/// (and which the other model predicted better).
const SWITCH_RHO: f64 = 0.25;

/// [`LmModel::Adaptive`] leaves Gauss–Newton's model after this many consecutive accepted steps
/// that it predicted poorly and the secant model better (Madsen, Nielsen & Tingleff's hybrid
/// also waits for three).
const SWITCH_AFTER: usize = 3;

/// The damping matrix `D` in `(JᵀJ + μD) h = −Jᵀr`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Scaling {
    /// `D = I`; the initial `μ` is `initial_lambda · max diag(JᵀJ)`.
    Identity,
    /// `D = diag(JᵀJ)`, kept at its running maximum (zero entries replaced by one); the initial
    /// `μ` is `initial_lambda`. Invariant to rescaling parameters.
    #[default]
    Marquardt,
}

/// The quadratic model of the cost whose damped minimiser is each trial step.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum LmModel {
    /// Gauss–Newton's `JᵀJ` only.
    GaussNewton,
    /// `JᵀJ`, or `JᵀJ + S` with `S` a secant estimate of the second-order term
    /// `Σ rᵢ ∇²rᵢ`, whichever predicted the last step's reduction better (Dennis, Gay & Welsch's
    /// adaptive model; see the [module docs](self)).
    #[default]
    Adaptive,
}

/// Options of [`LevenbergMarquardt`]. Deserialization validates them
/// ([`validate`](LmOptions::validate)).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawLmOptions")]
pub struct LmOptions {
    /// Maximum number of iterations (accepted steps). Default 500.
    pub max_iters: u64,
    /// Relative step tolerance: stop when `‖h‖ ≤ xtol (‖θ‖ + xtol)`. Default `1e-10`.
    pub xtol: f64,
    /// Relative cost-reduction tolerance: stop when the actual and the predicted reduction of an
    /// accepted step are both `≤ ftol · V`. Default `1e-12`.
    pub ftol: f64,
    /// Gradient tolerance: stop when `max_j |J_jᵀ r| / (‖J_j‖ ‖r‖) ≤ gtol` (or `r = 0`).
    /// Default `1e-10`.
    pub gtol: f64,
    /// Initial damping, relative (see [`Scaling`]). Default `1e-3`.
    pub initial_lambda: f64,
    /// The damping matrix. Default [`Scaling::Marquardt`].
    pub scaling: Scaling,
    /// Wall-clock budget in seconds: the run stops with [`Termination::TimeLimit`] at the first
    /// iteration boundary (or damping retry) after it is spent. Default 600; `f64::INFINITY`
    /// for none.
    pub max_seconds: f64,
    /// The quadratic model. Default [`LmModel::Adaptive`].
    pub model: LmModel,
}

/// [`LmOptions::max_seconds`] by default: far beyond any fit this crate's criteria need on
/// records of up to 10⁷ samples, short enough that a runaway fit ends on its own.
const DEFAULT_MAX_SECONDS: f64 = 600.0;

fn default_max_seconds() -> f64 {
    DEFAULT_MAX_SECONDS
}

/// [`LmOptions`] as read, before validation.
#[derive(Deserialize)]
struct RawLmOptions {
    max_iters: u64,
    xtol: f64,
    ftol: f64,
    gtol: f64,
    initial_lambda: f64,
    scaling: Scaling,
    #[serde(default = "default_max_seconds")]
    max_seconds: f64,
    #[serde(default)]
    model: LmModel,
}

impl TryFrom<RawLmOptions> for LmOptions {
    type Error = SolverError;

    fn try_from(raw: RawLmOptions) -> Result<Self, SolverError> {
        let options = LmOptions {
            max_iters: raw.max_iters,
            xtol: raw.xtol,
            ftol: raw.ftol,
            gtol: raw.gtol,
            initial_lambda: raw.initial_lambda,
            scaling: raw.scaling,
            max_seconds: raw.max_seconds,
            model: raw.model,
        };
        options.validate()?;
        Ok(options)
    }
}

impl Default for LmOptions {
    fn default() -> Self {
        LmOptions {
            max_iters: 500,
            xtol: 1e-10,
            ftol: 1e-12,
            gtol: 1e-10,
            initial_lambda: 1e-3,
            scaling: Scaling::Marquardt,
            max_seconds: DEFAULT_MAX_SECONDS,
            model: LmModel::Adaptive,
        }
    }
}

impl LmOptions {
    /// Checks that the tolerances are finite and non-negative and the initial damping positive.
    ///
    /// # Errors
    ///
    /// [`SolverError::InvalidOption`] naming the first invalid option.
    pub fn validate(&self) -> Result<(), SolverError> {
        let tol = |x: f64| x.is_finite() && x >= 0.0;
        check_option("xtol", self.xtol, tol(self.xtol), "must be finite and >= 0")?;
        check_option("ftol", self.ftol, tol(self.ftol), "must be finite and >= 0")?;
        check_option("gtol", self.gtol, tol(self.gtol), "must be finite and >= 0")?;
        check_option(
            "max_seconds",
            self.max_seconds,
            self.max_seconds >= 0.0,
            "must be >= 0 (infinity for no limit)",
        )?;
        check_option(
            "initial_lambda",
            self.initial_lambda,
            self.initial_lambda.is_finite() && self.initial_lambda > 0.0,
            "must be finite and > 0",
        )
    }
}

/// Levenberg–Marquardt with Nielsen's damping update; see the [module docs](self).
///
/// As an argmin solver it carries the run's damping state; [`minimize`](super::Solver::minimize)
/// always starts from a fresh copy, so one value can be reused for many problems.
#[derive(Clone, Debug)]
pub struct LevenbergMarquardt {
    options: LmOptions,
    /// Damping `μ`.
    mu: f64,
    /// Factor by which `μ` grows on the next rejection.
    nu: f64,
    /// Gain ratio of the last accepted step (NaN before one).
    rho: f64,
    /// Diagonal of `D`.
    diag: Vec<f64>,
    /// `JᵀJ` at the current point.
    jtj: Mat<f64>,
    /// The secant estimate `S` of the second-order term (zero until a step is accepted).
    secant: Mat<f64>,
    /// Whether the next trial step uses `JᵀJ + S` ([`LmModel::Adaptive`] only).
    use_secant: bool,
    /// Consecutive accepted Gauss–Newton steps that the secant model predicted better.
    poor_gn: usize,
    /// Why the run stopped, once it has.
    stop: Option<Termination>,
    /// When the run started (set by `init`).
    started: Option<Instant>,
    /// Receives the cost after every iteration, when set.
    progress: Option<ProgressHook>,
}

impl Default for LevenbergMarquardt {
    fn default() -> Self {
        Self::new(LmOptions::default())
    }
}

impl LevenbergMarquardt {
    /// A solver with `options` (validated when a run starts).
    pub fn new(options: LmOptions) -> Self {
        LevenbergMarquardt {
            options,
            mu: f64::NAN,
            nu: 2.0,
            rho: f64::NAN,
            diag: Vec::new(),
            jtj: Mat::zeros(0, 0),
            secant: Mat::zeros(0, 0),
            use_secant: false,
            poor_gn: 0,
            stop: None,
            started: None,
            progress: None,
        }
    }

    /// Sets [`LmOptions::max_iters`].
    #[must_use]
    pub fn with_max_iters(mut self, max_iters: u64) -> Self {
        self.options.max_iters = max_iters;
        self
    }

    /// Sets [`LmOptions::xtol`].
    #[must_use]
    pub fn with_xtol(mut self, xtol: f64) -> Self {
        self.options.xtol = xtol;
        self
    }

    /// Sets [`LmOptions::ftol`].
    #[must_use]
    pub fn with_ftol(mut self, ftol: f64) -> Self {
        self.options.ftol = ftol;
        self
    }

    /// Sets [`LmOptions::gtol`].
    #[must_use]
    pub fn with_gtol(mut self, gtol: f64) -> Self {
        self.options.gtol = gtol;
        self
    }

    /// Sets [`LmOptions::initial_lambda`].
    #[must_use]
    pub fn with_initial_lambda(mut self, initial_lambda: f64) -> Self {
        self.options.initial_lambda = initial_lambda;
        self
    }

    /// Sets [`LmOptions::scaling`].
    #[must_use]
    pub fn with_scaling(mut self, scaling: Scaling) -> Self {
        self.options.scaling = scaling;
        self
    }

    /// Sets [`LmOptions::model`].
    #[must_use]
    pub fn with_model(mut self, model: LmModel) -> Self {
        self.options.model = model;
        self
    }

    /// Sets [`LmOptions::max_seconds`].
    #[must_use]
    pub fn with_max_seconds(mut self, max_seconds: f64) -> Self {
        self.options.max_seconds = max_seconds;
        self
    }

    /// Reports the iteration and cost to `hook` after the start and after every iteration of
    /// [`minimize`](super::Solver::minimize) (under argmin's executor, attach an observer).
    #[must_use]
    pub fn with_progress(mut self, hook: ProgressHook) -> Self {
        self.progress = Some(hook);
        self
    }

    /// Whether the wall-clock budget is spent.
    fn out_of_time(&self) -> bool {
        self.started
            .is_some_and(|t| t.elapsed().as_secs_f64() >= self.options.max_seconds)
            || jitterid_numeric::budget::spent()
    }

    /// The options.
    pub fn options(&self) -> &LmOptions {
        &self.options
    }

    /// Why the last run stopped (`None` before a run ends, or if argmin stopped it for its own
    /// reasons such as a timeout).
    pub fn termination(&self) -> Option<&Termination> {
        self.stop.as_ref()
    }

    /// Current damping `μ` (NaN before a run).
    pub fn lambda(&self) -> f64 {
        self.mu
    }

    /// Rejection: raise the damping.
    fn raise(&mut self) {
        self.mu *= self.nu;
        self.nu *= 2.0;
    }

    /// Rejection of a trial step: a secant model's step is retried as Gauss–Newton's at the
    /// same damping (the secant estimate is what failed), Gauss–Newton's raises the damping.
    fn reject(&mut self, used_secant: bool) {
        if used_secant {
            self.use_secant = false;
        } else {
            self.raise();
        }
    }

    /// Solves `(JᵀJ + μD) h = −g`, or `(JᵀJ + S + μD) h = −g` with `secant`; `None` if the
    /// matrix is not numerically positive definite or the solution is not finite.
    fn damped_step(&self, g: &[f64], secant: bool) -> Option<Vec<f64>> {
        let n = g.len();
        let m = Mat::from_fn(n, n, |r, c| {
            self.jtj[(r, c)]
                + if secant { self.secant[(r, c)] } else { 0.0 }
                + if r == c { self.mu * self.diag[r] } else { 0.0 }
        });
        let llt = m.llt(Side::Lower).ok()?;
        let h = llt.solve(Mat::from_fn(n, 1, |i, _| -g[i]));
        let h: Vec<f64> = (0..n).map(|i| h[(i, 0)]).collect();
        first_non_finite(&h).is_none().then_some(h)
    }

    /// After an accepted step `s` (with the model `used_secant`) that reduced the cost by
    /// `actual`, from gradient `g` to `g_new` and from `self.jtj` to `gram`: chooses the next
    /// step's model and updates `S`.
    ///
    /// The model switches when the one used predicted the reduction poorly (its gain ratio off
    /// 1 by more than [`SWITCH_RHO`]) and the other one predicted it better. `S` then gets Dennis,
    /// Gay & Welsch's sized symmetric secant update with `y = g_new − g` and
    /// `y# = y − ½(JᵀJ + J_newᵀJ_new) s`, the part of the gradient's change that Gauss–Newton's
    /// matrices (trapezoidal rule along the step) do not explain.
    fn adapt(
        &mut self,
        s: &[f64],
        g: &[f64],
        g_new: &[f64],
        gram: &Mat<f64>,
        actual: f64,
        used_secant: bool,
    ) {
        let n = s.len();
        let quad = |a: &Mat<f64>| -> f64 {
            (0..n)
                .map(|i| s[i] * (0..n).map(|j| a[(i, j)] * s[j]).sum::<f64>())
                .sum()
        };
        let linear = -dot(g, s);
        let predicted_gn = linear - 0.5 * quad(&self.jtj);
        let predicted_secant = predicted_gn - 0.5 * quad(&self.secant);
        let (used, other) = if used_secant {
            (predicted_secant, predicted_gn)
        } else {
            (predicted_gn, predicted_secant)
        };
        let other_better = (actual / used - 1.0).abs() > SWITCH_RHO
            && other > 0.0
            && (other - actual).abs() < (used - actual).abs();
        if used_secant {
            if other_better {
                self.use_secant = false;
            }
        } else {
            self.poor_gn = if other_better { self.poor_gn + 1 } else { 0 };
            if self.poor_gn >= SWITCH_AFTER {
                self.use_secant = true;
                self.poor_gn = 0;
            }
        }

        let y: Vec<f64> = g_new.iter().zip(g).map(|(a, b)| a - b).collect();
        let ys = dot(&y, s);
        if !(ys > 0.0) {
            return;
        }
        let y_sharp: Vec<f64> = (0..n)
            .map(|i| {
                y[i] - 0.5
                    * (0..n)
                        .map(|j| (self.jtj[(i, j)] + gram[(i, j)]) * s[j])
                        .sum::<f64>()
            })
            .collect();
        // Sizing (Dennis, Gay & Welsch): shrink S where its curvature along s exceeds what the
        // step saw.
        let s_s = quad(&self.secant);
        let tau = if s_s.abs() > 0.0 {
            (dot(&y_sharp, s).abs() / s_s.abs()).min(1.0)
        } else {
            1.0
        };
        let w: Vec<f64> = (0..n)
            .map(|i| y_sharp[i] - tau * (0..n).map(|j| self.secant[(i, j)] * s[j]).sum::<f64>())
            .collect();
        let ws = dot(&w, s);
        let updated = Mat::from_fn(n, n, |i, j| {
            tau * self.secant[(i, j)] + (w[i] * y[j] + y[i] * w[j]) / ys
                - ws * y[i] * y[j] / (ys * ys)
        });
        if (0..n).all(|i| (0..n).all(|j| updated[(i, j)].is_finite())) {
            self.secant = updated;
        }
    }

    /// Stores `JᵀJ` and updates `D` at a new point.
    fn set_gram(&mut self, gram: Mat<f64>) {
        self.jtj = gram;
        let n = self.jtj.nrows();
        let diag = (0..n).map(|i| self.jtj[(i, i)]);
        self.diag = match self.options.scaling {
            Scaling::Identity => vec![1.0; n],
            Scaling::Marquardt => {
                let old = std::mem::take(&mut self.diag);
                diag.enumerate()
                    .map(|(i, a)| {
                        let a = if a > 0.0 { a } else { 1.0 };
                        old.get(i).map_or(a, |&o| a.max(o))
                    })
                    .collect()
            }
        };
    }

    /// MINPACK's scale-free gradient measure: the largest cosine between `r` and a column of `J`.
    fn gradient_cosine(&self, g: &[f64], r: &[f64]) -> f64 {
        let rnorm = norm(r);
        if rnorm == 0.0 {
            return 0.0;
        }
        g.iter()
            .enumerate()
            .filter_map(|(j, gj)| {
                let cnorm = self.jtj[(j, j)].sqrt();
                (cnorm > 0.0).then(|| gj.abs() / (cnorm * rnorm))
            })
            .fold(0.0, f64::max)
    }

    fn kv(&self) -> Option<KV> {
        let mut kv = KV::new();
        kv.insert("lambda", self.mu.into());
        kv.insert("rho", self.rho.into());
        kv.insert("secant", self.use_secant.into());
        Some(kv)
    }
}

/// The problem's normal equations at `x` with residuals `r`, counted by argmin.
fn normal_equations<O: NormalEquationsOperator<Param = Vec<f64>>>(
    problem: &mut Problem<O>,
    x: &O::Param,
    r: &[f64],
) -> Result<NormalEquations, Error> {
    let ne = problem.problem("normal_equations_count", |p| p.normal_equations(x, r))?;
    ne.check_shape(x.len())?;
    Ok(ne)
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

impl<O> argmin::core::Solver<O, LmState> for LevenbergMarquardt
where
    O: Operator<Param = Vec<f64>, Output = Vec<f64>> + NormalEquationsOperator<Param = Vec<f64>>,
{
    fn name(&self) -> &str {
        "Levenberg-Marquardt"
    }

    fn init(
        &mut self,
        problem: &mut Problem<O>,
        state: LmState,
    ) -> Result<(LmState, Option<KV>), Error> {
        self.options.validate()?;
        self.stop = None;
        self.started = Some(Instant::now());
        self.diag = Vec::new();
        let x = state.get_param().ok_or(SolverError::MissingStart)?.clone();
        self.secant = Mat::zeros(x.len(), x.len());
        self.use_secant = false;
        self.poor_gn = 0;
        if x.is_empty() {
            return Err(SolverError::NoParameters.into());
        }
        if let Some((index, value)) = first_non_finite(&x) {
            return Err(SolverError::NonFiniteStart { index, value }.into());
        }
        let r = problem.apply(&x)?;
        if r.len() < x.len() {
            return Err(SolverError::TooFewResiduals {
                residuals: r.len(),
                params: x.len(),
            }
            .into());
        }
        if let Some((index, value)) = first_non_finite(&r) {
            return Err(SolverError::NonFiniteResidual { index, value }.into());
        }
        let cost = half_sum_sq(&r);
        if !cost.is_finite() {
            return Err(SolverError::Evaluation(
                "the sum of squared residuals overflows at the start".to_string(),
            )
            .into());
        }
        let ne = normal_equations(problem, &x, &r)?;
        if let Some((what, index, value)) = ne.first_non_finite() {
            return Err(SolverError::NonFiniteNormalEquations { what, index, value }.into());
        }
        let NormalEquations { gram, gradient: g } = ne;
        self.set_gram(gram);
        self.nu = 2.0;
        self.mu = match self.options.scaling {
            Scaling::Identity => {
                let max_diag = (0..x.len()).map(|i| self.jtj[(i, i)]).fold(0.0, f64::max);
                self.options.initial_lambda * if max_diag > 0.0 { max_diag } else { 1.0 }
            }
            Scaling::Marquardt => self.options.initial_lambda,
        };
        if self.gradient_cosine(&g, &r) <= self.options.gtol {
            self.stop = Some(Termination::SmallGradient);
        }
        let kv = self.kv();
        Ok((state.param(x).cost(cost).residuals(r).gradient(g), kv))
    }

    fn next_iter(
        &mut self,
        problem: &mut Problem<O>,
        state: LmState,
    ) -> Result<(LmState, Option<KV>), Error> {
        let x = state.get_param().ok_or(SolverError::MissingStart)?.clone();
        let g = state
            .get_gradient()
            .ok_or(SolverError::Argmin(
                "Levenberg-Marquardt: state has no gradient; was `init` skipped?".to_string(),
            ))?
            .clone();
        // Only the length of the current residuals is read again: on a long record they are as
        // large as the data, and the trial point's residuals and normal equations are formed
        // next, so they are released here.
        let mut state = state;
        let m = state.take_residuals().map_or(0, |r| r.len());
        if g.len() != x.len()
            || self.jtj.nrows() != x.len()
            || self.diag.len() != x.len()
            || self.secant.nrows() != x.len()
        {
            return Err(SolverError::Argmin(
                "Levenberg-Marquardt: inconsistent state; was `init` skipped?".to_string(),
            )
            .into());
        }
        let cost = state.get_cost();
        let xtol = self.options.xtol;
        let x_norm = norm(&x);
        // Whether the latest rejection was for a non-finite trial point, so that a step that
        // shrank to nothing is reported as a wall of non-finite values, not as convergence.
        let mut last_rejection_non_finite = false;

        for _ in 0..MAX_REJECTIONS {
            if self.out_of_time() {
                self.stop = Some(crate::budget_termination().unwrap_or(Termination::TimeLimit));
                return Ok((state, self.kv()));
            }
            if !self.mu.is_finite() {
                self.stop = Some(if last_rejection_non_finite {
                    Termination::NonFinite
                } else {
                    Termination::Other("damping overflowed".to_string())
                });
                return Ok((state, self.kv()));
            }
            // The secant model's matrix may be indefinite where Gauss–Newton's is not: then this
            // trial is Gauss–Newton's.
            let secant_step = if self.use_secant {
                self.damped_step(&g, true)
            } else {
                None
            };
            let used_secant = secant_step.is_some();
            let Some(h) = secant_step.or_else(|| self.damped_step(&g, false)) else {
                self.raise();
                continue;
            };
            if norm(&h) <= xtol * (x_norm + xtol) {
                if used_secant {
                    // Only Gauss–Newton's step decides that the search has converged.
                    self.use_secant = false;
                    continue;
                }
                self.stop = Some(if last_rejection_non_finite {
                    Termination::NonFinite
                } else {
                    Termination::SmallStep
                });
                return Ok((state, self.kv()));
            }
            let x_new: Vec<f64> = x.iter().zip(&h).map(|(a, b)| a + b).collect();
            let r_new = problem.apply(&x_new)?;
            if r_new.len() != m {
                return Err(SolverError::ResidualLength {
                    expected: m,
                    got: r_new.len(),
                }
                .into());
            }
            let cost_new = half_sum_sq(&r_new);
            if !cost_new.is_finite() {
                last_rejection_non_finite = true;
                self.reject(used_secant);
                continue;
            }
            // L(0) − L(h) = ½ hᵀ(μDh − g), the reduction predicted by the linear model.
            let predicted = 0.5
                * h.iter()
                    .zip(&g)
                    .zip(&self.diag)
                    .map(|((hi, gi), di)| hi * (self.mu * di * hi - gi))
                    .sum::<f64>();
            let actual = cost - cost_new;
            let rho = actual / predicted;
            if !(predicted > 0.0 && rho > 0.0) {
                last_rejection_non_finite = false;
                self.reject(used_secant);
                continue;
            }
            let ne = normal_equations(problem, &x_new, &r_new)?;
            if !ne.is_finite() {
                last_rejection_non_finite = true;
                self.reject(used_secant);
                continue;
            }
            let NormalEquations {
                gram,
                gradient: g_new,
            } = ne;
            if self.options.model == LmModel::Adaptive {
                self.adapt(&h, &g, &g_new, &gram, actual, used_secant);
            }
            self.set_gram(gram);
            self.rho = rho;
            self.mu *= (1.0 - (2.0 * rho - 1.0).powi(3)).max(1.0 / 3.0);
            self.nu = 2.0;
            let ftol = self.options.ftol;
            if actual <= ftol * cost && predicted <= ftol * cost {
                self.stop = Some(Termination::SmallCostChange);
            } else if self.gradient_cosine(&g_new, &r_new) <= self.options.gtol {
                self.stop = Some(Termination::SmallGradient);
            }
            let kv = self.kv();
            let mut state = state
                .param(x_new)
                .cost(cost_new)
                .residuals(r_new)
                .gradient(g_new);
            // The previous residuals are never read again: on a long record they are as large
            // as the data.
            drop(state.take_prev_residuals());
            return Ok((state, kv));
        }
        self.stop = Some(Termination::Other(format!(
            "no acceptable step after {MAX_REJECTIONS} damping increases"
        )));
        Ok((state, self.kv()))
    }

    fn terminate(&mut self, state: &LmState) -> TerminationStatus {
        if self.stop.is_none() && state.get_iter() >= self.options.max_iters {
            self.stop = Some(Termination::MaxIterations);
        }
        if self.stop.is_none() && self.out_of_time() {
            self.stop = Some(crate::budget_termination().unwrap_or(Termination::TimeLimit));
        }
        match &self.stop {
            None => TerminationStatus::NotTerminated,
            Some(t) if t.is_convergence() => {
                TerminationStatus::Terminated(TerminationReason::SolverConverged)
            }
            Some(Termination::MaxIterations) => {
                TerminationStatus::Terminated(TerminationReason::MaxItersReached)
            }
            Some(t) => TerminationStatus::Terminated(TerminationReason::SolverExit(t.to_string())),
        }
    }
}

/// # Requirements
///
/// The problem is a [`LeastSquares`] problem (residuals and their Jacobian).
impl<P: LeastSquares + ?Sized> super::Solver<P> for LevenbergMarquardt {
    fn minimize(&self, problem: &P, start: &[f64]) -> Result<SolverReport, SolverError> {
        self.options.validate()?;
        validate_start(problem, start)?;
        // The run's own solver state; the hook goes to the observer for the reports.
        let mut run = LevenbergMarquardt::new(self.options.clone());
        run.progress = self.progress.clone();
        let mut executor = Executor::new(ArgminProblem::new(problem), run)
            .configure(|state| {
                state
                    .param(start.to_vec())
                    .max_iters(self.options.max_iters)
            })
            .ctrlc(false);
        if let Some(hook) = &self.progress {
            executor = executor.add_observer(
                ProgressObserver {
                    hook: hook.clone(),
                    started: Instant::now(),
                },
                ObserverMode::Always,
            );
        }
        let result = executor.run().map_err(SolverError::from_argmin)?;
        let mut state = result.state;
        let termination = result.solver.stop.clone().unwrap_or_else(|| {
            from_argmin_reason(&state.termination_status, Termination::SmallStep)
        });
        let cost = state.get_cost();
        let params = state.take_param().ok_or(SolverError::MissingStart)?;
        Ok(SolverReport {
            converged: termination.is_convergence() && cost.is_finite(),
            params,
            cost,
            iterations: state.get_iter(),
            termination,
        })
    }
}
