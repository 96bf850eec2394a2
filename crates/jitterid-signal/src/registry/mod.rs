//! The registry of signal kinds: every signal model a front end (the command line, Python, the
//! fuzz tests) can choose at run time, with its keys described, built from a spec table of
//! key/value pairs plus the known input that drives it.
//!
//! A spec table is a [`SpecTable`] (a JSON object): `"kind"` names the kind, the other keys are
//! the kind's (see [`SignalKind::params`]). The built-in kinds:
//!
//! | kind | keys | input |
//! |---|---|---|
//! | `zpk` | `gain`, `zeros` (optional), `poles` | piecewise constant or tones |
//! | `tf` | `num`, `den` | piecewise constant or tones |
//! | `sinusoid` | `amplitude`, `frequency` (Hz), `phase` (rad, default 0) | none |
//! | `pulse-response` | `coefficients`, `interval` (s) | piecewise constant |
//! | `grey-box` | `params`, `fixed` (optional), `bounds` (optional), `a`, `b`, `c`, `d` (optional) | piecewise constant |
//!
//! `zpk` and `tf` also take `delay` (s, ≥ 0: an input delay, the parameter `delay`; see
//! [`Delayed`](crate::Delayed)) and `initial` (one value per pole: the free response from an
//! unknown state at `origin`, default 0, parameters `initial.j`; see
//! [`WithInitialState`](crate::WithInitialState)), each a parameter only when given, and
//! `offset` with `estimate_offset` (an output offset `y₀` added to the response, the parameter
//! `offset` when `estimate_offset = true`; see [`Offset`](crate::Offset)).
//!
//! A root (in `zeros`, `poles`) is a number (a real root) or `[re, im]` with `im > 0` (the pair
//! `re ± i·im`). Errors name the offending key ([`SignalError::key`]).
//!
//! ```
//! use jitterid_signal::registry::SignalRegistry;
//! use jitterid_signal::testing::binary;
//! use jitterid_signal::Signal;
//! let spec = serde_json::json!({
//!     "kind": "zpk", "gain": 0.2, "zeros": [-0.5], "poles": [[-0.25, 0.3]],
//! });
//! let input = binary(1, 8.0, 0.0, 200.0).unwrap().into();
//! let registry = SignalRegistry::builtin();
//! let s = registry.build(spec.as_object().unwrap(), Some(&input)).unwrap();
//! assert_eq!(s.params(), [0.2, -0.5, -0.25, 0.3]);
//! let bad = serde_json::json!({"kind": "zpk", "gain": 1.0, "poles": [0.5]});
//! let e = registry.build(bad.as_object().unwrap(), Some(&input)).unwrap_err();
//! assert_eq!(e.key(), Some("poles"));
//! ```
//!
//! # Adding a kind at run time
//!
//! One type implementing [`Signal`](crate::Signal) and one [`SignalKind`] given to
//! [`SignalRegistry::register`].
//!
//! The registry is the workspace's one run-time registry shape ([`jitterid_registry::Registry`]
//! of [`SignalKind`] entries, each an [`Entry`]) whose build context is the known [`Input`]:
//! a kind that needs an input gets it, one that does not gets `None`. Errors are
//! [`SignalError`]s.

mod builtin;
mod greybox;
mod reader;

pub use builtin::roots_json;
/// The description of one spec-table key, shared by every registry of the workspace.
pub use jitterid_registry::ParamSpec;
/// A spec table: key/value construction input, shared by every registry of the workspace.
pub use jitterid_registry::SpecTable;
/// The former name of [`SpecTable`] in this module, kept so that the path still resolves.
pub use jitterid_registry::SpecTable as Spec;
pub use reader::KindReader;

use crate::{AnySignal, Input, SignalError};
use jitterid_registry::{Entry, Registry};
use std::fmt;
use std::sync::OnceLock;

/// The reader of a kind's spec table ([`jitterid_registry::SpecReader`] with
/// [`SignalError`]s); [`KindReader`] adds the reads of lists, flags and roots.
pub type SpecReader<'a> = jitterid_registry::SpecReader<'a, SignalError>;

/// The key naming the kind in a spec table.
pub const KIND_KEY: &str = "kind";

/// Builds a kind's model from a checked spec table and the input, if any.
pub type BuildFn =
    dyn Fn(&SpecReader<'_>, Option<&Input>) -> Result<AnySignal, SignalError> + Send + Sync;

/// The registry entry a [`SignalKind`] wraps.
pub type KindEntry = Entry<AnySignal, Input, SignalError>;

/// One registry entry: a kind's name, its keys, whether it needs an input, how to build it (an
/// [`Entry`] of the workspace's registry shape whose build context is the input).
#[derive(Clone)]
pub struct SignalKind(KindEntry);

impl fmt::Debug for SignalKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SignalKind")
            .field("name", &self.name())
            .field("params", &self.params())
            .field("needs_input", &self.needs_input())
            .finish()
    }
}

impl AsRef<KindEntry> for SignalKind {
    fn as_ref(&self) -> &KindEntry {
        &self.0
    }
}

impl SignalKind {
    /// A kind named `name`, described by `summary`, taking the keys `params`; `needs_input`
    /// when it is driven by a known input; `build` makes the model from a spec table already
    /// checked against `params` (no unknown key, every required key present). A key is
    /// required unless it has a default or its constraint text starts with `optional` (a list
    /// key such as `zeros`, empty when absent).
    pub fn new(
        name: &'static str,
        summary: &'static str,
        params: Vec<ParamSpec>,
        needs_input: bool,
        build: impl Fn(&SpecReader<'_>, Option<&Input>) -> Result<AnySignal, SignalError>
            + Send
            + Sync
            + 'static,
    ) -> Self {
        let entry = Entry::with_context(name, summary, params, move |r, input| {
            require(r)?;
            build(r, input)
        });
        SignalKind(if needs_input {
            entry.needs_context()
        } else {
            entry
        })
    }

    /// The name, as written after `kind =`.
    pub fn name(&self) -> &'static str {
        self.0.name
    }

    /// One line on what the kind is.
    pub fn summary(&self) -> &'static str {
        self.0.summary
    }

    /// Its keys.
    pub fn params(&self) -> &[ParamSpec] {
        &self.0.params
    }

    /// Whether it is driven by a known input.
    pub fn needs_input(&self) -> bool {
        self.0.takes_context()
    }

    /// `spec` checked against the kind's keys (no unknown key, every required key present),
    /// for reading it back.
    pub fn reader<'a>(&'a self, spec: &'a SpecTable) -> Result<SpecReader<'a>, SignalError> {
        let reader = self.0.reader(spec, KIND_KEY, &[])?;
        require(&reader)?;
        Ok(reader)
    }
}

/// Every required key of the reader's kind is present: those without a default whose
/// constraint does not start with `optional`.
fn require(r: &SpecReader<'_>) -> Result<(), SignalError> {
    match r
        .params()
        .iter()
        .find(|p| p.default.is_none() && !p.constraint.starts_with("optional") && !r.has(&p.key))
    {
        Some(p) => Err(r.missing(&p.key)),
        None => Ok(()),
    }
}

/// A set of signal kinds by name.
#[derive(Clone)]
pub struct SignalRegistry {
    kinds: Registry<AnySignal, Input, SignalError, SignalKind>,
}

impl Default for SignalRegistry {
    fn default() -> Self {
        SignalRegistry {
            kinds: Registry::empty(KIND_KEY, "signal kind", Vec::new(), None),
        }
    }
}

impl fmt::Debug for SignalRegistry {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SignalRegistry")
            .field("kinds", &self.kinds.entries())
            .finish()
    }
}

impl SignalRegistry {
    /// An empty registry.
    pub fn new() -> Self {
        Self::default()
    }

    /// The kinds of this crate (shared, built once): `zpk`, `tf`, `sinusoid`,
    /// `pulse-response`.
    pub fn builtin() -> &'static SignalRegistry {
        static REGISTRY: OnceLock<SignalRegistry> = OnceLock::new();
        REGISTRY.get_or_init(builtin::registry)
    }

    /// Adds a kind; its name must be new.
    pub fn register(&mut self, kind: SignalKind) -> Result<(), SignalError> {
        self.kinds.register(kind)
    }

    /// The kind named `name`.
    pub fn kind(&self, name: &str) -> Option<&SignalKind> {
        self.kinds.entry(name)
    }

    /// Every kind, in registration order.
    pub fn kinds(&self) -> impl Iterator<Item = &SignalKind> {
        self.kinds.entries().iter()
    }

    /// The names, comma-separated, for messages.
    pub fn names(&self) -> String {
        self.kinds.names().join(", ")
    }

    /// The kinds and their keys as a Markdown table (one row per kind with its summary, then
    /// one per key).
    pub fn markdown_table(&self) -> String {
        self.kinds.markdown_table()
    }

    /// The model of `spec` (`"kind"` and its keys) driven by `input`. Errors name the key:
    /// an unknown kind, a missing, unexpected or invalid key, a missing or unsuitable input.
    pub fn build(&self, spec: &SpecTable, input: Option<&Input>) -> Result<AnySignal, SignalError> {
        self.kinds.build_with(spec, input)
    }
}

impl jitterid_registry::SpecError for SignalError {
    fn not_a_name(key: &str, found: &serde_json::Value) -> Self {
        SignalError::InvalidKey {
            kind: String::new(),
            key: key.into(),
            message: format!("expected the name of a kind, found {found}"),
        }
    }

    fn missing_name(key: &str) -> Self {
        SignalError::MissingKey {
            kind: String::new(),
            key: key.into(),
        }
    }

    fn unknown_name(_: &str, _: &'static str, name: &str, known: &[&str]) -> Self {
        SignalError::UnknownKind {
            kind: name.into(),
            known: known.join(", "),
        }
    }

    fn unknown_key(entry: &str, key: &str, params: &[ParamSpec], _: &[&str]) -> Self {
        SignalError::UnexpectedKey {
            kind: entry.into(),
            key: key.into(),
            known: params
                .iter()
                .map(|p| p.key.as_str())
                .collect::<Vec<_>>()
                .join(", "),
        }
    }

    fn missing_key(entry: &str, key: &str) -> Self {
        SignalError::MissingKey {
            kind: entry.into(),
            key: key.into(),
        }
    }

    fn bad_value(entry: &str, key: &str, message: String) -> Self {
        SignalError::InvalidKey {
            kind: entry.into(),
            key: key.into(),
            message,
        }
    }

    fn duplicate(name: &str) -> Self {
        SignalError::DuplicateKind { kind: name.into() }
    }

    fn missing_context(entry: &str) -> Self {
        SignalError::MissingInput { kind: entry.into() }
    }

    fn no_scaled_form(entry: &str) -> Self {
        // Unreached: no signal kind has a constructor from one number.
        SignalError::InvalidKey {
            kind: entry.into(),
            key: KIND_KEY.into(),
            message: "cannot be built from a single number".into(),
        }
    }
}
