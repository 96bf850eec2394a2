//! The one run-time noise type, [`AnyNoise`], and the registry of noise models by name.

use crate::noise::{ArmaNoise, NoiseModel, WhiteNoise, WithFloor};
use crate::registry::{number, numbers, real, Builtin, Entry, ParamSpec, Registry, RegistryError};
use crate::EstimateError;
use std::fmt;
use std::sync::Arc;

/// A noise model behind a trait object: what [`AnyNoise`] holds. Implemented for every
/// [`NoiseModel`].
pub trait DynNoise: fmt::Debug + Send + Sync {
    /// [`NoiseModel::param_names`].
    fn param_names(&self) -> Vec<String>;
    /// [`NoiseModel::params`].
    fn params(&self) -> Vec<f64>;
    /// [`NoiseModel::with_params`], boxed.
    ///
    /// # Errors
    ///
    /// Those of [`NoiseModel::with_params`].
    fn with_params_dyn(&self, params: &[f64]) -> Result<AnyNoise, EstimateError>;
    /// [`NoiseModel::shape`].
    fn shape(&self, f: f64, interval: f64) -> f64;
    /// [`NoiseModel::is_white`].
    fn is_white(&self) -> bool;
    /// [`NoiseModel::floor`].
    fn floor(&self) -> f64;
}

impl<N: NoiseModel + 'static> DynNoise for N {
    fn param_names(&self) -> Vec<String> {
        NoiseModel::param_names(self)
    }
    fn params(&self) -> Vec<f64> {
        NoiseModel::params(self)
    }
    fn with_params_dyn(&self, params: &[f64]) -> Result<AnyNoise, EstimateError> {
        Ok(AnyNoise::new(NoiseModel::with_params(self, params)?))
    }
    fn shape(&self, f: f64, interval: f64) -> f64 {
        NoiseModel::shape(self, f, interval)
    }
    fn is_white(&self) -> bool {
        NoiseModel::is_white(self)
    }
    fn floor(&self) -> f64 {
        NoiseModel::floor(self)
    }
}

/// A noise model chosen at run time: any [`NoiseModel`] behind a shared pointer. Cheap to
/// clone; a [`NoiseModel`] itself, so it fits every structure and criterion.
#[derive(Clone, Debug)]
pub struct AnyNoise(Arc<dyn DynNoise>);

impl AnyNoise {
    /// Wraps a noise model.
    pub fn new<N: NoiseModel + 'static>(noise: N) -> Self {
        AnyNoise(Arc::new(noise))
    }
}

impl Default for AnyNoise {
    /// White noise.
    fn default() -> Self {
        AnyNoise::new(WhiteNoise)
    }
}

impl NoiseModel for AnyNoise {
    fn param_names(&self) -> Vec<String> {
        self.0.param_names()
    }
    fn params(&self) -> Vec<f64> {
        self.0.params()
    }
    fn with_params(&self, params: &[f64]) -> Result<Self, EstimateError> {
        self.0.with_params_dyn(params)
    }
    fn shape(&self, f: f64, interval: f64) -> f64 {
        self.0.shape(f, interval)
    }
    fn is_white(&self) -> bool {
        self.0.is_white()
    }
    fn floor(&self) -> f64 {
        self.0.floor()
    }
}

/// The key of a spec table that names the noise model.
pub const NOISE_KEY: &str = "noise";

/// A registered noise model.
pub type NoiseEntry = Entry<AnyNoise>;

/// Noise models by name: `"white"` and `"arma"` (keys `c`, `d`, optional `floor`).
pub type NoiseRegistry = Registry<AnyNoise>;

/// The optional `floor` key of the ARMA entry.
fn floor_spec() -> ParamSpec {
    real(
        "floor",
        "flat floor ρ added to the shape, |H|² + ρ (estimated through ln ρ); absent: no floor",
        "",
        "> 0, finite",
        None,
    )
}

impl Builtin for AnyNoise {
    /// The noise models of this crate.
    ///
    /// ```
    /// use jitterid_estimate::{NoiseModel, NoiseRegistry};
    ///
    /// let table = serde_json::json!({ "noise": "arma", "c": [0.5], "d": [-0.3] });
    /// let noise = NoiseRegistry::builtin().build(table.as_object().unwrap())?;
    /// assert_eq!(noise.param_names(), ["c1", "d1"]);
    /// let bad = serde_json::json!({ "noise": "arma", "c": [2.0] });
    /// let err = NoiseRegistry::builtin().build(bad.as_object().unwrap()).unwrap_err();
    /// assert_eq!(err.key(), Some("c"));
    /// # Ok::<(), jitterid_estimate::RegistryError>(())
    /// ```
    fn builtin() -> Registry<Self> {
        let white = NoiseEntry::new(
            "white",
            "white measurement noise, |H| ≡ 1 (OE and JOE structures)",
            Vec::new(),
            |_| Ok(AnyNoise::new(WhiteNoise)),
        );
        let arma = NoiseEntry::new(
            "arma",
            "ARMA shape H = C(z)/D(z), monic, roots inside the unit circle (BJ and JBJ)",
            vec![
                real(
                    "c",
                    "MA coefficients c₁…c_q of C(z) = 1 + c₁z⁻¹ + …",
                    "",
                    "a list; roots of C inside the unit circle",
                    None,
                ),
                real(
                    "d",
                    "AR coefficients d₁…d_p of D(z) = 1 + d₁z⁻¹ + …",
                    "",
                    "a list; roots of D inside the unit circle",
                    None,
                ),
                floor_spec(),
            ],
            |t| {
                let c = numbers(t, "c")?;
                let d = numbers(t, "d")?;
                // Each polynomial checked alone, so that the error names its key.
                ArmaNoise::new(c.clone(), Vec::new()).map_err(|e| RegistryError::bad("c", e))?;
                let arma = ArmaNoise::new(c, d).map_err(|e| RegistryError::bad("d", e))?;
                if t.contains_key("floor") {
                    let floor = number(t, &floor_spec(), "arma")?;
                    let with =
                        WithFloor::new(arma, floor).map_err(|e| RegistryError::bad("floor", e))?;
                    Ok(AnyNoise::new(with))
                } else {
                    Ok(AnyNoise::new(arma))
                }
            },
        );
        let mut r = Registry::empty(NOISE_KEY, "noise model", Vec::new(), None);
        for e in [white, arma] {
            r.insert(e);
        }
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::registry::SpecTable;

    fn table(v: serde_json::Value) -> SpecTable {
        v.as_object().unwrap().clone()
    }

    #[test]
    fn any_noise_forwards_the_model() {
        let arma = ArmaNoise::new(vec![0.5], vec![-0.3]).unwrap();
        let any = AnyNoise::new(arma.clone());
        for f in [0.0, 0.1, 0.37] {
            assert_eq!(
                NoiseModel::shape(&any, f, 1.0),
                NoiseModel::shape(&arma, f, 1.0)
            );
        }
        let moved = any.with_params(&[0.2, 0.1]).unwrap();
        assert_eq!(NoiseModel::params(&moved), [0.2, 0.1]);
        assert!(any.with_params(&[2.0, 0.1]).is_err());
        assert!(NoiseModel::is_white(&AnyNoise::default()));
    }

    #[test]
    fn registry_errors_name_the_key() {
        let r = NoiseRegistry::builtin();
        let e = r
            .build(&table(serde_json::json!({ "noise": "pink" })))
            .unwrap_err();
        assert_eq!(e.key(), Some("noise"));
        let e = r
            .build(&table(serde_json::json!({ "noise": "white", "c": [0.1] })))
            .unwrap_err();
        assert_eq!(e.key(), Some("c"));
        let e = r
            .build(&table(
                serde_json::json!({ "noise": "arma", "c": [0.1], "d": [1.5] }),
            ))
            .unwrap_err();
        assert_eq!(e.key(), Some("d"));
        let e = r
            .build(&table(
                serde_json::json!({ "noise": "arma", "d": [0.1], "floor": -1.0 }),
            ))
            .unwrap_err();
        assert_eq!(e.key(), Some("floor"));
        let n = r
            .build(&table(
                serde_json::json!({ "noise": "arma", "d": [0.1], "floor": 0.5 }),
            ))
            .unwrap();
        assert_eq!(NoiseModel::param_names(&n), ["d1", "log_floor"]);
    }
}
