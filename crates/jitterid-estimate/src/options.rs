//! [`FitOptions`]: how [`fit`](crate::fit) runs, for every criterion alike.

use crate::fit::{Frequencies, MomentOptions};
use crate::solver::{AnySolver, DynSolver, Transform};
use jitterid_window::{DirichletWindow, Window};
use std::sync::Arc;

/// How [`fit`](crate::fit), [`fit_profile`](crate::fit_profile) and
/// [`estimate_joint`](crate::estimate_joint) run: the one options type of every criterion.
///
/// A criterion reads what concerns it: the first-moment criteria the frequency set and the
/// window, the likelihoods the start of `σ_v` and the parameter constraints; every criterion
/// the solver and whether to compute the covariance.
///
/// ```
/// use jitterid_estimate::solver::GaussNewtonLineSearch;
/// use jitterid_estimate::{FitOptions, Frequencies};
/// use jitterid_window::HannWindow;
///
/// let options = FitOptions::default()
///     .with_frequencies(Frequencies::Band { min: 0.0, max: 0.25 })
///     .with_window(HannWindow)
///     .with_solver(GaussNewtonLineSearch::default());
/// assert_eq!(options.solver.as_ref().map(|s| s.name()), Some("gauss-newton"));
/// assert!(options.covariance);
/// ```
#[derive(Clone, Debug)]
pub struct FitOptions {
    /// The frequency set of a first-moment criterion (default: the DFT grid).
    pub frequencies: Frequencies,
    /// The window (taper) of the DTFT of a first-moment criterion (default: rectangular, the
    /// paper's).
    pub window: Arc<dyn Window>,
    /// The solver; `None` for the criterion's default (Levenberg–Marquardt for the
    /// first-moment criteria; Brent's method for one parameter and BFGS otherwise,
    /// [`BrentOrBfgs`](crate::solver::BrentOrBfgs), for the likelihoods).
    pub solver: Option<AnySolver>,
    /// Whether to compute the covariance of the estimate (default true).
    pub covariance: bool,
    /// Start of `σ_v` for a likelihood that estimates it (default: from the residuals'
    /// variance minus the jitter's).
    pub noise_std_start: Option<f64>,
    /// Constraints of a likelihood's parameters, one per parameter (default: positive widths
    /// and noise level, stable noise shapes; see `jitterid_likelihood::default_transforms`).
    pub transforms: Option<Vec<Transform>>,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            frequencies: Frequencies::Dft,
            window: Arc::new(DirichletWindow),
            solver: None,
            covariance: true,
            noise_std_start: None,
            transforms: None,
        }
    }
}

impl FitOptions {
    /// These options with the frequency set `frequencies`.
    #[must_use]
    pub fn with_frequencies(mut self, frequencies: Frequencies) -> Self {
        self.frequencies = frequencies;
        self
    }

    /// These options with the window `window`.
    #[must_use]
    pub fn with_window(mut self, window: impl Window + 'static) -> Self {
        self.window = Arc::new(window);
        self
    }

    /// These options with the solver `solver` (any solver of `jitterid_optim`, an
    /// [`AnySolver`] from the registry, or a [`DynSolver`] of one's own).
    #[must_use]
    pub fn with_solver(mut self, solver: impl DynSolver + 'static) -> Self {
        let any = &solver as &dyn std::any::Any;
        self.solver = Some(match any.downcast_ref::<AnySolver>() {
            Some(s) => s.clone(),
            None => AnySolver::new(solver),
        });
        self
    }

    /// These options with the covariance computed or not.
    #[must_use]
    pub fn with_covariance(mut self, covariance: bool) -> Self {
        self.covariance = covariance;
        self
    }

    /// These options with `σ_v` started at `noise_std` by a likelihood that estimates it.
    #[must_use]
    pub fn with_noise_std_start(mut self, noise_std: f64) -> Self {
        self.noise_std_start = Some(noise_std);
        self
    }

    /// The typed options of the least-squares estimator: the solver (Levenberg–Marquardt by
    /// default) and the window behind their trait objects.
    pub(crate) fn moment(&self) -> MomentOptions<AnySolver, Arc<dyn Window>> {
        MomentOptions {
            frequencies: self.frequencies.clone(),
            window: self.window.clone(),
            solver: self.solver.clone().unwrap_or_default(),
            covariance: self.covariance,
        }
    }

    /// These options with the likelihood's parameters constrained by `transforms`.
    #[must_use]
    pub fn with_transforms(mut self, transforms: Vec<Transform>) -> Self {
        self.transforms = Some(transforms);
        self
    }
}
