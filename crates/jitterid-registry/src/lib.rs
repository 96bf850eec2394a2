//! The one run-time registry shape of **jitterid**.
//!
//! Every choice a front end makes at run time (a jitter family, a signal, a noise model, a
//! criterion, a solver) is made by name from a registry and built from a *spec table*: a JSON
//! object ([`SpecTable`]) whose registry key (`"noise"`, `"criterion"`, `"solver"`, …) names the
//! choice and whose other keys are that choice's parameters. This crate holds the pieces every
//! such registry shares and depends on no model type:
//!
//! * [`ParamSpec`]: one key described for a reader (meaning, unit, constraint, default, whether
//!   it is a whole number or a boolean). Help texts and generated docs are written from these.
//! * [`Registry`] of [`Entry`]s: named constructors; [`Registry::build`] checks the table's keys
//!   against the entry's [`ParamSpec`]s before the constructor sees it.
//!   An entry may take a *build context* ([`Entry::with_context`]: the jitter registry hands
//!   itself to composite families whose terms are spec tables, the signal registry the known
//!   input), keys whose values are spec tables ([`Entry::with_nested`]), and a second
//!   constructor from one number ([`Entry::with_scaled`], [`Registry::build_scaled`]: a jitter
//!   family's member of a given standard deviation). [`Registry::markdown_table`] writes the
//!   entries and their keys for the docs.
//! * [`RegistryError`]: every error names the offending key ([`RegistryError::key`]), so a
//!   front end can point at it in its own input. A registry may report in its crate's own
//!   error type instead: one that implements [`SpecError`].
//! * [`SpecReader`]: the typed reader of a checked table that an entry's constructor gets
//!   (numbers with their defaults, whole numbers, booleans), its errors in the registry's error
//!   type; [`keys`] also holds helpers that read a bare table with [`RegistryError`]s.
//!
//! Conventions: a key absent from the table takes its [`ParamSpec::default`]; a key without a
//! default is required; whole numbers and booleans are carried as `f64` defaults (0/1 for
//! booleans). Values go through the constructor of the type they build, so a registry accepts
//! exactly what the library accepts.
//!
//! ```
//! use jitterid_registry::{keys, Entry, ParamSpec, Registry, SpecTable};
//!
//! // A registry of step sizes, named under "step".
//! let mut registry: Registry<f64> = Registry::empty("step", "step rule", vec![], None);
//! let h = ParamSpec::new("h", "the step", "", "> 0").with_default(0.1);
//! registry
//!     .register(Entry::new("fixed", "a fixed step", vec![h.clone()], move |t| {
//!         keys::number(t, &h, "fixed")
//!     }))
//!     .unwrap();
//! let table: SpecTable = serde_json::json!({"step": "fixed", "h": 0.5})
//!     .as_object()
//!     .unwrap()
//!     .clone();
//! assert_eq!(registry.build(&table).unwrap(), 0.5);
//! let bad = serde_json::json!({"step": "fixed", "k": 1}).as_object().unwrap().clone();
//! assert_eq!(registry.build(&bad).unwrap_err().key(), Some("k"));
//! ```
#![warn(missing_docs)]

mod error;
pub mod keys;
mod param_spec;
mod registry;

pub use error::{RegistryError, SpecError};
pub use keys::SpecReader;
pub use param_spec::ParamSpec;
pub use registry::{Build, BuildScaled, Builtin, Entry, Registry, Wrap};

/// A spec table: key/value construction input.
pub type SpecTable = serde_json::Map<String, serde_json::Value>;
