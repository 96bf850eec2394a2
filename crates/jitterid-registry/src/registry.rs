//! [`Registry`] and [`Entry`]: registered choices of one kind, built from spec tables.

use crate::keys::{check_keys, name_at, unknown};
use crate::{ParamSpec, RegistryError, SpecTable};
use std::fmt;
use std::sync::Arc;

/// Builds an entry's value from its checked spec table.
pub type Build<T> = dyn Fn(&SpecTable) -> Result<T, RegistryError> + Send + Sync;

/// After-build step of a registry: gets the spec table and the built value (for example the
/// solver registry's multi-start wrapper).
pub type Wrap<T> = fn(&SpecTable, T) -> Result<T, RegistryError>;

/// One registered choice: its name, what it is, its keys and how to build it.
pub struct Entry<T> {
    /// Registry name.
    pub name: &'static str,
    /// One line on what it is for and what it requires.
    pub summary: &'static str,
    /// Its keys (besides the registry's own key).
    pub params: Vec<ParamSpec>,
    build: Arc<Build<T>>,
}

impl<T> Clone for Entry<T> {
    fn clone(&self) -> Self {
        Entry {
            name: self.name,
            summary: self.summary,
            params: self.params.clone(),
            build: Arc::clone(&self.build),
        }
    }
}

impl<T> fmt::Debug for Entry<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Entry")
            .field("name", &self.name)
            .field("params", &self.params)
            .finish_non_exhaustive()
    }
}

impl<T> Entry<T> {
    /// An entry; `build` receives the whole spec table, its keys already checked against
    /// `params`.
    pub fn new(
        name: &'static str,
        summary: &'static str,
        params: Vec<ParamSpec>,
        build: impl Fn(&SpecTable) -> Result<T, RegistryError> + Send + Sync + 'static,
    ) -> Self {
        Entry {
            name,
            summary,
            params,
            build: Arc::new(build),
        }
    }
}

/// Registered choices of one kind (noise models, criteria, solvers), by name. A spec table
/// names its choice under the registry's [`key`](Self::key) and holds the entry's keys.
pub struct Registry<T> {
    key: &'static str,
    kind: &'static str,
    reserved: Vec<ParamSpec>,
    wrap: Option<Wrap<T>>,
    entries: Vec<Entry<T>>,
}

impl<T> Clone for Registry<T> {
    fn clone(&self) -> Self {
        Registry {
            key: self.key,
            kind: self.kind,
            reserved: self.reserved.clone(),
            wrap: self.wrap,
            entries: self.entries.clone(),
        }
    }
}

impl<T> fmt::Debug for Registry<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Registry")
            .field("key", &self.key)
            .field("entries", &self.entries)
            .finish_non_exhaustive()
    }
}

impl<T> Registry<T> {
    /// An empty registry whose tables name their choice under `key` (a `kind` of thing, for
    /// messages); `reserved` are keys every entry takes, handled by `wrap` after the build.
    pub fn empty(
        key: &'static str,
        kind: &'static str,
        reserved: Vec<ParamSpec>,
        wrap: Option<Wrap<T>>,
    ) -> Self {
        Registry {
            key,
            kind,
            reserved,
            wrap,
            entries: Vec::new(),
        }
    }

    /// The key that names the choice in a spec table (`"noise"`, `"criterion"`, `"solver"`).
    pub fn key(&self) -> &'static str {
        self.key
    }

    /// Keys every entry takes besides its own (the solvers' multi-start keys).
    pub fn common_keys(&self) -> &[ParamSpec] {
        &self.reserved
    }

    /// Adds an entry whose name the caller knows to be free (a builtin table); unlike
    /// [`register`](Self::register) it does not check for duplicates.
    pub fn insert(&mut self, entry: Entry<T>) {
        self.entries.push(entry);
    }

    /// Adds an entry.
    ///
    /// # Errors
    ///
    /// [`RegistryError::Duplicate`] if the name is taken.
    pub fn register(&mut self, entry: Entry<T>) -> Result<(), RegistryError> {
        if self.entry(entry.name).is_some() {
            return Err(RegistryError::Duplicate {
                name: entry.name.to_string(),
            });
        }
        self.entries.push(entry);
        Ok(())
    }

    /// The entry called `name`.
    pub fn entry(&self, name: &str) -> Option<&Entry<T>> {
        self.entries.iter().find(|e| e.name == name)
    }

    /// All entries, in registration order.
    pub fn entries(&self) -> &[Entry<T>] {
        &self.entries
    }

    /// Builds the choice named under [`key`](Self::key) from its keys.
    ///
    /// # Errors
    ///
    /// A [`RegistryError`] naming the offending key: an unknown name, a key the entry does
    /// not take, a missing key, a value of the wrong type or outside its domain.
    pub fn build(&self, table: &SpecTable) -> Result<T, RegistryError> {
        let name = name_at(table, self.key)?;
        let entry = self.entry(name).ok_or_else(|| {
            let names: Vec<&str> = self.entries.iter().map(|e| e.name).collect();
            unknown(self.key, self.kind, name, &names)
        })?;
        let mut reserved = vec![self.key];
        reserved.extend(self.reserved.iter().map(|s| s.key.as_str()));
        check_keys(table, entry.name, &reserved, &entry.params)?;
        let value = (entry.build)(table)?;
        match self.wrap {
            Some(wrap) => wrap(table, value),
            None => Ok(value),
        }
    }
}

/// A value type with a builtin registry: what [`Registry::builtin`] returns. Implemented by the
/// crate that defines the value type (the noise models', the solvers', the criteria's).
pub trait Builtin: Sized {
    /// The builtin registry of this value type.
    fn builtin() -> Registry<Self>;
}

impl<T: Builtin> Registry<T> {
    /// The builtin choices of this kind ([`Builtin::builtin`]).
    pub fn builtin() -> Self {
        T::builtin()
    }
}

impl<T: 'static> Entry<T> {
    /// An entry without keys whose value is `T::from(value)` (a clone of `value` each build).
    pub fn fixed<V>(name: &'static str, summary: &'static str, value: V) -> Self
    where
        V: Clone + Send + Sync + 'static,
        T: From<V>,
    {
        Entry::new(name, summary, Vec::new(), move |_| {
            Ok(T::from(value.clone()))
        })
    }
}
