//! A registry entry: a family's name, its keys, and how to build it.

use super::{
    FamilyEntry, JitterRegistry, ParamSpec, SpecReader, FAMILY_KEY, OFFSET_KEY, TERMS_KEY,
};
use crate::{AnyJitter, JitterError};
use jitterid_registry::Entry;
use std::fmt;

/// A registry entry: a family's name, a one-line summary, its keys, and its constructors (an
/// [`Entry`] of the workspace's registry shape whose build context is the [`JitterRegistry`]).
///
/// ```
/// use jitterid_jitter::registry::{Family, JitterRegistry, ParamSpec, SpecTable};
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
/// fn r_spec(s: f64) -> SpecTable {
///     serde_json::json!({"std": s}).as_object().unwrap().clone()
/// }
/// let mut registry = JitterRegistry::builtin().clone();
/// registry.register(entry).unwrap();
/// let j = registry.build(serde_json::json!({"family": "normal", "std": 0.2}).as_object().unwrap()).unwrap();
/// assert_eq!(j.std_dev(), 0.2);
/// assert_eq!(j.spec()["std"], 0.2);
/// ```
#[derive(Clone)]
pub struct Family(FamilyEntry);

impl fmt::Debug for Family {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Family")
            .field("name", &self.name())
            .field("params", &self.params())
            .field("takes_terms", &self.takes_terms())
            .finish_non_exhaustive()
    }
}

impl AsRef<FamilyEntry> for Family {
    fn as_ref(&self) -> &FamilyEntry {
        &self.0
    }
}

/// The registry a family's constructor builds terms with: the one building it (always given
/// by [`JitterRegistry`]), else the built-in one.
fn registry_of(context: Option<&JitterRegistry>) -> &JitterRegistry {
    context.unwrap_or_else(|| JitterRegistry::builtin())
}

impl Family {
    /// An entry named `name` whose spec tables hold `params`, built by `build`.
    pub fn new(
        name: &'static str,
        summary: &'static str,
        params: Vec<ParamSpec>,
        build: impl Fn(&SpecReader<'_>, &JitterRegistry) -> Result<AnyJitter, JitterError>
            + Send
            + Sync
            + 'static,
    ) -> Self {
        Family(
            Entry::with_context(name, summary, params, move |r, cx| {
                build(r, registry_of(cx))
            })
            .needs_context(),
        )
    }

    /// The same entry, also built from a standard deviation by `from_std_dev(sigma, spec,
    /// registry)` (the spec holds the keys `sigma` does not determine).
    pub fn with_std_dev(
        self,
        from_std_dev: impl Fn(f64, &SpecReader<'_>, &JitterRegistry) -> Result<AnyJitter, JitterError>
            + Send
            + Sync
            + 'static,
    ) -> Self {
        Family(
            self.0
                .with_scaled(move |sigma, r, cx| from_std_dev(sigma, r, registry_of(cx))),
        )
    }

    /// The same entry, whose spec tables hold `"terms"`: an array of spec tables.
    pub fn with_terms(self) -> Self {
        let terms = ParamSpec::new(
            TERMS_KEY,
            "the terms (`[[jitter.terms]]` in an experiment file)",
            "",
            format!("two or more tables, each with its own `{FAMILY_KEY}` and keys"),
        );
        Family(self.0.with_nested(terms))
    }

    /// The family's name in spec tables.
    pub fn name(&self) -> &'static str {
        self.0.name
    }

    /// A one-line description.
    pub fn summary(&self) -> &'static str {
        self.0.summary
    }

    /// The family's own keys (besides `"family"`, `"offset"` and `"terms"`).
    pub fn params(&self) -> &[ParamSpec] {
        &self.0.params
    }

    /// Whether spec tables of the family hold `"terms"`.
    pub fn takes_terms(&self) -> bool {
        self.0.nested().iter().any(|p| p.key == TERMS_KEY)
    }

    /// Whether [`JitterRegistry::from_std_dev`] can build the family.
    pub fn has_std_dev_form(&self) -> bool {
        self.0.has_scaled()
    }

    /// Every key a spec table of the family may hold.
    pub fn keys(&self) -> Vec<&str> {
        let mut keys = self.0.keys(FAMILY_KEY, &[]);
        keys.push(OFFSET_KEY);
        keys
    }
}
