//! The one run-time criterion type, [`AnyCriterion`] (a first-moment criterion behind a trait
//! object, or a likelihood criterion), one fit entry point for it, and the registry of criteria
//! by name.

use crate::{ml_estimate, ml_profile, ExactMl, MlOptions, QuasiMl};
use jitterid_estimate::solver::AnySolver;
use jitterid_estimate::EstimateError;
use jitterid_estimate::Fit;
use jitterid_estimate::ModelStructure;
use jitterid_estimate::NoiseModel;
use jitterid_estimate::Record;
use jitterid_estimate::{estimate, EstimateOptions, Frequencies};
use jitterid_estimate::{profile, Profile};
use jitterid_estimate::{Bcls, BoxJenkins, Criterion, Ls, WeightedBcls};
use jitterid_jitter::JitterModel;
use jitterid_registry::keys::{number, numbers, real};
use jitterid_registry::{Builtin, Entry, Registry, RegistryError};
use jitterid_signal::Signal;
use jitterid_window::DirichletWindow;
use std::sync::Arc;

/// A criterion chosen at run time. Cheap to clone.
///
/// First-moment criteria are any [`Criterion`] behind a trait object; the likelihood
/// criteria ([`QuasiMl`], [`ExactMl`]) are generic over the model and held by value. Both fit
/// through [`AnyCriterion::fit`] and return the one result type, [`Fit`].
#[derive(Clone, Debug)]
pub struct AnyCriterion(Kind);

#[derive(Clone, Debug)]
enum Kind {
    FirstMoment(Arc<dyn Criterion>),
    QuasiMl(QuasiMl),
    ExactMl(ExactMl),
}

/// How [`AnyCriterion::fit`] runs.
#[derive(Clone, Debug)]
pub struct FitOptions {
    /// The frequency set of a first-moment criterion (ignored by the likelihoods).
    pub frequencies: Frequencies,
    /// The solver; `None` for the criterion's default (Levenberg–Marquardt for first-moment
    /// criteria, [`BrentOrBfgs`](jitterid_estimate::solver::BrentOrBfgs) for likelihoods).
    pub solver: Option<AnySolver>,
    /// Whether to compute the covariance of the estimate.
    pub covariance: bool,
    /// Start of `σ_v` for a likelihood that estimates it (default from the residuals).
    pub noise_std_start: Option<f64>,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            frequencies: Frequencies::Dft,
            solver: None,
            covariance: true,
            noise_std_start: None,
        }
    }
}

impl AnyCriterion {
    /// A first-moment criterion.
    pub fn first_moment(criterion: impl Criterion + 'static) -> Self {
        AnyCriterion(Kind::FirstMoment(Arc::new(criterion)))
    }

    /// The Gaussian quasi-likelihood of the first two moments.
    pub fn quasi_ml() -> Self {
        AnyCriterion(Kind::QuasiMl(QuasiMl))
    }

    /// The exact likelihood with the given quadrature settings.
    pub fn exact_ml(criterion: ExactMl) -> Self {
        AnyCriterion(Kind::ExactMl(criterion))
    }

    /// The criterion's name.
    pub fn name(&self) -> &'static str {
        use crate::LikelihoodCriterion;
        match &self.0 {
            Kind::FirstMoment(c) => c.name(),
            Kind::QuasiMl(c) => c.name(),
            Kind::ExactMl(c) => c.name(),
        }
    }

    /// Whether this is a likelihood criterion (its cost is `−log L`).
    pub fn is_likelihood(&self) -> bool {
        !matches!(self.0, Kind::FirstMoment(_))
    }

    /// The first-moment criterion, if it is one.
    pub fn as_first_moment(&self) -> Option<&dyn Criterion> {
        match &self.0 {
            Kind::FirstMoment(c) => Some(c.as_ref()),
            _ => None,
        }
    }

    /// Estimates the free parameters of `structure` from `record` (see
    /// [`estimate`](jitterid_estimate::estimate) and [`ml_estimate`](crate::ml_estimate)).
    ///
    /// # Errors
    ///
    /// Those of the estimator; a likelihood's errors as [`EstimateError::Likelihood`].
    pub fn fit<S, J, N>(
        &self,
        structure: &ModelStructure<S, J, N>,
        record: &Record,
        options: &FitOptions,
    ) -> Result<Fit, EstimateError>
    where
        S: Signal + Clone,
        J: JitterModel + Clone,
        N: NoiseModel,
    {
        match &self.0 {
            Kind::FirstMoment(c) => {
                estimate(structure, record, c.as_ref(), &moment_options(options))
            }
            Kind::QuasiMl(c) => likelihood_fit(structure, record, c, options),
            Kind::ExactMl(c) => likelihood_fit(structure, record, c, options),
        }
    }

    /// Profiles an integer-valued jitter parameter (see [`profile`](jitterid_estimate::profile) and
    /// [`ml_profile`](crate::ml_profile)).
    ///
    /// # Errors
    ///
    /// The first error if no value could be fitted.
    pub fn profile<S, J, N, E>(
        &self,
        structure: &ModelStructure<S, J, N>,
        record: &Record,
        options: &FitOptions,
        values: impl IntoIterator<Item = i64>,
        build: impl Fn(i64) -> Result<J, E> + Sync,
    ) -> Result<Profile<J>, EstimateError>
    where
        S: Signal + Clone,
        J: JitterModel + Clone,
        N: NoiseModel,
        E: Into<EstimateError>,
    {
        let build = |v| build(v).map_err(Into::into);
        match &self.0 {
            Kind::FirstMoment(c) => profile(
                structure,
                record,
                c.as_ref(),
                &moment_options(options),
                values,
                build,
            ),
            Kind::QuasiMl(c) => likelihood_profile(structure, record, c, options, values, build),
            Kind::ExactMl(c) => likelihood_profile(structure, record, c, options, values, build),
        }
    }
}

fn moment_options(options: &FitOptions) -> EstimateOptions<AnySolver, DirichletWindow> {
    EstimateOptions {
        frequencies: options.frequencies.clone(),
        window: DirichletWindow,
        solver: options.solver.clone().unwrap_or_default(),
        covariance: options.covariance,
    }
}

fn ml_options(options: &FitOptions) -> MlOptions {
    MlOptions {
        covariance: options.covariance,
        noise_std_start: options.noise_std_start,
        ..MlOptions::default()
    }
}

fn likelihood_fit<S, J, N, C>(
    structure: &ModelStructure<S, J, N>,
    record: &Record,
    criterion: &C,
    options: &FitOptions,
) -> Result<Fit, EstimateError>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: crate::LikelihoodCriterion,
{
    let base = ml_options(options);
    Ok(match &options.solver {
        None => ml_estimate(structure, record, criterion, &base)?,
        Some(s) => ml_estimate(structure, record, criterion, &base.with_solver(s.clone()))?,
    })
}

fn likelihood_profile<S, J, N, C>(
    structure: &ModelStructure<S, J, N>,
    record: &Record,
    criterion: &C,
    options: &FitOptions,
    values: impl IntoIterator<Item = i64>,
    build: impl Fn(i64) -> Result<J, EstimateError> + Sync,
) -> Result<Profile<J>, EstimateError>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
    C: crate::LikelihoodCriterion,
{
    let base = ml_options(options);
    Ok(match &options.solver {
        None => ml_profile(structure, record, criterion, &base, values, build)?,
        Some(s) => ml_profile(
            structure,
            record,
            criterion,
            &base.with_solver(s.clone()),
            values,
            build,
        )?,
    })
}

/// The key of a spec table that names the criterion.
pub const CRITERION_KEY: &str = "criterion";

/// A registered criterion.
pub type CriterionEntry = Entry<AnyCriterion>;

/// Criteria by name: `"ls"`, `"bcls"`, `"weighted-bcls"` (key `weights`), `"bj"`,
/// `"quasi-ml"` and `"ml"` (the exact likelihood; keys `resolution`, `window`).
pub type CriterionRegistry = Registry<AnyCriterion>;

impl<C: Criterion + Clone + 'static> From<C> for AnyCriterion {
    fn from(criterion: C) -> Self {
        AnyCriterion::first_moment(criterion)
    }
}

impl Builtin for AnyCriterion {
    /// The criteria of this crate.
    ///
    /// ```
    /// use jitterid_likelihood::CriterionRegistry;
    ///
    /// let registry = CriterionRegistry::builtin();
    /// let all: Vec<_> = registry
    ///     .entries()
    ///     .iter()
    ///     .filter(|e| !e.params.iter().any(|p| p.default.is_none()))
    ///     .map(|e| registry.build(serde_json::json!({ "criterion": e.name }).as_object().unwrap()))
    ///     .collect::<Result<_, _>>()?;
    /// assert_eq!(all.len(), 5);
    /// # Ok::<(), jitterid_estimate::RegistryError>(())
    /// ```
    fn builtin() -> Registry<Self> {
        let exact = ExactMl::default();
        let exact_keys = vec![
            real(
                "resolution",
                "signal range of one refined quadrature sub-interval",
                "σ_v",
                "> 0, finite",
                Some(exact.resolution),
            ),
            real(
                "window",
                "distance from y_k beyond which sub-intervals share one rule",
                "σ_v",
                "> 0, finite",
                Some(exact.window),
            ),
        ];
        let keys = exact_keys.clone();
        let entries = vec![
            Entry::fixed(
                "ls",
                "naive least squares, jitter ignored (the paper's eq. 9)",
                Ls,
            ),
            Entry::fixed(
                "bcls",
                "bias-compensated least squares (the paper's eq. 14)",
                Bcls,
            ),
            Entry::new(
                "weighted-bcls",
                "BCLS with one weight per frequency of the set",
                vec![real(
                    "weights",
                    "one weight per frequency of the set",
                    "",
                    "a list of finite numbers >= 0, not all zero",
                    None,
                )],
                |t| {
                    if !t.contains_key("weights") {
                        return Err(RegistryError::MissingKey {
                            key: "weights".into(),
                            entry: "weighted-bcls".into(),
                        });
                    }
                    let w = WeightedBcls::new(numbers(t, "weights")?)
                        .map_err(|e| RegistryError::bad("weights", e))?;
                    Ok(AnyCriterion::first_moment(w))
                },
            ),
            Entry::fixed(
                "bj",
                "Box–Jenkins: BCLS weighted by the inverse noise shape",
                BoxJenkins,
            ),
            Entry::new(
                "quasi-ml",
                "Gaussian quasi-likelihood of the first two moments (a likelihood)",
                Vec::new(),
                |_| Ok(AnyCriterion::quasi_ml()),
            ),
            Entry::new(
                "ml",
                "exact likelihood of independent jittered samples, white noise (a likelihood)",
                exact_keys,
                move |t| {
                    let resolution = number(t, &keys[0], "ml")?;
                    let window = number(t, &keys[1], "ml")?;
                    for (key, v) in [("resolution", resolution), ("window", window)] {
                        if !(v.is_finite() && v > 0.0) {
                            return Err(RegistryError::bad(
                                key,
                                format!("must be finite and > 0, got {v}"),
                            ));
                        }
                    }
                    Ok(AnyCriterion::exact_ml(ExactMl {
                        resolution,
                        window,
                        ..ExactMl::default()
                    }))
                },
            ),
        ];
        let mut r = Registry::empty(CRITERION_KEY, "criterion", Vec::new(), None);
        for e in entries {
            r.insert(e);
        }
        r
    }
}
