//! The crate's run-time registries (noise models, criteria, solvers) share one shape: a
//! [`Registry`] of [`Entry`]s, each describing its keys with [`ParamSpec`], built from a spec
//! table (`serde_json::Map`), with errors ([`RegistryError`]) that name the offending key.
//! The shape lives in `jitterid-registry` and is re-exported here.
//!
//! Front ends (the command line's TOML tables, Python keyword arguments) convert their input to
//! a spec table and build from it; every value goes through the constructor of the type it
//! builds, so a registry accepts exactly what the library accepts.

#[allow(unused_imports)]
pub(crate) use jitterid_registry::keys::{
    check_keys, count, name_at, number, numbers, real, unknown, whole,
};
pub use jitterid_registry::{
    keys, Build, Builtin, Entry, ParamSpec, Registry, RegistryError, SpecTable, Wrap,
};
