//! What a design search reports while it runs, for a front end's progress display: the
//! library never prints, it calls the observer a [`Plan`](super::Plan) carries
//! ([`Plan::with_observer`](super::Plan::with_observer)).
//!
//! The observer rides on the plan rather than on every function's arguments so that the
//! search, the jitter-blind search (a plan derived from the first) and a robust design's prior
//! draws all report to it without a signature changing; it only watches, so what is computed
//! does not depend on it.

use std::fmt;
use std::sync::Arc;

/// One step of a design computation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DesignProgress {
    /// A design search evaluated one more design (memoised repeats are not reported).
    Evaluated {
        /// Whether the search is the jitter-blind one ([`Plan::jitter_blind`](super::Plan::jitter_blind)).
        jitter_blind: bool,
        /// Designs this search has evaluated so far, this one included.
        evaluations: usize,
        /// Points of the search's grid (the part of the search whose size is known before it
        /// runs; the refinement and the file's own design follow); 0 for a search without a
        /// grid (a multisine's descent).
        grid_points: usize,
    },
    /// A robust design's evaluation predicted one more of its prior draws.
    PriorDraw {
        /// Prior draws predicted so far for the design being evaluated.
        done: usize,
        /// Prior draws per design.
        total: usize,
    },
}

/// A shared observer of [`DesignProgress`]: called on the thread that runs the search, in the
/// order of the steps, except in a multisine's descent, whose gradient evaluates its
/// components in parallel and reports each from its own thread (numbered as they start).
#[derive(Clone)]
pub struct DesignObserver(Arc<dyn Fn(&DesignProgress) + Send + Sync>);

impl DesignObserver {
    /// An observer calling `f`.
    pub fn new(f: impl Fn(&DesignProgress) + Send + Sync + 'static) -> Self {
        Self(Arc::new(f))
    }

    /// Reports `p`.
    pub(crate) fn report(&self, p: &DesignProgress) {
        (self.0)(p)
    }
}

impl fmt::Debug for DesignObserver {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("DesignObserver")
    }
}
