//! The parameter vector of the likelihood criteria: the structure's free parameters (signal,
//! jitter, noise shape) followed by the measurement-noise level `σ_v` when it is estimated
//! (`structure.noise_std` is `None`).

use super::MlError;
use jitterid_estimate::solver::Transform;
use jitterid_estimate::ModelStructure;
use jitterid_estimate::NoiseModel;
use jitterid_jitter::JitterModel;
use jitterid_signal::Signal;

/// Name of the measurement-noise level in parameter lists.
pub const NOISE_STD_NAME: &str = "noise.std";

/// Sizes of the blocks of the likelihood's parameter vector.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Layout {
    /// Signal parameters.
    pub ns: usize,
    /// Jitter parameters.
    pub nj: usize,
    /// Noise-shape parameters.
    pub nn: usize,
    /// Whether `σ_v` is the last parameter.
    pub sigma: bool,
}

impl Layout {
    pub(crate) fn of<S: Signal + Clone, J: JitterModel + Clone, N: NoiseModel>(
        structure: &ModelStructure<S, J, N>,
    ) -> Self {
        let (ns, nj, nn) = structure.blocks();
        Layout {
            ns,
            nj,
            nn,
            sigma: structure.noise_std.is_none(),
        }
    }

    pub(crate) fn len(&self) -> usize {
        self.ns + self.nj + self.nn + usize::from(self.sigma)
    }

    /// Index of `σ_v`, if estimated.
    pub(crate) fn sigma_index(&self) -> Option<usize> {
        self.sigma.then_some(self.ns + self.nj + self.nn)
    }

    pub(crate) fn jitter_range(&self) -> std::ops::Range<usize> {
        self.ns..self.ns + self.nj
    }

    pub(crate) fn noise_range(&self) -> std::ops::Range<usize> {
        self.ns + self.nj..self.ns + self.nj + self.nn
    }
}

/// Names of the likelihood's parameters: the structure's, then [`NOISE_STD_NAME`] when `σ_v`
/// is estimated.
pub fn likelihood_param_names<S: Signal + Clone, J: JitterModel + Clone, N: NoiseModel>(
    structure: &ModelStructure<S, J, N>,
) -> Vec<String> {
    let mut names = structure.param_names();
    if structure.noise_std.is_none() {
        names.push(NOISE_STD_NAME.to_string());
    }
    names
}

/// The likelihood's parameter vector at `structure` with noise level `noise_std` (used only
/// when `σ_v` is estimated).
pub fn likelihood_params<S: Signal + Clone, J: JitterModel + Clone, N: NoiseModel>(
    structure: &ModelStructure<S, J, N>,
    noise_std: f64,
) -> Vec<f64> {
    let mut p = structure.params();
    if structure.noise_std.is_none() {
        p.push(noise_std);
    }
    p
}

/// The structure and noise level at parameter vector `theta`.
pub(crate) fn split<S: Signal + Clone, J: JitterModel + Clone, N: NoiseModel>(
    structure: &ModelStructure<S, J, N>,
    theta: &[f64],
) -> Result<(ModelStructure<S, J, N>, f64), MlError> {
    let layout = Layout::of(structure);
    if theta.len() != layout.len() {
        return Err(jitterid_estimate::EstimateError::WrongParamCount {
            expected: layout.len(),
            got: theta.len(),
        }
        .into());
    }
    let k = layout.ns + layout.nj + layout.nn;
    let model = structure.with_params(&theta[..k])?;
    let sigma = match structure.noise_std {
        Some(s) => s,
        None => theta[k],
    };
    if !(sigma.is_finite() && sigma >= 0.0) {
        return Err(jitterid_estimate::EstimateError::BadNoiseStd { value: sigma }.into());
    }
    Ok((model, sigma))
}

/// Default constraints: `Positive` for `σ_v` and for every jitter parameter that is positive
/// at the start and whose family rejects zero (a half-width, a standard deviation); `Free`
/// otherwise (signal and noise-shape parameters are validated by their constructors, and an
/// invalid trial point is rejected by the solver).
pub fn default_transforms<S: Signal + Clone, J: JitterModel + Clone, N: NoiseModel>(
    structure: &ModelStructure<S, J, N>,
) -> Vec<Transform> {
    let layout = Layout::of(structure);
    let mut t = vec![Transform::Free; layout.len()];
    if layout.nj > 0 {
        let theta = structure.jitter.params();
        for (j, &v) in theta.iter().enumerate() {
            let mut zero = theta.clone();
            zero[j] = 0.0;
            if v > 0.0 && structure.jitter.with_params(&zero).is_err() {
                t[layout.ns + j] = Transform::Positive;
            }
        }
    }
    if let Some(i) = layout.sigma_index() {
        t[i] = Transform::Positive;
    }
    t
}
