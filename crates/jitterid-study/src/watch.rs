//! Hooks through which a front end follows long work (a fit's solver iterations and a study's
//! finished realisations) and stops it (a study checks a cancel flag before each realisation).
//! The study layer calls them and draws nothing itself; the command line turns them into a
//! progress bar, Python into its own callback and its Ctrl-C.

use jitterid::estimate::solver::{AnySolver, ProgressHook};
use std::fmt;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// What a front end watches. The default watches nothing.
#[derive(Clone, Default)]
pub struct Watch {
    /// Called by the solver of a fit after each iteration (the iteration and the cost).
    pub iterations: Option<ProgressHook>,
    /// Called once for each finished realisation of a Monte Carlo study, from the worker
    /// thread that ran it.
    pub runs: Option<Arc<dyn Fn(RunsDone) + Send + Sync>>,
    /// Set by the front end to stop a Monte Carlo study: realisations not yet started are not
    /// run, and the study ends with an error saying it was interrupted.
    pub cancel: Option<Arc<AtomicBool>>,
}

/// How far a Monte Carlo study is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RunsDone {
    /// Realisations finished so far.
    pub done: u64,
    /// Realisations of the study (or of its shard).
    pub total: u64,
}

impl Watch {
    /// Nothing is watched.
    pub fn none() -> Self {
        Self::default()
    }

    /// `solver` reporting its iterations to [`iterations`](Self::iterations), if watched.
    pub(crate) fn watched(&self, solver: AnySolver) -> AnySolver {
        match &self.iterations {
            Some(hook) => solver.with_progress(hook.clone()),
            None => solver,
        }
    }

    /// Whether the front end asked to stop.
    pub fn cancelled(&self) -> bool {
        self.cancel
            .as_ref()
            .is_some_and(|c| c.load(Ordering::Relaxed))
    }

    /// Tells the watcher that one realisation finished.
    pub(crate) fn run_done(&self, progress: RunsDone) {
        if let Some(f) = &self.runs {
            f(progress);
        }
    }
}

impl fmt::Debug for Watch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Watch")
            .field("iterations", &self.iterations.is_some())
            .field("runs", &self.runs.is_some())
            .field("cancelled", &self.cancelled())
            .finish()
    }
}
