//! Model structures (the paper's eq. 2): a signal, a jitter model and a noise model, each fixed
//! or estimated.

use crate::noise::{NoiseModel, WhiteNoise};
use crate::EstimateError;
use jitterid_jitter::JitterModel;
use jitterid_signal::Signal;

/// A composition of a [`Signal`], a [`JitterModel`] and a [`NoiseModel`], each part known or
/// estimated.
///
/// | structure | signal | noise | jitter |
/// |---|---|---|---|
/// | [`oe`](Self::oe) | estimated | white | known |
/// | [`bj`](Self::bj) | estimated | estimated | known |
/// | [`joe`](Self::joe) | estimated | white | estimated |
/// | [`jbj`](Self::jbj) | estimated | estimated | estimated |
///
/// Any part may also be fixed ([`with_estimated`](Self::with_estimated)), as in the paper's
/// section 4.1 where the system is known and only the jitter is estimated. The free parameter
/// vector is the signal's (if estimated), then the jitter's, then the noise shape's.
///
/// The measurement-noise level `σ_v` does not enter the first-moment criteria; it is either
/// known ([`with_noise_std`](Self::with_noise_std)) or estimated from the residuals after the
/// fit, for the covariance of the estimate.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ModelStructure<S, J, N = WhiteNoise> {
    /// The signal model `s(t; θ)`.
    pub signal: S,
    /// The jitter model `p(τ; θ)`.
    pub jitter: J,
    /// The noise shape `|H|²`.
    pub noise: N,
    /// Whether the signal's parameters are estimated.
    pub estimate_signal: bool,
    /// Whether the jitter's parameters are estimated.
    pub estimate_jitter: bool,
    /// Whether the noise shape's parameters are estimated.
    pub estimate_noise: bool,
    /// Known measurement-noise standard deviation, if any.
    pub noise_std: Option<f64>,
}

impl<S: Signal + Clone, J: JitterModel + Clone> ModelStructure<S, J, WhiteNoise> {
    /// Output error: signal estimated, jitter known, white noise.
    pub fn oe(signal: S, jitter: J) -> Self {
        Self::new(signal, jitter, WhiteNoise, true, false, false)
    }

    /// Jitter output error: signal and jitter estimated, white noise.
    pub fn joe(signal: S, jitter: J) -> Self {
        Self::new(signal, jitter, WhiteNoise, true, true, false)
    }
}

impl<S: Signal + Clone, J: JitterModel + Clone, N: NoiseModel> ModelStructure<S, J, N> {
    fn new(
        signal: S,
        jitter: J,
        noise: N,
        estimate_signal: bool,
        estimate_jitter: bool,
        estimate_noise: bool,
    ) -> Self {
        Self {
            signal,
            jitter,
            noise,
            estimate_signal,
            estimate_jitter,
            estimate_noise,
            noise_std: None,
        }
    }

    /// Box–Jenkins: signal and noise shape estimated, jitter known.
    pub fn bj(signal: S, jitter: J, noise: N) -> Self {
        Self::new(signal, jitter, noise, true, false, true)
    }

    /// Jitter Box–Jenkins: everything estimated.
    pub fn jbj(signal: S, jitter: J, noise: N) -> Self {
        Self::new(signal, jitter, noise, true, true, true)
    }

    /// Chooses which parts are estimated.
    pub fn with_estimated(mut self, signal: bool, jitter: bool, noise: bool) -> Self {
        self.estimate_signal = signal;
        self.estimate_jitter = jitter;
        self.estimate_noise = noise;
        self
    }

    /// Declares the measurement-noise standard deviation known.
    pub fn with_noise_std(mut self, std: f64) -> Result<Self, EstimateError> {
        if !(std.is_finite() && std >= 0.0) {
            return Err(EstimateError::BadNoiseStd { value: std });
        }
        self.noise_std = Some(std);
        Ok(self)
    }

    /// Sizes of the free blocks: (signal, jitter, noise).
    pub fn blocks(&self) -> (usize, usize, usize) {
        (
            if self.estimate_signal {
                self.signal.num_params()
            } else {
                0
            },
            if self.estimate_jitter {
                self.jitter.num_params()
            } else {
                0
            },
            if self.estimate_noise {
                self.noise.params().len()
            } else {
                0
            },
        )
    }

    /// Number of free parameters.
    pub fn num_params(&self) -> usize {
        let (a, b, c) = self.blocks();
        a + b + c
    }

    /// The free parameters, in order signal, jitter, noise.
    pub fn params(&self) -> Vec<f64> {
        let mut p = Vec::with_capacity(self.num_params());
        if self.estimate_signal {
            p.extend(self.signal.params());
        }
        if self.estimate_jitter {
            p.extend(self.jitter.params());
        }
        if self.estimate_noise {
            p.extend(self.noise.params());
        }
        p
    }

    /// Names of the free parameters (jitter and noise names prefixed `jitter.`/`noise.`).
    pub fn param_names(&self) -> Vec<String> {
        let mut n = Vec::with_capacity(self.num_params());
        if self.estimate_signal {
            n.extend(self.signal.param_names());
        }
        if self.estimate_jitter {
            n.extend(
                self.jitter
                    .param_names()
                    .iter()
                    .map(|s| format!("jitter.{s}")),
            );
        }
        if self.estimate_noise {
            n.extend(
                self.noise
                    .param_names()
                    .iter()
                    .map(|s| format!("noise.{s}")),
            );
        }
        n
    }

    /// The structure with new free parameters, each part validated by its own constructor.
    pub fn with_params(&self, params: &[f64]) -> Result<Self, EstimateError> {
        let (ns, nj, nn) = self.blocks();
        if params.len() != ns + nj + nn {
            return Err(EstimateError::WrongParamCount {
                expected: ns + nj + nn,
                got: params.len(),
            });
        }
        let mut out = self.clone();
        if self.estimate_signal {
            out.signal = self.signal.with_params(&params[..ns])?;
        }
        if self.estimate_jitter {
            out.jitter = self.jitter.with_params(&params[ns..ns + nj])?;
        }
        if self.estimate_noise {
            out.noise = self.noise.with_params(&params[ns + nj..])?;
        }
        Ok(out)
    }
}
