//! The registry of jitter families: every family a front end (the command line, Python, the
//! fuzz tests) can choose at run time, with its parameter keys described, built from a spec
//! table of key/value pairs.
//!
//! A spec table is a [`Spec`] (a JSON object): `"family"` names the family, the other keys are
//! the family's (see [`Family::params`]); any family also takes `"offset"` (s), a constant
//! added to the jitter ([`Shifted`]). Composite families (`"sum"`,
//! `"mixture"`) take `"terms"`, an array of spec tables.
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
pub use reader::SpecReader;

use crate::{AnyJitter, JitterError, Shifted};
use std::sync::{Arc, OnceLock};

/// A spec table: key/value construction input of a family.
pub type Spec = serde_json::Map<String, serde_json::Value>;

/// The key naming the family in a spec table.
pub const FAMILY_KEY: &str = "family";

/// The key of a constant offset, taken by every family.
pub const OFFSET_KEY: &str = "offset";

/// The key of the terms of a composite family.
pub const TERMS_KEY: &str = "terms";

/// A set of jitter families by name.
#[derive(Clone, Default)]
pub struct JitterRegistry {
    families: Vec<Arc<Family>>,
}

impl std::fmt::Debug for JitterRegistry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list()
            .entries(self.families.iter().map(|fam| fam.name()))
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
        if self.family(family.name()).is_some() {
            return Err(JitterError::DuplicateFamily {
                family: family.name().to_string(),
            });
        }
        self.families.push(Arc::new(family));
        Ok(())
    }

    /// The family of this name, if registered.
    pub fn family(&self, name: &str) -> Option<&Family> {
        self.families
            .iter()
            .find(|f| f.name() == name)
            .map(|f| f.as_ref())
    }

    /// Every family, in registration order.
    pub fn families(&self) -> impl Iterator<Item = &Family> {
        self.families.iter().map(|f| f.as_ref())
    }

    /// The registered names, quoted and joined for a message.
    pub fn names(&self) -> String {
        let names: Vec<String> = self
            .families
            .iter()
            .map(|f| format!("\"{}\"", f.name()))
            .collect();
        names.join(", ")
    }

    /// The families and their keys as a Markdown table (one row per family with its summary,
    /// then one per key), as `docs/experiments.md` shows it.
    pub fn markdown_table(&self) -> String {
        let mut out = String::from(
            "| family | key | unit | accepts | default | meaning |\n|---|---|---|---|---|---|\n",
        );
        for f in self.families() {
            let name = f.name();
            out.push_str(&format!("| `{name}` | — | | | | {} |\n", f.summary()));
            for p in f.params() {
                let default = match p.default {
                    Some(d) if p.boolean => (d != 0.0).to_string(),
                    Some(d) if p.integer || d.fract() == 0.0 => format!("{d:.0}"),
                    Some(d) => d.to_string(),
                    None => "required".into(),
                };
                out.push_str(&format!(
                    "| `{name}` | `{}` | {} | {} | {default} | {} |\n",
                    p.key, p.unit, p.constraint, p.meaning
                ));
            }
            if f.takes_terms() {
                out.push_str(&format!(
                    "| `{name}` | `{TERMS_KEY}` | | two or more tables, each with its own `{FAMILY_KEY}` and keys | required | the terms (`[[jitter.terms]]` in an experiment file) |\n"
                ));
            }
        }
        out
    }

    fn lookup(&self, name: &str) -> Result<&Family, JitterError> {
        self.family(name).ok_or_else(|| JitterError::UnknownFamily {
            family: name.to_string(),
            known: self.names(),
        })
    }

    /// Builds the model a spec table describes: `"family"`, the family's keys, and optionally
    /// `"offset"`. Every key is checked, and a key the family does not take is an error, so a
    /// front end removes its own keys (such as an experiment file's `estimate`) first; an
    /// error names the key.
    pub fn build(&self, spec: &Spec) -> Result<AnyJitter, JitterError> {
        let name = family_name(spec)?;
        let family = self.lookup(name)?;
        let reader = SpecReader::new(family, spec)?;
        let model = family.build_with(&reader, self)?;
        shift(model, &reader)
    }

    /// The member of family `name` with standard deviation `sigma` (s); `spec` holds the
    /// family's structural keys (such as the uniform sum's integer `n`) and optionally
    /// `"offset"`, but not the keys `sigma` determines. The family `"none"` ignores `sigma`
    /// (which may then be 0).
    pub fn from_std_dev(
        &self,
        name: &str,
        sigma: f64,
        spec: &Spec,
    ) -> Result<AnyJitter, JitterError> {
        let family = self.lookup(name)?;
        // A family without keys (`none`) has no spread to set: any σ, even 0, gives it.
        if !family.params().is_empty() || family.takes_terms() {
            crate::kernels::validate::positive("sigma", sigma)?;
        }
        let reader = SpecReader::new(family, spec)?;
        let model = family.std_dev_member(sigma, &reader, self)?;
        shift(model, &reader)
    }
}

/// The `"family"` value of a spec table.
fn family_name(spec: &Spec) -> Result<&str, JitterError> {
    match spec.get(FAMILY_KEY) {
        Some(serde_json::Value::String(s)) => Ok(s),
        Some(other) => Err(JitterError::InvalidKey {
            family: String::new(),
            key: FAMILY_KEY.into(),
            message: format!("expected a family name (a string), found {other}"),
        }),
        None => Err(JitterError::MissingKey {
            family: String::new(),
            key: FAMILY_KEY.into(),
        }),
    }
}

/// `model` moved by the spec's `"offset"`, if it has one.
fn shift(model: AnyJitter, reader: &SpecReader<'_>) -> Result<AnyJitter, JitterError> {
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

#[cfg(test)]
mod tests;
