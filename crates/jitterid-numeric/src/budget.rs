//! A wall-clock budget and a cancel flag that every long loop of the library checks.
//!
//! A front end gives a whole command one [`Budget`] and runs the command's work inside
//! [`Budget::run`]; the loops whose length the caller chose (samples of a first moment,
//! rows of a covariance, nodes of a quadrature rule, realisations of a simulation, iterations
//! of a solver) ask [`spent`] as they go and stop early when it says so. A loop that stops
//! leaves its result unfinished (NaN where it did not get to), and the layer that installed
//! the budget turns that into a reported outcome (a fit that stopped on its time limit, a
//! study that was interrupted), never into an answer.
//!
//! The budget travels with the thread: [`Budget::run`] installs it for the closure, and code
//! that hands work to other threads (rayon) takes [`current`] along and installs it there
//! with [`run_with`]. Without a budget, [`spent`] is `false` and costs one thread-local read.
//!
//! ```
//! use jitterid_numeric::budget::{self, Budget};
//! let b = Budget::new(Some(0.0), None);
//! let stopped_at = b.run(|| (0..1000).find(|_| budget::spent()));
//! assert_eq!(stopped_at, Some(0));
//! assert!(b.stop().is_some());
//! assert!(!budget::spent()); // outside `run`, no budget
//! ```

use std::cell::RefCell;
use std::fmt;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Why a budget is spent.
#[non_exhaustive]
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Stop {
    /// The wall-clock limit, in seconds, passed.
    TimeLimit {
        /// The limit.
        seconds: f64,
    },
    /// The caller set the cancel flag (Ctrl-C).
    Cancelled,
}

impl fmt::Display for Stop {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Stop::TimeLimit { seconds } => write!(f, "the time limit of {seconds} s was spent"),
            Stop::Cancelled => f.write_str("it was stopped by the caller"),
        }
    }
}

/// A deadline and a cancel flag, with the budget it was made under (whose stop also stops
/// this one).
#[derive(Debug)]
pub struct Budget {
    seconds: Option<f64>,
    deadline: Option<Instant>,
    cancel: Option<Arc<AtomicBool>>,
    parent: Option<Arc<Budget>>,
    /// Set on the first check that found the budget spent, so that every later check agrees
    /// and a loop that finished just before the deadline is not reported as stopped.
    spent: AtomicBool,
}

impl Budget {
    /// A budget of `seconds` from now (none: no time limit) and `cancel` (none: not
    /// cancellable), under the budget of the calling thread if there is one. A limit that is
    /// not a finite number `>= 0` is taken as no limit, the constructors of the options that
    /// carry it having refused it already; one too large for the clock is no limit either.
    pub fn new(seconds: Option<f64>, cancel: Option<Arc<AtomicBool>>) -> Arc<Self> {
        let seconds = seconds.filter(|s| s.is_finite() && *s >= 0.0);
        let deadline = seconds
            .and_then(|s| Duration::try_from_secs_f64(s).ok())
            .and_then(|d| Instant::now().checked_add(d));
        Arc::new(Budget {
            seconds,
            deadline,
            cancel,
            parent: current(),
            spent: AtomicBool::new(false),
        })
    }

    /// Whether the budget is spent: its time is up, its flag set, or its parent spent.
    pub fn is_spent(&self) -> bool {
        self.stop().is_some()
    }

    /// Why the budget is spent, if it is.
    pub fn stop(&self) -> Option<Stop> {
        if let Some(stop) = self.parent.as_ref().and_then(|p| p.stop()) {
            return Some(stop);
        }
        let cancelled = self
            .cancel
            .as_ref()
            .is_some_and(|c| c.load(Ordering::Relaxed));
        if cancelled {
            self.spent.store(true, Ordering::Relaxed);
            return Some(Stop::Cancelled);
        }
        let timed_out = self.spent.load(Ordering::Relaxed)
            || self.deadline.is_some_and(|d| Instant::now() >= d);
        if timed_out {
            self.spent.store(true, Ordering::Relaxed);
            return Some(Stop::TimeLimit {
                seconds: self.seconds.unwrap_or(0.0),
            });
        }
        None
    }

    /// The seconds left before the deadline (`None` without a time limit).
    pub fn seconds_left(&self) -> Option<f64> {
        let own = self
            .deadline
            .map(|d| d.saturating_duration_since(Instant::now()).as_secs_f64());
        let parent = self.parent.as_ref().and_then(|p| p.seconds_left());
        match (own, parent) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }

    /// `work` run with this budget installed on the calling thread (the previous one is
    /// restored after, also when `work` panics).
    pub fn run<R>(self: &Arc<Self>, work: impl FnOnce() -> R) -> R {
        run_with(Some(self.clone()), work)
    }
}

thread_local! {
    static CURRENT: RefCell<Option<Arc<Budget>>> = const { RefCell::new(None) };
}

/// Restores the thread's previous budget when dropped.
struct Restore(Option<Arc<Budget>>);

impl Drop for Restore {
    fn drop(&mut self) {
        let previous = self.0.take();
        CURRENT.with(|c| *c.borrow_mut() = previous);
    }
}

/// `work` run with `budget` installed on the calling thread (`None`: no budget): how work
/// handed to another thread keeps the budget of the thread that handed it over.
pub fn run_with<R>(budget: Option<Arc<Budget>>, work: impl FnOnce() -> R) -> R {
    let previous = CURRENT.with(|c| std::mem::replace(&mut *c.borrow_mut(), budget));
    let _restore = Restore(previous);
    work()
}

/// The budget installed on the calling thread, to take along to worker threads.
pub fn current() -> Option<Arc<Budget>> {
    CURRENT.with(|c| c.borrow().clone())
}

/// Whether the calling thread's budget is spent (`false` without one): what long loops ask.
pub fn spent() -> bool {
    CURRENT.with(|c| c.borrow().as_ref().is_some_and(|b| b.is_spent()))
}

/// Why the calling thread's budget is spent, if it is.
pub fn stop() -> Option<Stop> {
    CURRENT.with(|c| c.borrow().as_ref().and_then(|b| b.stop()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_budget_is_never_spent() {
        assert!(!spent());
        assert_eq!(stop(), None);
    }

    #[test]
    fn a_zero_budget_is_spent_at_once_and_stays_spent() {
        let b = Budget::new(Some(0.0), None);
        assert_eq!(b.run(stop), Some(Stop::TimeLimit { seconds: 0.0 }));
        assert!(b.is_spent());
        assert!(!spent(), "the budget is uninstalled after run");
    }

    #[test]
    fn a_long_budget_is_not_spent_until_cancelled() {
        let flag = Arc::new(AtomicBool::new(false));
        let b = Budget::new(Some(1e9), Some(flag.clone()));
        assert!(!b.run(spent));
        flag.store(true, Ordering::Relaxed);
        assert_eq!(b.run(stop), Some(Stop::Cancelled));
    }

    #[test]
    fn a_budget_made_inside_another_stops_with_it() {
        let flag = Arc::new(AtomicBool::new(false));
        let outer = Budget::new(None, Some(flag.clone()));
        let inner = outer.run(|| Budget::new(Some(1e9), None));
        assert!(!inner.is_spent());
        flag.store(true, Ordering::Relaxed);
        assert_eq!(inner.stop(), Some(Stop::Cancelled));
    }

    #[test]
    fn the_budget_travels_to_another_thread_with_run_with() {
        let b = Budget::new(Some(0.0), None);
        let seen = b.run(|| {
            let mine = current();
            std::thread::spawn(move || run_with(mine, spent))
                .join()
                .unwrap()
        });
        assert!(seen);
    }

    #[test]
    fn a_limit_beyond_the_clock_or_not_a_number_is_no_limit() {
        assert_eq!(Budget::new(Some(f64::MAX), None).stop(), None);
        assert_eq!(Budget::new(Some(f64::NAN), None).stop(), None);
        assert_eq!(Budget::new(None, None).seconds_left(), None);
    }
}
