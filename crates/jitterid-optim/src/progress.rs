//! Progress reports of a running solver: an observer hook that a front end can print. (A
//! front end stops a solver through the budget it runs under, `jitterid_numeric::budget`.)

use argmin::core::observers::Observe;
use argmin::core::{Error, State, KV};
use std::fmt;
use std::sync::Arc;

/// Where a solver is after one iteration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Progress {
    /// Iterations done (accepted steps; 0 after the start's evaluation).
    pub iteration: u64,
    /// The solver's cost at the current point: `½ Σ rᵢ²` for least squares, the criterion's
    /// value (a negative log-likelihood) for the likelihood solvers.
    pub cost: f64,
    /// Seconds since the run started.
    pub elapsed_seconds: f64,
}

/// A callback that receives a [`Progress`] after the start's evaluation and after every
/// iteration. Cheap to clone (shared).
///
/// ```
/// use jitterid_optim::{LevenbergMarquardt, ProgressHook};
/// let solver = LevenbergMarquardt::default()
///     .with_progress(ProgressHook::new(|p| eprintln!("{} {:.3e}", p.iteration, p.cost)));
/// # let _ = solver;
/// ```
#[derive(Clone)]
pub struct ProgressHook {
    report: Arc<dyn Fn(&Progress) + Send + Sync>,
}

impl ProgressHook {
    /// Wraps `report`.
    pub fn new(report: impl Fn(&Progress) + Send + Sync + 'static) -> Self {
        ProgressHook {
            report: Arc::new(report),
        }
    }

    /// Calls the hook.
    pub fn report(&self, progress: &Progress) {
        (self.report)(progress);
    }
}

/// Two hooks are equal when they share the same callback (so options holding a hook compare).
impl PartialEq for ProgressHook {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.report, &other.report)
    }
}

impl fmt::Debug for ProgressHook {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("ProgressHook")
    }
}

/// The hook as an argmin observer, for solvers run through argmin's executor.
pub(crate) struct ProgressObserver {
    pub(crate) hook: ProgressHook,
    pub(crate) started: std::time::Instant,
}

impl ProgressObserver {
    /// Reports `state` after `iteration` iterations.
    fn send<I: State<Float = f64>>(&self, iteration: u64, state: &I) {
        self.hook.report(&Progress {
            iteration,
            cost: state.get_cost(),
            elapsed_seconds: self.started.elapsed().as_secs_f64(),
        });
    }
}

impl<I: State<Float = f64>> Observe<I> for ProgressObserver {
    fn observe_init(&mut self, _name: &str, state: &I, _kv: &KV) -> Result<(), Error> {
        self.send(0, state);
        Ok(())
    }

    /// argmin observes an iteration before it counts it: this is iteration `get_iter() + 1`.
    fn observe_iter(&mut self, state: &I, _kv: &KV) -> Result<(), Error> {
        self.send(state.get_iter() + 1, state);
        Ok(())
    }
}
