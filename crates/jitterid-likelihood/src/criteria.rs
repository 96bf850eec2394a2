//! The one run-time criterion type, [`AnyCriterion`] (any [`FitCriterion`] of the run-time
//! model types behind a shared trait object), and the registry of criteria by name.

use crate::fit_criterion::Likelihood;
use crate::{ExactMl, LikelihoodCriterion, QuasiMl};
use jitterid_estimate::{
    AnyNoise, Bcls, BoxJenkins, CostKind, Criterion, EstimateError, Fit, FitCriterion, FitOptions,
    Ls, ModelStructure, Profile, Record, WeightedBcls,
};
use jitterid_jitter::AnyJitter;
use jitterid_registry::keys::{number, numbers, real};
use jitterid_registry::{Builtin, Entry, Registry, RegistryError};
use jitterid_signal::AnySignal;
use std::sync::Arc;

/// The model structure of run-time choices: a signal, a jitter family and a noise model each
/// chosen by name.
pub type AnyStructure = ModelStructure<AnySignal, AnyJitter, AnyNoise>;

/// A criterion chosen at run time: any [`FitCriterion`] of the run-time model types
/// ([`AnyStructure`]). Cheap to clone.
///
/// A first-moment [`Criterion`], a shipped likelihood ([`QuasiMl`], [`ExactMl`]) or a
/// [`LikelihoodCriterion`] of one's own ([`AnyCriterion::likelihood`]) alike: each fits through
/// [`fit`](jitterid_estimate::fit) (this type is itself a [`FitCriterion`]) and returns the one
/// result type, [`Fit`].
#[derive(Clone, Debug)]
pub struct AnyCriterion(Arc<dyn FitCriterion<AnySignal, AnyJitter, AnyNoise>>);

impl AnyCriterion {
    /// Any criterion of the run-time model types.
    pub fn new(criterion: impl FitCriterion<AnySignal, AnyJitter, AnyNoise> + 'static) -> Self {
        AnyCriterion(Arc::new(criterion))
    }

    /// A first-moment criterion.
    pub fn first_moment(criterion: impl Criterion + 'static) -> Self {
        AnyCriterion::new(criterion)
    }

    /// A likelihood criterion (one's own; see [`Likelihood`]).
    pub fn likelihood(criterion: impl LikelihoodCriterion + 'static) -> Self {
        AnyCriterion::new(Likelihood(criterion))
    }

    /// The Gaussian quasi-likelihood of the first two moments.
    pub fn quasi_ml() -> Self {
        AnyCriterion::new(QuasiMl)
    }

    /// The exact likelihood with the given quadrature settings.
    pub fn exact_ml(criterion: ExactMl) -> Self {
        AnyCriterion::new(criterion)
    }

    /// The criterion's name.
    pub fn name(&self) -> &'static str {
        self.0.name()
    }

    /// Whether this is a likelihood criterion (its cost is `−log L`).
    pub fn is_likelihood(&self) -> bool {
        self.0.cost_kind() == CostKind::NegLogLikelihood
    }

    /// The first-moment criterion, if it is one.
    pub fn as_first_moment(&self) -> Option<&dyn Criterion> {
        self.0.as_first_moment()
    }
}

impl FitCriterion<AnySignal, AnyJitter, AnyNoise> for AnyCriterion {
    fn name(&self) -> &'static str {
        self.0.name()
    }
    fn cost_kind(&self) -> CostKind {
        self.0.cost_kind()
    }
    fn as_first_moment(&self) -> Option<&dyn Criterion> {
        self.0.as_first_moment()
    }
    fn fit(
        &self,
        structure: &AnyStructure,
        record: &Record,
        options: &FitOptions,
    ) -> Result<Fit, EstimateError> {
        self.0.fit(structure, record, options)
    }
    fn profile(
        &self,
        structure: &AnyStructure,
        record: &Record,
        options: &FitOptions,
        values: &[i64],
        build: &(dyn Fn(i64) -> Result<AnyJitter, EstimateError> + Sync),
    ) -> Result<Profile<AnyJitter>, EstimateError> {
        self.0.profile(structure, record, options, values, build)
    }
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
