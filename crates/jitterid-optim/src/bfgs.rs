//! Dense BFGS with an Armijo backtracking line search, for smooth objectives of a handful of
//! parameters (the likelihood criteria).
//!
//! Written here because the likelihoods are `+∞` outside the model's domain (a negative noise
//! level after a long step, a reach wider than the record), which argmin's Wolfe line searches
//! do not accept. An update is skipped when the curvature `sᵀy` is not positive, so the inverse
//! Hessian stays positive definite. The objective may offer an initial inverse Hessian
//! ([`Objective::initial_metric`]), for example the inverse of the expected information.

use super::progress::{Progress, ProgressHook};
use super::{Solver, SolverError, SolverReport, Termination};
use crate::objective::check_objective_start;
use crate::Objective;
use serde::{Deserialize, Serialize};

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
    /// Receives the iteration and cost after the start's evaluation and after every
    /// iteration, when set (a front end's progress line; not serialised).
    #[serde(skip)]
    pub progress: Option<ProgressHook>,
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
            progress: None,
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

    /// Minimises `objective` from `start` with the initial inverse Hessian `metric` (for
    /// example the inverse of an expected information matrix; ignored unless it is a
    /// symmetric matrix of the right size with a positive diagonal).
    ///
    /// # Errors
    ///
    /// Invalid options; a start of the wrong length, not finite, or where the cost or the
    /// gradient is not finite.
    pub fn minimize_with_metric<O: Objective + ?Sized>(
        &self,
        objective: &O,
        start: &[f64],
        metric: Option<&[Vec<f64>]>,
    ) -> Result<SolverReport, SolverError> {
        self.validate()?;
        check_objective_start(objective, start)?;
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
        let report = |iteration: u64, cost: f64| {
            if let Some(hook) = &self.progress {
                hook.report(&Progress {
                    iteration,
                    cost,
                    elapsed_seconds: started.elapsed().as_secs_f64(),
                });
            }
        };
        report(0, f);
        let termination = loop {
            if iterations >= self.max_iters {
                break Termination::MaxIterations;
            }
            if started.elapsed().as_secs_f64() >= self.max_seconds {
                break Termination::TimeLimit;
            }
            if let Some(stop) = crate::budget_termination() {
                break stop;
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
            report(iterations, f);
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

/// # Requirements
///
/// The problem is an [`Objective`] with a gradient ([`Objective::cost_gradient`]; the default
/// finite differences work). An [`Objective::initial_metric`] is used as the first inverse
/// Hessian when it is valid.
impl<P> Solver<P> for Bfgs
where
    P: Objective + ?Sized,
{
    fn minimize(&self, problem: &P, start: &[f64]) -> Result<SolverReport, SolverError> {
        self.minimize_with_metric(problem, start, problem.initial_metric())
    }
}
