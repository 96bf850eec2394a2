//! The registry of signal kinds: every signal model a front end (the command line, Python, the
//! fuzz tests) can choose at run time, with its keys described, built from a spec table of
//! key/value pairs plus the known input that drives it.
//!
//! A spec table is a [`Spec`] (a JSON object): `"kind"` names the kind, the other keys are the
//! kind's (see [`SignalKind::params`]). The built-in kinds:
//!
//! | kind | keys | input |
//! |---|---|---|
//! | `zpk` | `gain`, `zeros` (optional), `poles` | piecewise constant or tones |
//! | `tf` | `num`, `den` | piecewise constant or tones |
//! | `sinusoid` | `amplitude`, `frequency` (Hz), `phase` (rad, default 0) | none |
//! | `pulse-response` | `coefficients`, `interval` (s) | piecewise constant |
//!
//! `zpk` and `tf` also take `delay` (s, ≥ 0: an input delay, the parameter `delay`; see
//! [`Delayed`](crate::Delayed)) and `initial` (one value per pole: the free response from an
//! unknown state at `origin`, default 0, parameters `initial.j`; see
//! [`WithInitialState`](crate::WithInitialState)), each a parameter only when given.
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

mod builtin;
mod reader;

pub use builtin::roots_json;
pub use jitterid_jitter::registry::ParamSpec;
pub use reader::SpecReader;

use crate::{AnySignal, Input, SignalError};
use std::fmt;
use std::sync::{Arc, OnceLock};

/// A spec table: key/value construction input of a signal kind.
pub type Spec = serde_json::Map<String, serde_json::Value>;

/// The key naming the kind in a spec table.
pub const KIND_KEY: &str = "kind";

/// Builds a kind's model from a checked spec table and the input, if any.
pub type BuildFn =
    dyn Fn(&SpecReader<'_>, Option<&Input>) -> Result<AnySignal, SignalError> + Send + Sync;

/// One registry entry: a kind's name, its keys, whether it needs an input, how to build it.
#[derive(Clone)]
pub struct SignalKind {
    name: String,
    summary: String,
    params: Vec<ParamSpec>,
    needs_input: bool,
    build: Arc<BuildFn>,
}

impl fmt::Debug for SignalKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SignalKind")
            .field("name", &self.name)
            .field("params", &self.params)
            .field("needs_input", &self.needs_input)
            .finish()
    }
}

impl SignalKind {
    /// A kind named `name`, described by `summary`, taking the keys `params`; `needs_input`
    /// when it is driven by a known input; `build` makes the model from a spec table already
    /// checked against `params` (no unknown key, every required key present). A key is
    /// required unless it has a default or its constraint text starts with `optional` (a list
    /// key such as `zeros`, empty when absent).
    pub fn new(
        name: impl Into<String>,
        summary: impl Into<String>,
        params: Vec<ParamSpec>,
        needs_input: bool,
        build: impl Fn(&SpecReader<'_>, Option<&Input>) -> Result<AnySignal, SignalError>
            + Send
            + Sync
            + 'static,
    ) -> Self {
        SignalKind {
            name: name.into(),
            summary: summary.into(),
            params,
            needs_input,
            build: Arc::new(build),
        }
    }

    /// The name, as written after `kind =`.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// One line on what the kind is.
    pub fn summary(&self) -> &str {
        &self.summary
    }

    /// Its keys.
    pub fn params(&self) -> &[ParamSpec] {
        &self.params
    }

    /// Whether it is driven by a known input.
    pub fn needs_input(&self) -> bool {
        self.needs_input
    }
}

/// A set of signal kinds by name.
#[derive(Clone, Default, Debug)]
pub struct SignalRegistry {
    kinds: Vec<Arc<SignalKind>>,
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
        if self.kind(kind.name()).is_some() {
            return Err(SignalError::DuplicateKind { kind: kind.name });
        }
        self.kinds.push(Arc::new(kind));
        Ok(())
    }

    /// The kind named `name`.
    pub fn kind(&self, name: &str) -> Option<&SignalKind> {
        self.kinds
            .iter()
            .map(AsRef::as_ref)
            .find(|k| k.name == name)
    }

    /// Every kind, in registration order.
    pub fn kinds(&self) -> impl Iterator<Item = &SignalKind> {
        self.kinds.iter().map(AsRef::as_ref)
    }

    /// The names, comma-separated, for messages.
    pub fn names(&self) -> String {
        self.kinds
            .iter()
            .map(|k| k.name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The model of `spec` (`"kind"` and its keys) driven by `input`. Errors name the key:
    /// an unknown kind, a missing, unexpected or invalid key, a missing or unsuitable input.
    pub fn build(&self, spec: &Spec, input: Option<&Input>) -> Result<AnySignal, SignalError> {
        let name = match spec.get(KIND_KEY) {
            Some(serde_json::Value::String(s)) => s.as_str(),
            Some(other) => {
                return Err(SignalError::InvalidKey {
                    kind: String::new(),
                    key: KIND_KEY.into(),
                    message: format!("expected the name of a kind, found {other}"),
                })
            }
            None => {
                return Err(SignalError::MissingKey {
                    kind: String::new(),
                    key: KIND_KEY.into(),
                })
            }
        };
        let kind = self.kind(name).ok_or_else(|| SignalError::UnknownKind {
            kind: name.into(),
            known: self.names(),
        })?;
        if kind.needs_input && input.is_none() {
            return Err(SignalError::MissingInput {
                kind: kind.name.clone(),
            });
        }
        let reader = SpecReader::new(kind, spec)?;
        (kind.build)(&reader, if kind.needs_input { input } else { None })
    }
}
