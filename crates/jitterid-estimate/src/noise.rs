//! Noise models for the Box–Jenkins structures: the shape `|H(f)|²` of the measurement noise's
//! spectrum (its level is estimated separately).

use crate::EstimateError;
use jitterid_signal::poly;
use num_complex::Complex64;
use std::fmt;

/// The spectral shape of the measurement noise `v_k = H(q) e_k`: `Φ_v(f) = σ² |H(f)|²`.
pub trait NoiseModel: fmt::Debug + Clone + Send + Sync {
    /// Names of the shape parameters.
    fn param_names(&self) -> Vec<String>;
    /// The shape parameters.
    fn params(&self) -> Vec<f64>;
    /// The same model with new parameters, validated.
    fn with_params(&self, params: &[f64]) -> Result<Self, EstimateError>;
    /// `|H(f)|²` for sampling interval `interval`.
    fn shape(&self, f: f64, interval: f64) -> f64;
    /// Whether the noise is white (`|H| ≡ 1`).
    fn is_white(&self) -> bool {
        false
    }
    /// The flat floor `ρ` that [`shape`](Self::shape) includes for the jitter's own noise
    /// (`0` for a model without one): `shape − floor` is the measurement noise's shape alone.
    fn floor(&self) -> f64 {
        0.0
    }
}

/// White measurement noise: `|H| ≡ 1`, no shape parameter.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WhiteNoise;

impl NoiseModel for WhiteNoise {
    fn param_names(&self) -> Vec<String> {
        Vec::new()
    }
    fn params(&self) -> Vec<f64> {
        Vec::new()
    }
    fn with_params(&self, params: &[f64]) -> Result<Self, EstimateError> {
        if params.is_empty() {
            Ok(WhiteNoise)
        } else {
            Err(EstimateError::WrongParamCount {
                expected: 0,
                got: params.len(),
            })
        }
    }
    fn shape(&self, _: f64, _: f64) -> f64 {
        1.0
    }
    fn is_white(&self) -> bool {
        true
    }
}

/// Discrete-time ARMA noise `H(z) = C(z)/D(z)` with monic
/// `C(z) = 1 + c_1 z^{-1} + … + c_q z^{-q}` and `D(z) = 1 + d_1 z^{-1} + … + d_p z^{-p}`, both
/// with all roots inside the unit circle (stable and minimum phase, so `H` is identifiable).
///
/// Parameters: `c_1..c_q`, then `d_1..d_p`.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ArmaNoise {
    c: Vec<f64>,
    d: Vec<f64>,
}

fn check_inside_unit_circle(name: &str, coefs: &[f64]) -> Result<(), EstimateError> {
    let mut p = vec![1.0];
    p.extend_from_slice(coefs);
    if let Some(i) = coefs.iter().position(|c| !c.is_finite()) {
        return Err(EstimateError::Noise(format!(
            "{name}[{}] is not finite ({})",
            i + 1,
            coefs[i]
        )));
    }
    let roots = poly::roots(&p).ok_or_else(|| EstimateError::Noise(format!("roots of {name}")))?;
    if let Some(r) = roots.iter().find(|r| r.norm() >= 1.0) {
        return Err(EstimateError::Noise(format!(
            "{name} has a root {r} on or outside the unit circle"
        )));
    }
    Ok(())
}

impl ArmaNoise {
    /// `c` (MA) and `d` (AR) coefficients without their leading 1.
    pub fn new(c: Vec<f64>, d: Vec<f64>) -> Result<Self, EstimateError> {
        check_inside_unit_circle("c", &c)?;
        check_inside_unit_circle("d", &d)?;
        Ok(Self { c, d })
    }

    fn eval(coefs: &[f64], z_inv: Complex64) -> Complex64 {
        // 1 + Σ c_i z^{-i} by Horner in z^{-1}.
        let mut acc = Complex64::new(0.0, 0.0);
        for &c in coefs.iter().rev() {
            acc = (acc + c) * z_inv;
        }
        acc + 1.0
    }
}

impl NoiseModel for ArmaNoise {
    fn param_names(&self) -> Vec<String> {
        (1..=self.c.len())
            .map(|i| format!("c{i}"))
            .chain((1..=self.d.len()).map(|i| format!("d{i}")))
            .collect()
    }
    fn params(&self) -> Vec<f64> {
        self.c.iter().chain(&self.d).copied().collect()
    }
    fn with_params(&self, params: &[f64]) -> Result<Self, EstimateError> {
        let n = self.c.len() + self.d.len();
        if params.len() != n {
            return Err(EstimateError::WrongParamCount {
                expected: n,
                got: params.len(),
            });
        }
        Self::new(
            params[..self.c.len()].to_vec(),
            params[self.c.len()..].to_vec(),
        )
    }
    fn shape(&self, f: f64, interval: f64) -> f64 {
        let z_inv = Complex64::from_polar(1.0, -std::f64::consts::TAU * f * interval);
        (Self::eval(&self.c, z_inv) / Self::eval(&self.d, z_inv)).norm_sqr()
    }
}

/// A noise shape plus a flat floor: `|H(f)|² + ρ`, `ρ > 0` estimated with the shape through its
/// logarithm (the parameter is `log_floor = ln ρ`, so every parameter vector is valid).
///
/// Jittered samples carry their own noise, `E[s(t_k+τ)²] − m_k²`, which is independent from
/// sample to sample and so has a flat spectrum (`docs/method.md`: `Var Y(f) = Σ_k λ_k` at every
/// `f`). The residual spectrum of a Box–Jenkins fit to jittered data is therefore
/// `σ_e²|H(f)|² + λ̄ = σ_e² (|H(f)|² + ρ)`; without the floor the noise model absorbs it and its
/// parameters are biased towards white noise. With it, `σ_e²` still concentrates out of the
/// likelihood exactly.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WithFloor<N> {
    inner: N,
    floor: f64,
    /// A known floor: not a parameter (see [`WithFloor::known`]).
    #[serde(default)]
    known: bool,
}

impl<N: NoiseModel> WithFloor<N> {
    /// `floor > 0`, finite.
    pub fn new(inner: N, floor: f64) -> Result<Self, EstimateError> {
        if !(floor.is_finite() && floor > 0.0) {
            return Err(EstimateError::Noise(format!(
                "floor must be finite and > 0, got {floor}"
            )));
        }
        Ok(Self {
            inner,
            floor,
            known: false,
        })
    }

    /// A floor `ρ` set from outside and not estimated with the shape: the parameters are the
    /// shape's alone. The jitter's floor is known from the jitter model up to the noise level
    /// (`ρ = λ̄ / σ_e²`), so a fit updates it between rounds instead of searching for it
    /// ([`ModelStructure::fit_with_jitter_floor`](crate::ModelStructure::fit_with_jitter_floor)).
    ///
    /// # Errors
    ///
    /// [`EstimateError::Noise`] unless `floor` is finite and `> 0`.
    pub fn known(inner: N, floor: f64) -> Result<Self, EstimateError> {
        let mut with = Self::new(inner, floor)?;
        with.known = true;
        Ok(with)
    }

    /// The floor `ρ`.
    pub fn floor(&self) -> f64 {
        self.floor
    }
}

impl<N: NoiseModel> NoiseModel for WithFloor<N> {
    fn param_names(&self) -> Vec<String> {
        let mut n = self.inner.param_names();
        if !self.known {
            n.push("log_floor".into());
        }
        n
    }
    fn params(&self) -> Vec<f64> {
        let mut p = self.inner.params();
        if !self.known {
            p.push(self.floor.ln());
        }
        p
    }
    fn with_params(&self, params: &[f64]) -> Result<Self, EstimateError> {
        if self.known {
            return Self::known(self.inner.with_params(params)?, self.floor);
        }
        let Some((&log_floor, inner)) = params.split_last() else {
            return Err(EstimateError::WrongParamCount {
                expected: self.inner.params().len() + 1,
                got: 0,
            });
        };
        Self::new(self.inner.with_params(inner)?, log_floor.exp())
    }
    fn shape(&self, f: f64, interval: f64) -> f64 {
        self.inner.shape(f, interval) + self.floor
    }
    fn floor(&self) -> f64 {
        self.floor
    }
}
