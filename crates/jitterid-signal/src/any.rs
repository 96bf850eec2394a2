//! One run-time signal type: any [`Signal`] behind a shared pointer, with its registry kind and
//! the spec table that rebuilds it.

use crate::registry::SpecTable;
use crate::{Jacobian, SampleGrid, Signal, SignalError, SpectralLine, Spectrum};
use jitterid_jitter::JitterModel;
use num_complex::Complex64;
use std::fmt;
use std::sync::Arc;

/// A signal model chosen at run time (from a [`SignalRegistry`](crate::registry::SignalRegistry)
/// or wrapped by hand), cheap to clone.
///
/// Every method of [`Signal`] is forwarded to the model inside, the fast exact overrides of
/// `expected_values` and friends included. [`Spectrum`] is forwarded when the model has one
/// ([`has_spectrum`](Self::has_spectrum)); otherwise its density is NaN, which
/// `first_moment_integral` reports as a typed error.
///
/// ```
/// use jitterid_signal::registry::SignalRegistry;
/// use jitterid_signal::{Multisine, Signal};
/// let spec = serde_json::json!({"kind": "tf", "num": [1.0], "den": [1.0, 2.0]});
/// let input = Multisine::sine(0.1, 1.0, 0.0).unwrap().into();
/// let s = SignalRegistry::builtin().build(spec.as_object().unwrap(), Some(&input)).unwrap();
/// assert_eq!(s.kind(), "tf");
/// assert_eq!(s.param_names(), ["b0", "a0"]);
/// let t = s.with_params(&[2.0, 2.0]).unwrap();
/// assert_eq!(t.spec()["num"], serde_json::json!([2.0]));
/// ```
#[derive(Clone)]
pub struct AnySignal(Arc<dyn DynSignal>);

impl AnySignal {
    /// Wraps `model` as a member of `kind`, with `to_spec` writing its keys (all but `"kind"`)
    /// so that the registry entry of `kind` rebuilds it from the same input.
    pub fn new<T: Signal + Clone + 'static>(
        kind: impl Into<Arc<str>>,
        model: T,
        to_spec: impl Fn(&T) -> SpecTable + Send + Sync + 'static,
    ) -> Self {
        Self::wrap(kind.into(), model, Arc::new(to_spec), None)
    }

    /// Like [`new`](Self::new), for a model with a closed-form [`Spectrum`], which is then
    /// forwarded too.
    pub fn with_spectrum<T: Spectrum + Clone + 'static>(
        kind: impl Into<Arc<str>>,
        model: T,
        to_spec: impl Fn(&T) -> SpecTable + Send + Sync + 'static,
    ) -> Self {
        Self::wrap(
            kind.into(),
            model,
            Arc::new(to_spec),
            Some(|m: &T| m as &dyn Spectrum),
        )
    }

    fn wrap<T: Signal + Clone + 'static>(
        kind: Arc<str>,
        model: T,
        to_spec: ToSpec<T>,
        spectrum: Option<fn(&T) -> &dyn Spectrum>,
    ) -> Self {
        AnySignal(Arc::new(Entry {
            kind,
            model,
            to_spec,
            spectrum,
        }))
    }

    /// The registry name of the kind.
    pub fn kind(&self) -> &str {
        self.0.kind()
    }

    /// The spec table that rebuilds this model (with the same input): `"kind"` and its keys.
    pub fn spec(&self) -> SpecTable {
        let mut spec = SpecTable::new();
        spec.insert("kind".into(), self.kind().into());
        spec.extend(self.0.spec());
        spec
    }

    /// The same model (same kind and parameters) driven by `input`, rebuilt through the
    /// built-in registry: a model fitted on one record, evaluated on another record's input.
    /// A kind registered elsewhere is rebuilt with
    /// [`SignalRegistry::build`](crate::registry::SignalRegistry::build) of its own registry and
    /// this model's [`spec`](Self::spec).
    ///
    /// # Errors
    ///
    /// Those of [`SignalRegistry::build`](crate::registry::SignalRegistry::build): an unknown
    /// kind, an input the kind cannot take.
    pub fn with_input(&self, input: &crate::Input) -> Result<AnySignal, SignalError> {
        crate::registry::SignalRegistry::builtin().build(&self.spec(), Some(input))
    }

    /// The model inside, as a trait object.
    pub fn model(&self) -> &dyn Signal {
        self.0.model()
    }

    /// The model inside as its own type, when it is a `T` (a front end that needs more of a
    /// model than [`Signal`] gives: the matrices of a grey-box model for export).
    pub fn downcast<T: 'static>(&self) -> Option<&T> {
        self.0.as_any().downcast_ref()
    }

    /// Whether the model has a closed-form spectrum.
    pub fn has_spectrum(&self) -> bool {
        self.0.spectrum().is_some()
    }
}

impl fmt::Debug for AnySignal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.model().fmt(f)
    }
}

impl PartialEq for AnySignal {
    /// Same kind, same keys (the input is not compared).
    fn eq(&self, other: &Self) -> bool {
        self.spec() == other.spec()
    }
}

/// Turns a model into the spec table's keys.
type ToSpec<T> = Arc<dyn Fn(&T) -> SpecTable + Send + Sync>;

struct Entry<T> {
    kind: Arc<str>,
    model: T,
    to_spec: ToSpec<T>,
    spectrum: Option<fn(&T) -> &dyn Spectrum>,
}

trait DynSignal: Send + Sync {
    fn kind(&self) -> &str;
    fn model(&self) -> &dyn Signal;
    fn as_any(&self) -> &dyn std::any::Any;
    fn spectrum(&self) -> Option<&dyn Spectrum>;
    fn spec(&self) -> SpecTable;
    fn with_params(&self, params: &[f64]) -> Result<Arc<dyn DynSignal>, SignalError>;
}

impl<T: Signal + Clone + 'static> DynSignal for Entry<T> {
    fn kind(&self) -> &str {
        &self.kind
    }
    fn model(&self) -> &dyn Signal {
        &self.model
    }
    fn as_any(&self) -> &dyn std::any::Any {
        &self.model
    }
    fn spectrum(&self) -> Option<&dyn Spectrum> {
        self.spectrum.map(|f| f(&self.model))
    }
    fn spec(&self) -> SpecTable {
        (self.to_spec)(&self.model)
    }
    fn with_params(&self, params: &[f64]) -> Result<Arc<dyn DynSignal>, SignalError> {
        Ok(Arc::new(Entry {
            kind: self.kind.clone(),
            model: self.model.with_params(params)?,
            to_spec: self.to_spec.clone(),
            spectrum: self.spectrum,
        }))
    }
}

impl Signal for AnySignal {
    fn param_names(&self) -> Vec<String> {
        self.model().param_names()
    }
    fn params(&self) -> Vec<f64> {
        self.model().params()
    }
    fn with_params(&self, params: &[f64]) -> Result<Self, SignalError> {
        self.0.with_params(params).map(AnySignal)
    }
    fn value(&self, t: f64) -> f64 {
        self.model().value(t)
    }
    fn value_gradient(&self, t: f64, grad: &mut [f64]) {
        self.model().value_gradient(t, grad)
    }
    fn value_and_gradient(&self, t: f64, grad: &mut [f64]) -> f64 {
        self.model().value_and_gradient(t, grad)
    }
    fn breakpoints(&self) -> Vec<f64> {
        self.model().breakpoints()
    }
    fn rate(&self) -> f64 {
        self.model().rate()
    }
    fn num_params(&self) -> usize {
        self.model().num_params()
    }
    fn expected_values(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Vec<f64> {
        self.model().expected_values(grid, jitter)
    }
    fn expected_values_gradient(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Jacobian {
        self.model().expected_values_gradient(grid, jitter)
    }
    fn expected_values_and_gradient(
        &self,
        grid: &SampleGrid,
        jitter: &dyn JitterModel,
    ) -> (Vec<f64>, Jacobian) {
        self.model().expected_values_and_gradient(grid, jitter)
    }
    fn expected_squares(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Vec<f64> {
        self.model().expected_squares(grid, jitter)
    }
}

impl Spectrum for AnySignal {
    fn density(&self, f: f64) -> Complex64 {
        match self.0.spectrum() {
            Some(s) => s.density(f),
            None => Complex64::new(f64::NAN, f64::NAN),
        }
    }
    fn density_gradient(&self, f: f64, grad: &mut [Complex64]) {
        match self.0.spectrum() {
            Some(s) => s.density_gradient(f, grad),
            None => grad.fill(Complex64::new(f64::NAN, f64::NAN)),
        }
    }
    fn lines(&self) -> Vec<SpectralLine> {
        self.0.spectrum().map(|s| s.lines()).unwrap_or_default()
    }
    fn lines_gradient(&self) -> Vec<Vec<(Complex64, f64)>> {
        self.0
            .spectrum()
            .map(|s| s.lines_gradient())
            .unwrap_or_default()
    }
}
