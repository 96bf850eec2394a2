//! A registry entry: a family's name, its keys, and how to build it.

use super::{JitterRegistry, ParamSpec, SpecReader};
use crate::{AnyJitter, JitterError};
use std::fmt;
use std::sync::Arc;

/// Builds a family's model from a checked spec table.
pub type BuildFn =
    dyn Fn(&SpecReader<'_>, &JitterRegistry) -> Result<AnyJitter, JitterError> + Send + Sync;

/// Builds a family's member of a given standard deviation.
pub type StdDevFn =
    dyn Fn(f64, &SpecReader<'_>, &JitterRegistry) -> Result<AnyJitter, JitterError> + Send + Sync;

/// A registry entry: a family's name, a one-line summary, its keys, and its constructors.
///
/// ```
/// use jitterid_jitter::registry::{Family, JitterRegistry, ParamSpec};
/// use jitterid_jitter::{AnyJitter, Gaussian, JitterModel};
///
/// // A second name for the Gaussian family, as a user would add a family of their own.
/// let entry = Family::new(
///     "normal",
///     "zero-mean Gaussian jitter",
///     vec![ParamSpec::new("std", "standard deviation", "s", "> 0")],
///     |r, _| {
///         let g = Gaussian::new(r.f64("std")?).map_err(|e| r.invalid("std", e))?;
///         Ok(AnyJitter::new("normal", g, |g| r_spec(g.sigma())))
///     },
/// )
/// .with_std_dev(|sigma, _, _| Ok(AnyJitter::new("normal", Gaussian::new(sigma)?, |g| r_spec(g.sigma()))));
/// fn r_spec(s: f64) -> jitterid_jitter::registry::Spec {
///     serde_json::json!({"std": s}).as_object().unwrap().clone()
/// }
/// let mut registry = JitterRegistry::builtin().clone();
/// registry.register(entry).unwrap();
/// let j = registry.build(serde_json::json!({"family": "normal", "std": 0.2}).as_object().unwrap()).unwrap();
/// assert_eq!(j.std_dev(), 0.2);
/// assert_eq!(j.spec()["std"], 0.2);
/// ```
#[derive(Clone)]
pub struct Family {
    name: String,
    summary: String,
    params: Vec<ParamSpec>,
    takes_terms: bool,
    build: Arc<BuildFn>,
    from_std_dev: Option<Arc<StdDevFn>>,
}

impl fmt::Debug for Family {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Family")
            .field("name", &self.name)
            .field("params", &self.params)
            .field("takes_terms", &self.takes_terms)
            .finish_non_exhaustive()
    }
}

impl Family {
    /// An entry named `name` whose spec tables hold `params`, built by `build`.
    pub fn new(
        name: impl Into<String>,
        summary: impl Into<String>,
        params: Vec<ParamSpec>,
        build: impl Fn(&SpecReader<'_>, &JitterRegistry) -> Result<AnyJitter, JitterError>
            + Send
            + Sync
            + 'static,
    ) -> Self {
        Family {
            name: name.into(),
            summary: summary.into(),
            params,
            takes_terms: false,
            build: Arc::new(build),
            from_std_dev: None,
        }
    }

    /// The same entry, also built from a standard deviation by `from_std_dev(sigma, spec,
    /// registry)` (the spec holds the keys `sigma` does not determine).
    pub fn with_std_dev(
        mut self,
        from_std_dev: impl Fn(f64, &SpecReader<'_>, &JitterRegistry) -> Result<AnyJitter, JitterError>
            + Send
            + Sync
            + 'static,
    ) -> Self {
        self.from_std_dev = Some(Arc::new(from_std_dev));
        self
    }

    /// The same entry, whose spec tables hold `"terms"`: an array of spec tables.
    pub fn with_terms(mut self) -> Self {
        self.takes_terms = true;
        self
    }

    /// The family's name in spec tables.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// A one-line description.
    pub fn summary(&self) -> &str {
        &self.summary
    }

    /// The family's own keys (besides `"family"`, `"offset"` and `"terms"`).
    pub fn params(&self) -> &[ParamSpec] {
        &self.params
    }

    /// Whether spec tables of the family hold `"terms"`.
    pub fn takes_terms(&self) -> bool {
        self.takes_terms
    }

    /// Whether [`JitterRegistry::from_std_dev`] can build the family.
    pub fn has_std_dev_form(&self) -> bool {
        self.from_std_dev.is_some()
    }

    /// Every key a spec table of the family may hold.
    pub fn keys(&self) -> Vec<&str> {
        let mut keys = vec![super::FAMILY_KEY];
        keys.extend(self.params.iter().map(|p| p.key.as_str()));
        if self.takes_terms {
            keys.push(super::TERMS_KEY);
        }
        keys.push(super::OFFSET_KEY);
        keys
    }

    pub(super) fn build_with(
        &self,
        reader: &SpecReader<'_>,
        registry: &JitterRegistry,
    ) -> Result<AnyJitter, JitterError> {
        (self.build)(reader, registry)
    }

    pub(super) fn std_dev_member(
        &self,
        sigma: f64,
        reader: &SpecReader<'_>,
        registry: &JitterRegistry,
    ) -> Result<AnyJitter, JitterError> {
        match &self.from_std_dev {
            Some(f) => f(sigma, reader, registry),
            None => Err(JitterError::NoStdDevForm {
                family: self.name.clone(),
            }),
        }
    }
}
