//! Minimisers of general (cost + gradient) objectives.
//!
//! The likelihood criteria are not sums of squares (`ln λ_k`, `−ln p(y_k)`), so the
//! Levenberg–Marquardt layer does not apply. Three minimisers, all reporting through the
//! crate's [`SolverReport`]:
//!
//! * [`Bfgs`]: dense BFGS with an Armijo backtracking line search, written here because the
//!   criteria are `+∞` outside the model's domain (a negative noise level after a long step, a
//!   reach wider than the record), which argmin's Wolfe line searches do not accept; an update
//!   is skipped when the curvature `sᵀy` is not positive, so the inverse Hessian stays positive
//!   definite. For a handful of parameters.
//! * [`Brent`]: one parameter. A golden-section bracket is grown from the start (infinite
//!   values count as high), then argmin's [`BrentOpt`](argmin::solver::brent::BrentOpt) runs
//!   on it. No gradient needed: the integer-`n` profile of a Table 1 record costs about 20
//!   likelihood evaluations per `n`.
//! * [`ArgminNelderMead`]: argmin's Nelder–Mead simplex on the cost; derivative-free fallback.
//!
//! [`ArgminObjective`] exposes any [`Objective`] through argmin's `CostFunction` and
//! `Gradient` traits, for argmin's other solvers.

use super::objective::Objective;
use crate::solver::{SolverError, SolverReport, Termination};
use argmin::core::{CostFunction, Error, Executor, Gradient, IterState, State};
use argmin::solver::brent::BrentOpt;
use argmin::solver::neldermead::NelderMead;
use serde::{Deserialize, Serialize};

/// Exposes an [`Objective`] as argmin's `CostFunction` and `Gradient` on `Vec<f64>`.
#[derive(Debug)]
pub struct ArgminObjective<'a, O: ?Sized>(pub &'a O);

impl<O: Objective + ?Sized> CostFunction for ArgminObjective<'_, O> {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, p: &Vec<f64>) -> Result<f64, Error> {
        Ok(self.0.cost(p))
    }
}

impl<O: Objective + ?Sized> Gradient for ArgminObjective<'_, O> {
    type Param = Vec<f64>;
    type Gradient = Vec<f64>;
    fn gradient(&self, p: &Vec<f64>) -> Result<Vec<f64>, Error> {
        Ok(self.0.cost_gradient(p).1)
    }
}

/// Which minimiser [`ml_estimate`](super::ml_estimate) uses.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub enum MlSolver {
    /// [`Brent`] for one parameter, [`Bfgs`] otherwise (the default).
    #[default]
    Auto,
    /// Dense BFGS.
    Bfgs(Bfgs),
    /// Brent's method (one parameter only).
    Brent(Brent),
    /// argmin's Nelder–Mead.
    NelderMead(ArgminNelderMead),
}

impl MlSolver {
    /// Minimises `objective` from `start` (unconstrained coordinates).
    ///
    /// # Errors
    ///
    /// A start of the wrong length or where the cost is not finite; invalid options; Brent
    /// asked for more than one parameter.
    pub fn minimize<O: Objective + ?Sized>(
        &self,
        objective: &O,
        start: &[f64],
    ) -> Result<SolverReport, SolverError> {
        self.minimize_with_metric(objective, start, None)
    }

    /// As [`minimize`](Self::minimize), with an initial inverse Hessian for BFGS.
    ///
    /// # Errors
    ///
    /// As [`minimize`](Self::minimize).
    pub fn minimize_with_metric<O: Objective + ?Sized>(
        &self,
        objective: &O,
        start: &[f64],
        metric: Option<&[Vec<f64>]>,
    ) -> Result<SolverReport, SolverError> {
        match self {
            MlSolver::Auto if start.len() == 1 => Brent::default().minimize(objective, start),
            MlSolver::Auto => Bfgs::default().minimize_with_metric(objective, start, metric),
            MlSolver::Bfgs(b) => b.minimize_with_metric(objective, start, metric),
            MlSolver::Brent(b) => b.minimize(objective, start),
            MlSolver::NelderMead(n) => n.minimize(objective, start),
        }
    }
}

fn check_start<O: Objective + ?Sized>(objective: &O, start: &[f64]) -> Result<f64, SolverError> {
    if start.len() != objective.num_params() {
        return Err(SolverError::WrongStartLength {
            expected: objective.num_params(),
            got: start.len(),
        });
    }
    if start.is_empty() {
        return Err(SolverError::NoParameters);
    }
    if let Some((index, &value)) = start.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(SolverError::NonFiniteStart { index, value });
    }
    let f = objective.cost(start);
    if !f.is_finite() {
        return Err(SolverError::NonFiniteResidual { index: 0, value: f });
    }
    Ok(f)
}

/// Dense BFGS with Armijo backtracking (see the module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Bfgs {
    /// Iteration limit. Default 200.
    pub max_iters: u64,
    /// Stop when the predicted decrease `½ gᵀ H g` is below this (absolute, in cost units; a
    /// log-likelihood change of `1e-9` is far below any statistical resolution). Default
    /// `1e-9`.
    pub decrement_tol: f64,
    /// Stop when the step is below `step_tol · (1 + ‖θ‖∞)`. Default `1e-10`.
    pub step_tol: f64,
    /// Stop when the cost changed by less than `cost_tol · (1 + |f|)` twice in a row.
    /// Default `1e-14`.
    pub cost_tol: f64,
    /// Largest component of the first trial step (unconstrained coordinates). Default 0.2.
    pub initial_step: f64,
    /// Wall-clock budget in seconds, checked between iterations: the run stops with
    /// [`Termination::TimeLimit`] once it is spent. Default 600; `f64::INFINITY` for none.
    #[serde(default = "default_max_seconds")]
    pub max_seconds: f64,
}

fn default_max_seconds() -> f64 {
    600.0
}

impl Default for Bfgs {
    fn default() -> Self {
        Bfgs {
            max_iters: 200,
            decrement_tol: 1e-9,
            step_tol: 1e-10,
            cost_tol: 1e-14,
            initial_step: 0.2,
            max_seconds: default_max_seconds(),
        }
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn mat_vec(h: &[Vec<f64>], v: &[f64]) -> Vec<f64> {
    h.iter().map(|row| dot(row, v)).collect()
}

fn inf_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

impl Bfgs {
    fn validate(&self) -> Result<(), SolverError> {
        for (option, value) in [
            ("decrement_tol", self.decrement_tol),
            ("step_tol", self.step_tol),
            ("cost_tol", self.cost_tol),
            ("initial_step", self.initial_step),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(SolverError::InvalidOption {
                    option,
                    value,
                    reason: "must be finite and > 0",
                });
            }
        }
        if !(self.max_seconds >= 0.0) {
            return Err(SolverError::InvalidOption {
                option: "max_seconds",
                value: self.max_seconds,
                reason: "must be >= 0 (infinity for no limit)",
            });
        }
        Ok(())
    }

    /// Minimises `objective` from `start`.
    ///
    /// # Errors
    ///
    /// Invalid options; a start of the wrong length, not finite, or where the cost or the
    /// gradient is not finite.
    pub fn minimize<O: Objective + ?Sized>(
        &self,
        objective: &O,
        start: &[f64],
    ) -> Result<SolverReport, SolverError> {
        self.minimize_with_metric(objective, start, None)
    }

    /// Minimises `objective` from `start` with the initial inverse Hessian `metric` (for
    /// example the inverse of an expected information matrix; ignored unless it is a
    /// symmetric matrix of the right size with a positive diagonal).
    ///
    /// # Errors
    ///
    /// As [`minimize`](Self::minimize).
    pub fn minimize_with_metric<O: Objective + ?Sized>(
        &self,
        objective: &O,
        start: &[f64],
        metric: Option<&[Vec<f64>]>,
    ) -> Result<SolverReport, SolverError> {
        self.validate()?;
        check_start(objective, start)?;
        let n = start.len();
        let mut x = start.to_vec();
        let (mut f, mut g) = objective.cost_gradient(&x);
        if let Some((index, &value)) = g.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(SolverError::NonFiniteJacobian {
                row: 0,
                col: index,
                value,
            });
        }
        let identity = |scale: f64| -> Vec<Vec<f64>> {
            (0..n)
                .map(|i| (0..n).map(|j| if i == j { scale } else { 0.0 }).collect())
                .collect()
        };
        let first_scale = |g: &[f64]| self.initial_step / inf_norm(g).max(1e-300);
        let valid_metric = metric.filter(|m| {
            m.len() == n
                && m.iter()
                    .all(|r| r.len() == n && r.iter().all(|v| v.is_finite()))
                && (0..n).all(|i| m[i][i] > 0.0)
        });
        let (mut h, mut updated) = match valid_metric {
            Some(m) => (m.to_vec(), true),
            None => (identity(first_scale(&g)), false),
        };
        let mut small_changes = 0;
        let mut iterations = 0;
        let started = std::time::Instant::now();
        let termination = loop {
            if iterations >= self.max_iters {
                break Termination::MaxIterations;
            }
            if started.elapsed().as_secs_f64() >= self.max_seconds {
                break Termination::TimeLimit;
            }
            let hg = mat_vec(&h, &g);
            if 0.5 * dot(&g, &hg) <= self.decrement_tol && updated {
                break Termination::SmallGradient;
            }
            if inf_norm(&g) == 0.0 {
                break Termination::SmallGradient;
            }
            let mut d: Vec<f64> = hg.iter().map(|v| -v).collect();
            let mut slope = dot(&g, &d);
            if !(slope < 0.0) {
                h = identity(first_scale(&g));
                updated = false;
                d = mat_vec(&h, &g).iter().map(|v| -v).collect();
                slope = dot(&g, &d);
            }
            // Armijo backtracking with safeguarded quadratic interpolation.
            let mut alpha = 1.0;
            let mut accepted = None;
            for _ in 0..60 {
                let xt: Vec<f64> = x.iter().zip(&d).map(|(a, b)| a + alpha * b).collect();
                let ft = objective.cost(&xt);
                if ft.is_finite() && ft <= f + 1e-4 * alpha * slope {
                    accepted = Some((xt, ft));
                    break;
                }
                let next = if ft.is_finite() {
                    let q = -slope * alpha * alpha / (2.0 * (ft - f - slope * alpha));
                    q.clamp(0.1 * alpha, 0.5 * alpha)
                } else {
                    0.25 * alpha
                };
                alpha = next;
                if alpha * inf_norm(&d) < 1e-16 * (1.0 + inf_norm(&x)) {
                    break;
                }
            }
            iterations += 1;
            let Some((xt, _)) = accepted else {
                // No decrease along a descent direction: at the resolution of the cost.
                let hg = mat_vec(&h, &g);
                break if 0.5 * dot(&g, &hg) <= 1e3 * self.decrement_tol {
                    Termination::SmallGradient
                } else if updated {
                    // Retry once from a steepest-descent metric before giving up.
                    h = identity(first_scale(&g));
                    updated = false;
                    continue;
                } else {
                    Termination::LineSearchFailed
                };
            };
            let (ft, gt) = objective.cost_gradient(&xt);
            if !ft.is_finite() || gt.iter().any(|v| !v.is_finite()) {
                break Termination::NonFinite;
            }
            let s: Vec<f64> = xt.iter().zip(&x).map(|(a, b)| a - b).collect();
            let yv: Vec<f64> = gt.iter().zip(&g).map(|(a, b)| a - b).collect();
            let sy = dot(&s, &yv);
            let step_small = inf_norm(&s) <= self.step_tol * (1.0 + inf_norm(&x));
            if (f - ft).abs() <= self.cost_tol * (1.0 + ft.abs()) {
                small_changes += 1;
            } else {
                small_changes = 0;
            }
            x = xt;
            f = ft;
            g = gt;
            if sy > 1e-12 * dot(&s, &s).sqrt() * dot(&yv, &yv).sqrt() {
                if !updated {
                    let yy = dot(&yv, &yv);
                    h = identity(sy / yy);
                    updated = true;
                }
                // H ← (I − ρ s yᵀ) H (I − ρ y sᵀ) + ρ s sᵀ.
                let rho = 1.0 / sy;
                let hy = mat_vec(&h, &yv);
                let yhy = dot(&yv, &hy);
                for i in 0..n {
                    for j in 0..n {
                        h[i][j] += -rho * (s[i] * hy[j] + hy[i] * s[j])
                            + (rho * rho * yhy + rho) * s[i] * s[j];
                    }
                }
            }
            if step_small {
                break Termination::SmallStep;
            }
            if small_changes >= 2 {
                break Termination::SmallCostChange;
            }
        };
        Ok(SolverReport {
            converged: termination.is_convergence() && f.is_finite(),
            params: x,
            cost: f,
            iterations,
            termination,
        })
    }
}

/// Brent's method for one parameter (see the module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Brent {
    /// First bracketing step (unconstrained coordinate). Default 0.1.
    pub bracket_step: f64,
    /// Absolute tolerance on the parameter. Default `1e-8`.
    pub tolerance: f64,
    /// Iteration limit of Brent's method (and of the bracket's growth). Default 100.
    pub max_iters: u64,
}

impl Default for Brent {
    fn default() -> Self {
        Brent {
            bracket_step: 0.1,
            tolerance: 1e-8,
            max_iters: 100,
        }
    }
}

struct Scalar<'a, O: ?Sized>(&'a O);

impl<O: Objective + ?Sized> CostFunction for Scalar<'_, O> {
    type Param = f64;
    type Output = f64;
    fn cost(&self, p: &f64) -> Result<f64, Error> {
        let v = self.0.cost(&[*p]);
        Ok(if v.is_finite() { v } else { f64::INFINITY })
    }
}

impl Brent {
    /// Minimises a one-parameter `objective` from `start`.
    ///
    /// # Errors
    ///
    /// More than one parameter; invalid options; a start where the cost is not finite.
    pub fn minimize<O: Objective + ?Sized>(
        &self,
        objective: &O,
        start: &[f64],
    ) -> Result<SolverReport, SolverError> {
        if objective.num_params() != 1 {
            return Err(SolverError::InvalidOption {
                option: "brent parameters",
                value: objective.num_params() as f64,
                reason: "Brent's method minimises over exactly one parameter",
            });
        }
        for (option, value) in [
            ("bracket_step", self.bracket_step),
            ("tolerance", self.tolerance),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(SolverError::InvalidOption {
                    option,
                    value,
                    reason: "must be finite and > 0",
                });
            }
        }
        let f0 = check_start(objective, start)?;
        let f = |x: f64| {
            let v = objective.cost(&[x]);
            if v.is_finite() {
                v
            } else {
                f64::INFINITY
            }
        };
        // Bracket (a, b, c) with f(b) ≤ f(a), f(b) ≤ f(c), growing by the golden ratio.
        const GOLD: f64 = 1.618_033_988_749_895;
        let (mut a, mut fa) = (start[0], f0);
        let (mut b, mut fb) = (a + self.bracket_step, f(a + self.bracket_step));
        let mut evals = 2u64;
        if fb > fa {
            std::mem::swap(&mut a, &mut b);
            std::mem::swap(&mut fa, &mut fb);
        }
        let mut c = b + GOLD * (b - a);
        let mut fc = f(c);
        evals += 1;
        let mut grown = 0;
        while fc < fb {
            if grown >= self.max_iters {
                return Ok(SolverReport {
                    params: vec![c],
                    cost: fc,
                    iterations: evals,
                    termination: Termination::MaxIterations,
                    converged: false,
                });
            }
            a = b;
            b = c;
            fb = fc;
            c = b + GOLD * (b - a);
            fc = f(c);
            evals += 1;
            grown += 1;
        }
        let (lo, hi) = if a < c { (a, c) } else { (c, a) };
        let solver = BrentOpt::new(lo, hi).set_tolerance(f64::EPSILON.sqrt(), self.tolerance);
        let result = Executor::new(Scalar(objective), solver)
            .configure(|s: IterState<f64, (), (), (), (), f64>| s.max_iters(self.max_iters))
            .ctrlc(false)
            .run()
            .map_err(|e| SolverError::Argmin(e.to_string()))?;
        let state = result.state;
        let (mut x, mut fx) = (state.best_param.unwrap_or(b), state.best_cost);
        if !(fx <= fb) {
            x = b;
            fx = fb;
        }
        let termination = match state.termination_status {
            argmin::core::TerminationStatus::Terminated(
                argmin::core::TerminationReason::SolverConverged,
            ) => Termination::SmallStep,
            argmin::core::TerminationStatus::Terminated(
                argmin::core::TerminationReason::MaxItersReached,
            ) => Termination::MaxIterations,
            ref other => Termination::Other(format!("{other:?}")),
        };
        Ok(SolverReport {
            converged: termination.is_convergence() && fx.is_finite(),
            params: vec![x],
            cost: fx,
            iterations: evals + state.iter,
            termination,
        })
    }
}

/// argmin's Nelder–Mead on an [`Objective`]'s cost.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ArgminNelderMead {
    /// Iteration limit. Default 2000.
    pub max_iters: u64,
    /// Stop when the standard deviation of the simplex's costs is below this (absolute).
    /// Default `1e-10`.
    pub sd_tolerance: f64,
    /// Initial simplex: each vertex moves one coordinate by this (unconstrained coordinates).
    /// Default 0.1.
    pub initial_step: f64,
}

impl Default for ArgminNelderMead {
    fn default() -> Self {
        ArgminNelderMead {
            max_iters: 2000,
            sd_tolerance: 1e-10,
            initial_step: 0.1,
        }
    }
}

struct Infinite<'a, O: ?Sized>(&'a O);

impl<O: Objective + ?Sized> CostFunction for Infinite<'_, O> {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, p: &Vec<f64>) -> Result<f64, Error> {
        let v = self.0.cost(p);
        Ok(if v.is_finite() { v } else { f64::INFINITY })
    }
}

impl ArgminNelderMead {
    /// Minimises `objective` from `start`.
    ///
    /// # Errors
    ///
    /// Invalid options; a start where the cost is not finite; argmin's errors.
    pub fn minimize<O: Objective + ?Sized>(
        &self,
        objective: &O,
        start: &[f64],
    ) -> Result<SolverReport, SolverError> {
        if !(self.initial_step.is_finite() && self.initial_step > 0.0) {
            return Err(SolverError::InvalidOption {
                option: "initial_step",
                value: self.initial_step,
                reason: "must be finite and > 0",
            });
        }
        check_start(objective, start)?;
        let mut simplex = vec![start.to_vec()];
        for j in 0..start.len() {
            let mut v = start.to_vec();
            v[j] += self.initial_step;
            simplex.push(v);
        }
        let solver = NelderMead::new(simplex)
            .with_sd_tolerance(self.sd_tolerance)
            .map_err(|e| SolverError::Argmin(e.to_string()))?;
        let result = Executor::new(Infinite(objective), solver)
            .configure(|s: IterState<Vec<f64>, (), (), (), (), f64>| s.max_iters(self.max_iters))
            .ctrlc(false)
            .run()
            .map_err(|e| SolverError::Argmin(e.to_string()))?;
        let mut state = result.state;
        let termination = match state.termination_status {
            argmin::core::TerminationStatus::Terminated(
                argmin::core::TerminationReason::SolverConverged,
            ) => Termination::SmallCostChange,
            argmin::core::TerminationStatus::Terminated(
                argmin::core::TerminationReason::MaxItersReached,
            ) => Termination::MaxIterations,
            ref other => Termination::Other(format!("{other:?}")),
        };
        let params = state.take_best_param().unwrap_or_else(|| start.to_vec());
        let cost = objective.cost(&params);
        Ok(SolverReport {
            converged: termination.is_convergence() && cost.is_finite(),
            params,
            cost,
            iterations: state.get_iter(),
            termination,
        })
    }
}
