//! [`Registry`] and [`Entry`]: registered choices of one kind, built from spec tables.

use crate::keys::{check_table, name_in, SpecReader};
use crate::{ParamSpec, RegistryError, SpecError, SpecTable};
use std::fmt;
use std::marker::PhantomData;
use std::sync::Arc;

/// Builds an entry's value from its checked spec table and the build context, if the entry
/// takes one (see [`Entry::with_context`]).
pub type Build<T, C = (), E = RegistryError> =
    dyn Fn(&SpecReader<'_, E>, Option<&C>) -> Result<T, E> + Send + Sync;

/// Builds an entry's value from one number (a scale, such as a jitter family's standard
/// deviation), its checked spec table and the build context (see [`Entry::with_scaled`]).
pub type BuildScaled<T, C = (), E = RegistryError> =
    dyn Fn(f64, &SpecReader<'_, E>, Option<&C>) -> Result<T, E> + Send + Sync;

/// After-build step of a registry: gets the spec table and the built value (for example the
/// solver registry's multi-start wrapper).
pub type Wrap<T, E = RegistryError> = fn(&SpecTable, T) -> Result<T, E>;

/// After-build step of a registry, reading the table through the entry's reader (see
/// [`Registry::with_wrap`]).
type WrapFn<T, E> = dyn Fn(&SpecReader<'_, E>, T) -> Result<T, E> + Send + Sync;

/// One registered choice: its name, what it is, its keys and how to build it.
///
/// `C` is the build context a registry may hand to the constructor (what the caller knows
/// besides the table: the registry itself for entries whose keys hold spec tables, a known
/// input); `E` the registry's error type.
pub struct Entry<T, C = (), E = RegistryError> {
    /// Registry name.
    pub name: &'static str,
    /// One line on what it is for and what it requires.
    pub summary: &'static str,
    /// Its keys (besides the registry's own key).
    pub params: Vec<ParamSpec>,
    nested: Vec<ParamSpec>,
    needs_context: bool,
    build: Arc<Build<T, C, E>>,
    scaled: Option<Arc<BuildScaled<T, C, E>>>,
}

impl<T, C, E> Clone for Entry<T, C, E> {
    fn clone(&self) -> Self {
        Entry {
            name: self.name,
            summary: self.summary,
            params: self.params.clone(),
            nested: self.nested.clone(),
            needs_context: self.needs_context,
            build: Arc::clone(&self.build),
            scaled: self.scaled.clone(),
        }
    }
}

impl<T, C, E> fmt::Debug for Entry<T, C, E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Entry")
            .field("name", &self.name)
            .field("params", &self.params)
            .finish_non_exhaustive()
    }
}

impl<T, C, E> AsRef<Entry<T, C, E>> for Entry<T, C, E> {
    fn as_ref(&self) -> &Entry<T, C, E> {
        self
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
        Entry::with_context(name, summary, params, move |r, _| build(r.table()))
    }
}

impl<T, C, E> Entry<T, C, E> {
    /// An entry whose constructor reads its table through a [`SpecReader`] (its keys already
    /// checked against `params`) and gets the registry's build context when the entry
    /// [`needs_context`](Self::needs_context) (`None` otherwise).
    pub fn with_context(
        name: &'static str,
        summary: &'static str,
        params: Vec<ParamSpec>,
        build: impl Fn(&SpecReader<'_, E>, Option<&C>) -> Result<T, E> + Send + Sync + 'static,
    ) -> Self {
        Entry {
            name,
            summary,
            params,
            nested: Vec::new(),
            needs_context: false,
            build: Arc::new(build),
            scaled: None,
        }
    }

    /// The same entry, built only with a build context: a registry refuses to build it
    /// without one, and hands it to the constructor.
    pub fn needs_context(mut self) -> Self {
        self.needs_context = true;
        self
    }

    /// The same entry, also built from one number (a scale) and its table by `scaled` (see
    /// [`Registry::build_scaled`]).
    pub fn with_scaled(
        mut self,
        scaled: impl Fn(f64, &SpecReader<'_, E>, Option<&C>) -> Result<T, E> + Send + Sync + 'static,
    ) -> Self {
        self.scaled = Some(Arc::new(scaled));
        self
    }

    /// The same entry with a key `spec` whose value is made of spec tables (the terms of a
    /// composite jitter family): accepted in its tables, read by its constructor, listed after
    /// the `params` in [`Registry::markdown_table`] (without a unit).
    pub fn with_nested(mut self, spec: ParamSpec) -> Self {
        self.nested.push(spec);
        self
    }

    /// Its keys whose values are spec tables.
    pub fn nested(&self) -> &[ParamSpec] {
        &self.nested
    }

    /// Whether it is built only with a build context.
    pub fn takes_context(&self) -> bool {
        self.needs_context
    }

    /// Whether it has a constructor from one number ([`with_scaled`](Self::with_scaled)).
    pub fn has_scaled(&self) -> bool {
        self.scaled.is_some()
    }

    /// Every key its tables may hold in a registry whose key is `registry_key` and whose
    /// common keys are `common`: the registry key, the params, the nested keys, the common
    /// keys.
    pub fn keys<'s>(&'s self, registry_key: &'s str, common: &'s [ParamSpec]) -> Vec<&'s str> {
        let mut keys = vec![registry_key];
        keys.extend(self.params.iter().map(|p| p.key.as_str()));
        keys.extend(self.nested.iter().map(|p| p.key.as_str()));
        keys.extend(common.iter().map(|p| p.key.as_str()));
        keys
    }
}

impl<T, C, E: SpecError> Entry<T, C, E> {
    /// `table` read as one of this entry's, checked to hold no key but
    /// [`keys`](Self::keys)`(registry_key, common)`.
    ///
    /// # Errors
    ///
    /// [`SpecError::unknown_key`] for the first key it does not take.
    pub fn reader<'a>(
        &'a self,
        table: &'a SpecTable,
        registry_key: &str,
        common: &[ParamSpec],
    ) -> Result<SpecReader<'a, E>, E> {
        check_table(
            table,
            self.name,
            &self.params,
            &self.keys(registry_key, common),
        )?;
        Ok(SpecReader::new(self.name, &self.params, table))
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

/// Registered choices of one kind (jitter families, signal kinds, noise models, criteria,
/// solvers), by name. A spec table names its choice under the registry's [`key`](Self::key)
/// and holds the entry's keys.
///
/// `T` is the built value, `C` the build context, `E` the error type, `En` the registered
/// entry: an [`Entry`], or a crate's own entry type wrapping one (`AsRef<Entry<T, C, E>>`).
pub struct Registry<T, C = (), E = RegistryError, En = Entry<T, C, E>> {
    key: &'static str,
    kind: &'static str,
    reserved: Vec<ParamSpec>,
    wrap: Option<Arc<WrapFn<T, E>>>,
    entries: Vec<En>,
    context: PhantomData<fn() -> C>,
}

impl<T, C, E, En: Clone> Clone for Registry<T, C, E, En> {
    fn clone(&self) -> Self {
        Registry {
            key: self.key,
            kind: self.kind,
            reserved: self.reserved.clone(),
            wrap: self.wrap.clone(),
            entries: self.entries.clone(),
            context: PhantomData,
        }
    }
}

impl<T, C, E, En: fmt::Debug> fmt::Debug for Registry<T, C, E, En> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Registry")
            .field("key", &self.key)
            .field("entries", &self.entries)
            .finish_non_exhaustive()
    }
}

impl<T: 'static, C, E: 'static, En> Registry<T, C, E, En> {
    /// An empty registry whose tables name their choice under `key` (a `kind` of thing, for
    /// messages); `reserved` are keys every entry takes, handled by `wrap` after the build.
    pub fn empty(
        key: &'static str,
        kind: &'static str,
        reserved: Vec<ParamSpec>,
        wrap: Option<Wrap<T, E>>,
    ) -> Self {
        Registry {
            key,
            kind,
            reserved,
            wrap: wrap.map(|w| {
                Arc::new(move |r: &SpecReader<'_, E>, value: T| w(r.table(), value))
                    as Arc<WrapFn<T, E>>
            }),
            entries: Vec::new(),
            context: PhantomData,
        }
    }

    /// The same registry, whose after-build step is `wrap` (reading the table through the
    /// entry's reader, so that its errors name the entry).
    pub fn with_wrap(
        mut self,
        wrap: impl Fn(&SpecReader<'_, E>, T) -> Result<T, E> + Send + Sync + 'static,
    ) -> Self {
        self.wrap = Some(Arc::new(wrap));
        self
    }
}

impl<T, C, E, En> Registry<T, C, E, En> {
    /// The key that names the choice in a spec table (`"noise"`, `"criterion"`, `"solver"`).
    pub fn key(&self) -> &'static str {
        self.key
    }

    /// What kind of thing it holds, for messages (`"noise model"`).
    pub fn kind(&self) -> &'static str {
        self.kind
    }

    /// Keys every entry takes besides its own (the solvers' multi-start keys).
    pub fn common_keys(&self) -> &[ParamSpec] {
        &self.reserved
    }

    /// Adds an entry whose name the caller knows to be free (a builtin table); unlike
    /// [`register`](Self::register) it does not check for duplicates.
    pub fn insert(&mut self, entry: En) {
        self.entries.push(entry);
    }

    /// All entries, in registration order.
    pub fn entries(&self) -> &[En] {
        &self.entries
    }
}

impl<T, C, E: SpecError, En: AsRef<Entry<T, C, E>>> Registry<T, C, E, En> {
    /// Adds an entry.
    ///
    /// # Errors
    ///
    /// [`SpecError::duplicate`] ([`RegistryError::Duplicate`]) if the name is taken.
    pub fn register(&mut self, entry: En) -> Result<(), E> {
        let name = entry.as_ref().name;
        if self.entry(name).is_some() {
            return Err(E::duplicate(name));
        }
        self.entries.push(entry);
        Ok(())
    }

    /// The entry called `name`.
    pub fn entry(&self, name: &str) -> Option<&En> {
        self.entries.iter().find(|e| e.as_ref().name == name)
    }

    /// The registered names, in registration order.
    pub fn names(&self) -> Vec<&'static str> {
        self.entries.iter().map(|e| e.as_ref().name).collect()
    }

    fn lookup(&self, name: &str) -> Result<&Entry<T, C, E>, E> {
        self.entry(name)
            .map(AsRef::as_ref)
            .ok_or_else(|| E::unknown_name(self.key, self.kind, name, &self.names()))
    }

    /// The reader of `table` for `entry`: its keys checked against the entry's and the
    /// registry's ([`Entry::reader`]).
    ///
    /// # Errors
    ///
    /// [`SpecError::unknown_key`] for the first key neither takes.
    pub fn reader<'a>(
        &'a self,
        entry: &'a Entry<T, C, E>,
        table: &'a SpecTable,
    ) -> Result<SpecReader<'a, E>, E> {
        entry.reader(table, self.key, &self.reserved)
    }

    /// Builds the choice named under [`key`](Self::key) from its keys.
    ///
    /// # Errors
    ///
    /// An error naming the offending key: an unknown name, a key the entry does not take, a
    /// missing key, a value of the wrong type or outside its domain.
    pub fn build(&self, table: &SpecTable) -> Result<T, E> {
        self.build_with(table, None)
    }

    /// [`build`](Self::build) with a build context, handed to the entries that
    /// [need one](Entry::needs_context).
    ///
    /// # Errors
    ///
    /// Those of [`build`](Self::build), and [`SpecError::missing_context`] when the entry
    /// needs a context and `context` is `None`.
    pub fn build_with(&self, table: &SpecTable, context: Option<&C>) -> Result<T, E> {
        let entry = self.lookup(name_in(table, self.key)?)?;
        let (reader, context) = self.prepare(entry, table, context)?;
        let value = (entry.build)(&reader, context)?;
        self.finish(&reader, value)
    }

    /// The member of entry `name` of scale `x` (its constructor from one number, see
    /// [`Entry::with_scaled`]); `table` holds the entry's other keys.
    ///
    /// # Errors
    ///
    /// [`SpecError::unknown_name`], [`SpecError::no_scaled_form`] when the entry has no such
    /// constructor, and those of [`build_with`](Self::build_with).
    pub fn build_scaled(
        &self,
        name: &str,
        x: f64,
        table: &SpecTable,
        context: Option<&C>,
    ) -> Result<T, E> {
        let entry = self.lookup(name)?;
        let (reader, context) = self.prepare(entry, table, context)?;
        let scaled = entry
            .scaled
            .as_ref()
            .ok_or_else(|| E::no_scaled_form(entry.name))?;
        let value = scaled(x, &reader, context)?;
        self.finish(&reader, value)
    }

    /// The checked reader and the context the entry gets.
    fn prepare<'a>(
        &'a self,
        entry: &'a Entry<T, C, E>,
        table: &'a SpecTable,
        context: Option<&'a C>,
    ) -> Result<(SpecReader<'a, E>, Option<&'a C>), E> {
        if entry.needs_context && context.is_none() {
            return Err(E::missing_context(entry.name));
        }
        let reader = self.reader(entry, table)?;
        Ok((reader, context.filter(|_| entry.needs_context)))
    }

    fn finish(&self, reader: &SpecReader<'_, E>, value: T) -> Result<T, E> {
        match &self.wrap {
            Some(wrap) => wrap(reader, value),
            None => Ok(value),
        }
    }

    /// The entries and their keys as a Markdown table: a header naming the registry key, then
    /// per entry a row with its summary and one per key (its params, then its nested keys),
    /// with unit, accepted values, default (`required` when none) and meaning.
    pub fn markdown_table(&self) -> String {
        let mut out = format!(
            "| {} | key | unit | accepts | default | meaning |\n|---|---|---|---|---|---|\n",
            self.key
        );
        for e in &self.entries {
            let e = e.as_ref();
            let name = e.name;
            out.push_str(&format!("| `{name}` | — | | | | {} |\n", e.summary));
            for p in &e.params {
                out.push_str(&format!(
                    "| `{name}` | `{}` | {} | {} | {} | {} |\n",
                    p.key,
                    p.unit,
                    p.constraint,
                    default_cell(p),
                    p.meaning
                ));
            }
            for p in &e.nested {
                out.push_str(&format!(
                    "| `{name}` | `{}` | | {} | {} | {} |\n",
                    p.key,
                    p.constraint,
                    default_cell(p),
                    p.meaning
                ));
            }
        }
        out
    }
}

/// The default column of a key's row.
fn default_cell(p: &ParamSpec) -> String {
    match p.default {
        Some(d) if p.boolean => (d != 0.0).to_string(),
        Some(d) if p.integer || d.fract() == 0.0 => format!("{d:.0}"),
        Some(d) => d.to_string(),
        None => "required".into(),
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
