//! [`AnyJitter`]: one run-time jitter type for every family, built by the
//! [registry](crate::registry).

use crate::registry::{JitterRegistry, SpecTable};
use crate::{Atom, JitterError, JitterModel, QuadratureRule};
use num_complex::Complex64;
use rand::RngCore;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::any::Any;
use std::fmt;
use std::sync::Arc;

/// Writes a model's keys to a spec table (without the `"family"` key).
pub type ToSpec<T> = Arc<dyn Fn(&T) -> SpecTable + Send + Sync>;

/// What [`AnyJitter`] needs of the model inside it beyond [`JitterModel`].
trait DynJitter: Send + Sync {
    fn model(&self) -> &dyn JitterModel;
    fn family(&self) -> &str;
    fn spec(&self) -> SpecTable;
    fn with_params(&self, params: &[f64]) -> Result<AnyJitter, JitterError>;
    fn as_any(&self) -> &dyn Any;
    fn same_as(&self, other: &dyn DynJitter) -> bool;
}

struct Entry<T> {
    family: Arc<str>,
    model: T,
    to_spec: ToSpec<T>,
}

impl<T: JitterModel + Clone + PartialEq + 'static> DynJitter for Entry<T> {
    fn model(&self) -> &dyn JitterModel {
        &self.model
    }
    fn family(&self) -> &str {
        &self.family
    }
    fn spec(&self) -> SpecTable {
        (self.to_spec)(&self.model)
    }
    fn with_params(&self, params: &[f64]) -> Result<AnyJitter, JitterError> {
        Ok(AnyJitter(Arc::new(Entry {
            family: self.family.clone(),
            model: self.model.with_params(params)?,
            to_spec: self.to_spec.clone(),
        })))
    }
    fn as_any(&self) -> &dyn Any {
        &self.model
    }
    fn same_as(&self, other: &dyn DynJitter) -> bool {
        self.family() == other.family()
            && other
                .as_any()
                .downcast_ref::<T>()
                .is_some_and(|m| *m == self.model)
    }
}

/// A jitter model of any family, chosen at run time: cheap to clone (an `Arc` inside), and a
/// [`JitterModel`] that forwards every method, the provided ones included, to the family's
/// own implementation (so a family's fast `rule` or `reach` is kept).
///
/// Built by a [`JitterRegistry`] from a spec table, or wrapped by hand with [`AnyJitter::new`].
/// It serialises as its spec table (`"family"` and the family's keys) and deserialises
/// through [`JitterRegistry::builtin`], so every value read is validated.
///
/// ```
/// use jitterid_jitter::{AnyJitter, JitterModel};
/// let spec = serde_json::json!({"family": "uniform-sum", "n": 2, "a": 0.25});
/// let j: AnyJitter = serde_json::from_value(spec.clone()).unwrap();
/// assert_eq!(j.family(), "uniform-sum");
/// assert_eq!(j.params(), vec![0.25]);
/// assert_eq!(serde_json::to_value(&j).unwrap(), spec);
/// let k = j.with_params(&[0.5]).unwrap();
/// assert_eq!(k.spec()["a"], 0.5);
/// ```
#[derive(Clone)]
pub struct AnyJitter(Arc<dyn DynJitter>);

impl AnyJitter {
    /// Wraps `model` as a member of `family`, with `to_spec` writing its keys (all but
    /// `"family"`) so that the registry entry of `family` rebuilds it.
    pub fn new<T: JitterModel + Clone + PartialEq + 'static>(
        family: impl Into<Arc<str>>,
        model: T,
        to_spec: impl Fn(&T) -> SpecTable + Send + Sync + 'static,
    ) -> Self {
        AnyJitter(Arc::new(Entry {
            family: family.into(),
            model,
            to_spec: Arc::new(to_spec),
        }))
    }

    /// The registry name of the family (for a shifted model, the inner family's).
    pub fn family(&self) -> &str {
        self.0.family()
    }

    /// The spec table that rebuilds this model: `"family"` and the family's keys.
    pub fn spec(&self) -> SpecTable {
        let mut spec = SpecTable::new();
        spec.insert("family".into(), self.family().into());
        spec.extend(self.0.spec());
        spec
    }

    /// The model inside, as a trait object.
    pub fn model(&self) -> &dyn JitterModel {
        self.0.model()
    }

    /// The model inside if it is a `T`.
    pub fn downcast_ref<T: 'static>(&self) -> Option<&T> {
        self.0.as_any().downcast_ref()
    }
}

impl fmt::Debug for AnyJitter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(self.model(), f)
    }
}

impl PartialEq for AnyJitter {
    fn eq(&self, other: &Self) -> bool {
        self.0.same_as(other.0.as_ref())
    }
}

impl Serialize for AnyJitter {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        self.spec().serialize(serializer)
    }
}

impl<'de> Deserialize<'de> for AnyJitter {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let spec = SpecTable::deserialize(deserializer)?;
        JitterRegistry::builtin()
            .build(&spec)
            .map_err(serde::de::Error::custom)
    }
}

impl JitterModel for AnyJitter {
    fn name(&self) -> &'static str {
        self.model().name()
    }
    fn param_names(&self) -> Vec<String> {
        self.model().param_names()
    }
    fn params(&self) -> Vec<f64> {
        self.model().params()
    }
    fn with_params(&self, params: &[f64]) -> Result<Self, JitterError> {
        self.0.with_params(params)
    }
    fn cf(&self, f: f64) -> Complex64 {
        self.model().cf(f)
    }
    fn cf_gradient(&self, f: f64) -> Vec<Complex64> {
        self.model().cf_gradient(f)
    }
    fn mgf(&self, z: Complex64) -> Option<Complex64> {
        self.model().mgf(z)
    }
    fn pdf(&self, tau: f64) -> f64 {
        self.model().pdf(tau)
    }
    fn atoms(&self) -> Vec<Atom> {
        self.model().atoms()
    }
    fn pieces(&self) -> Vec<(f64, f64)> {
        self.model().pieces()
    }
    fn mean(&self) -> f64 {
        self.model().mean()
    }
    fn variance(&self) -> f64 {
        self.model().variance()
    }
    fn sample(&self, rng: &mut dyn RngCore) -> f64 {
        self.model().sample(rng)
    }
    fn num_params(&self) -> usize {
        self.model().num_params()
    }
    fn even_params(&self) -> Vec<bool> {
        self.model().even_params()
    }
    fn std_dev(&self) -> f64 {
        self.model().std_dev()
    }
    fn reach(&self) -> (f64, f64) {
        self.model().reach()
    }
    fn rule(&self, breaks: &[f64], rate: f64) -> QuadratureRule {
        self.model().rule(breaks, rate)
    }
    fn rule_from(&self, from: f64, breaks: &[f64], rate: f64) -> QuadratureRule {
        self.model().rule_from(from, breaks, rate)
    }
}
