//! The registry of jitter families: every family a front end (the command line, Python, the
//! fuzz tests) can choose at run time, with its parameter keys described, built from a spec
//! table of key/value pairs.
//!
//! A spec table is a [`SpecTable`] (a JSON object): `"family"` names the family, the other keys
//! are the family's (see [`Family::params`]); any family also takes `"offset"` (s), a constant
//! added to the jitter ([`Shifted`]). Composite families (`"sum"`,
//! `"mixture"`) take `"terms"`, an array of spec tables.
//!
//! The registry is the workspace's one run-time registry shape ([`jitterid_registry::Registry`]
//! of [`Family`] entries, each an [`Entry`]): the registry hands itself to a family's
//! constructor as its build context (the terms of `sum` and `mixture` are built by it), and a
//! family's second constructor builds its member of a given standard deviation
//! ([`JitterRegistry::from_std_dev`]). Errors are [`JitterError`]s.
//!
//! ```
//! use jitterid_jitter::registry::JitterRegistry;
//! use jitterid_jitter::JitterModel;
//! let registry = JitterRegistry::builtin();
//! let spec = serde_json::json!({"family": "gaussian", "sigma": 0.1, "offset": 0.5});
//! let j = registry.build(spec.as_object().unwrap()).unwrap();
//! assert_eq!(j.mean(), 0.5);
//! // The uniform sum with n = 2 and the same standard deviation as a Gaussian of σ = 0.1.
//! let n2 = serde_json::json!({"n": 2});
//! let u = registry.from_std_dev("uniform-sum", 0.1, n2.as_object().unwrap()).unwrap();
//! assert!((u.std_dev() - 0.1).abs() < 1e-16);
//! ```
//!
//! # Adding a family at run time
//!
//! One type implementing [`JitterModel`](crate::JitterModel) and one [`Family`] entry given to
//! [`JitterRegistry::register`]; see `docs/extending.md`.

mod builtin;
mod family;
mod reader;

pub use family::Family;
/// The description of one spec-table key, shared by every registry of the workspace.
pub use jitterid_registry::ParamSpec;
/// A spec table: key/value construction input, shared by every registry of the workspace.
pub use jitterid_registry::SpecTable;
/// The former name of [`SpecTable`] in this module, kept so that the path still resolves.
pub use jitterid_registry::SpecTable as Spec;
pub use reader::FamilyReader;

use crate::{AnyJitter, JitterError, Shifted};
use jitterid_registry::{Entry, Registry};
use std::sync::OnceLock;

/// The reader of a family's spec table ([`jitterid_registry::SpecReader`] with
/// [`JitterError`]s); [`FamilyReader`] adds the reads of lists and terms.
pub type SpecReader<'a> = jitterid_registry::SpecReader<'a, JitterError>;

/// The key naming the family in a spec table.
pub const FAMILY_KEY: &str = "family";

/// The key of a constant offset, taken by every family.
pub const OFFSET_KEY: &str = "offset";

/// The key of the terms of a composite family.
pub const TERMS_KEY: &str = "terms";

/// The entries of a [`JitterRegistry`], by name.
type Families = Registry<AnyJitter, JitterRegistry, JitterError, Family>;

/// A set of jitter families by name.
#[derive(Clone)]
pub struct JitterRegistry {
    families: Families,
}

impl Default for JitterRegistry {
    fn default() -> Self {
        let offset = ParamSpec::new(OFFSET_KEY, "constant added to the jitter", "s", "finite");
        let families =
            Registry::empty(FAMILY_KEY, "jitter family", vec![offset], None).with_wrap(shift);
        JitterRegistry { families }
    }
}

impl std::fmt::Debug for JitterRegistry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list()
            .entries(self.families().map(Family::name))
            .finish()
    }
}

impl JitterRegistry {
    /// An empty registry.
    pub fn new() -> Self {
        Self::default()
    }

    /// The families of this crate (shared, built once): `none`, `uniform-sum`, `gaussian`,
    /// `laplace`, `two-point`, `exponential`, `periodic`, `sum`, `mixture`.
    pub fn builtin() -> &'static JitterRegistry {
        static REGISTRY: OnceLock<JitterRegistry> = OnceLock::new();
        REGISTRY.get_or_init(builtin::registry)
    }

    /// Adds a family; its name must be new.
    pub fn register(&mut self, family: Family) -> Result<(), JitterError> {
        self.families.register(family)
    }

    /// The family of this name, if registered.
    pub fn family(&self, name: &str) -> Option<&Family> {
        self.families.entry(name)
    }

    /// Every family, in registration order.
    pub fn families(&self) -> impl Iterator<Item = &Family> {
        self.families.entries().iter()
    }

    /// The registered names, quoted and joined for a message.
    pub fn names(&self) -> String {
        quoted(&self.families.names())
    }

    /// The families and their keys as a Markdown table (one row per family with its summary,
    /// then one per key), as `docs/experiments.md` shows it.
    pub fn markdown_table(&self) -> String {
        self.families.markdown_table()
    }

    /// Builds the model a spec table describes: `"family"`, the family's keys, and optionally
    /// `"offset"`. Every key is checked, and a key the family does not take is an error, so a
    /// front end removes its own keys (such as an experiment file's `estimate`) first; an
    /// error names the key.
    pub fn build(&self, spec: &SpecTable) -> Result<AnyJitter, JitterError> {
        representable(self.families.build_with(spec, Some(self))?)
    }

    /// The member of family `name` with standard deviation `sigma` (s); `spec` holds the
    /// family's structural keys (such as the uniform sum's integer `n`) and optionally
    /// `"offset"`, but not the keys `sigma` determines. The family `"none"` ignores `sigma`
    /// (which may then be 0).
    pub fn from_std_dev(
        &self,
        name: &str,
        sigma: f64,
        spec: &SpecTable,
    ) -> Result<AnyJitter, JitterError> {
        let family = self
            .family(name)
            .ok_or_else(|| JitterError::UnknownFamily {
                family: name.to_string(),
                known: self.names(),
            })?;
        // A family without keys (`none`) has no spread to set: any σ, even 0, gives it.
        if !family.params().is_empty() || family.takes_terms() {
            crate::kernels::validate::positive("sigma", sigma)?;
        }
        representable(self.families.build_scaled(name, sigma, spec, Some(self))?)
    }
}

/// `j` if its variance is finite: a member built from finite keys can still have a spread
/// that squares to infinity (`sigma = 1e308`), whose `γ(0)` is then NaN, not 1.
fn representable(j: AnyJitter) -> Result<AnyJitter, JitterError> {
    let variance = crate::JitterModel::variance(&j);
    if variance.is_finite() {
        Ok(j)
    } else {
        Err(JitterError::Unrepresentable {
            family: j.family().to_string(),
            variance,
        })
    }
}

/// Names quoted and joined for a message.
fn quoted(names: &[&str]) -> String {
    let names: Vec<String> = names.iter().map(|n| format!("\"{n}\"")).collect();
    names.join(", ")
}

/// `model` moved by the spec's `"offset"`, if it has one.
fn shift(reader: &SpecReader<'_>, model: AnyJitter) -> Result<AnyJitter, JitterError> {
    let Some(offset) = reader.opt_f64(OFFSET_KEY)? else {
        return Ok(model);
    };
    let shifted = Shifted::new(model.clone(), offset).map_err(|e| reader.invalid(OFFSET_KEY, e))?;
    Ok(AnyJitter::new(model.family().to_string(), shifted, |s| {
        let mut spec = s.inner().spec();
        spec.remove(FAMILY_KEY);
        spec.insert(OFFSET_KEY.into(), s.offset().into());
        spec
    }))
}

impl jitterid_registry::SpecError for JitterError {
    fn not_a_name(key: &str, found: &serde_json::Value) -> Self {
        JitterError::InvalidKey {
            family: String::new(),
            key: key.into(),
            message: format!("expected a family name (a string), found {found}"),
        }
    }

    fn missing_name(key: &str) -> Self {
        JitterError::MissingKey {
            family: String::new(),
            key: key.into(),
        }
    }

    fn unknown_name(_: &str, _: &'static str, name: &str, known: &[&str]) -> Self {
        JitterError::UnknownFamily {
            family: name.to_string(),
            known: quoted(known),
        }
    }

    fn unknown_key(entry: &str, key: &str, _: &[ParamSpec], allowed: &[&str]) -> Self {
        JitterError::UnexpectedKey {
            family: entry.to_string(),
            key: key.to_string(),
            allowed: allowed
                .iter()
                .map(|k| format!("`{k}`"))
                .collect::<Vec<_>>()
                .join(", "),
        }
    }

    fn missing_key(entry: &str, key: &str) -> Self {
        JitterError::MissingKey {
            family: entry.to_string(),
            key: key.to_string(),
        }
    }

    fn bad_value(entry: &str, key: &str, message: String) -> Self {
        JitterError::InvalidKey {
            family: entry.to_string(),
            key: key.to_string(),
            message,
        }
    }

    fn duplicate(name: &str) -> Self {
        JitterError::DuplicateFamily {
            family: name.to_string(),
        }
    }

    fn missing_context(entry: &str) -> Self {
        // Unreached: a JitterRegistry always hands itself to its families.
        JitterError::InvalidKey {
            family: entry.to_string(),
            key: FAMILY_KEY.into(),
            message: "built without the registry of its terms".into(),
        }
    }

    fn no_scaled_form(entry: &str) -> Self {
        JitterError::NoStdDevForm {
            family: entry.to_string(),
        }
    }
}

/// The registry entry a [`Family`] wraps.
pub type FamilyEntry = Entry<AnyJitter, JitterRegistry, JitterError>;

#[cfg(test)]
mod tests;
