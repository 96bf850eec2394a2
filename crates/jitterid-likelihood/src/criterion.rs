//! The likelihood criteria as one trait, and the data they are evaluated on.

use super::cheb::PiecewiseCheb;
use super::exact::{
    signal_table, ExactMl, JitterPrep, RuleTooLarge, SampleModel, Scratch, SignalEval,
    MAX_SAMPLE_NODES, SCREEN_RESOLUTION, SCREEN_SHORTCUT_TOLERANCE, SCREEN_WINDOW,
};
use super::MlError;
use jitterid_estimate::support::reach_beyond;
use jitterid_estimate::ModelStructure;
use jitterid_estimate::NoiseModel;
use jitterid_estimate::Record;
use jitterid_jitter::JitterModel;
use jitterid_signal::{SampleGrid, Signal};
use rayon::prelude::*;
use std::fmt;

/// A likelihood criterion at one parameter value: the negative log-likelihood (or
/// quasi-log-likelihood), with its gradient in the signal's parameters and in `σ_v` when
/// requested. Gradients in the jitter's and the noise shape's parameters are central
/// differences of the value, taken by [`LikelihoodObjective`](super::LikelihoodObjective).
#[derive(Debug, Clone, PartialEq)]
pub struct Evaluation {
    /// `−log L` (including all constants: a proper negative log-density of the record).
    pub nll: f64,
    /// `∂(−log L)/∂θ_signal`, when requested.
    pub signal_gradient: Option<Vec<f64>>,
    /// `∂(−log L)/∂σ_v`, when requested.
    pub noise_std_gradient: Option<f64>,
}

/// What an evaluation should compute besides the value.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct GradientRequest {
    /// The gradient in the signal's parameters.
    pub signal: bool,
    /// The derivative in `σ_v`.
    pub noise_std: bool,
}

/// A record prepared for a likelihood criterion: the samples and, when the signal is fixed,
/// a table of it built once.
#[derive(Debug, Clone)]
pub struct LikelihoodData {
    pub(crate) record: Record,
    pub(crate) table: Option<PiecewiseCheb>,
}

impl LikelihoodData {
    /// The record.
    pub fn record(&self) -> &Record {
        &self.record
    }
}

/// A maximum-likelihood criterion: [`QuasiMl`](super::QuasiMl) (Gaussian, second moment) or
/// [`ExactMl`] (the exact per-sample likelihood).
pub trait LikelihoodCriterion: fmt::Debug + Send + Sync {
    /// Short name (`"quasi-ml"`, `"exact-ml"`).
    fn name(&self) -> &'static str;

    /// Whether coloured (Box–Jenkins) measurement noise is supported.
    fn supports_coloured_noise(&self) -> bool;

    /// Prepares `record` for evaluations at parameters of `structure`.
    fn prepare<S: Signal + Clone, J: JitterModel + Clone, N: NoiseModel>(
        &self,
        structure: &ModelStructure<S, J, N>,
        record: &Record,
    ) -> LikelihoodData {
        let _ = structure;
        LikelihoodData {
            record: record.clone(),
            table: None,
        }
    }

    /// A cheaper form of this criterion for screening: the loose first pass of
    /// [`fit_profile`](jitterid_estimate::fit_profile), which needs each value only to well within its cost
    /// tolerance. It is evaluated on the data [`prepare`](Self::prepare) made for `self`.
    /// `None` (the default): the criterion itself screens.
    fn screening(&self) -> Option<Self>
    where
        Self: Sized,
    {
        None
    }

    /// The criterion at `model` with measurement-noise level `noise_std`.
    ///
    /// # Errors
    ///
    /// Typed errors where the criterion is not defined (see [`MlError`]): the objective
    /// turns them into an infinite cost during a search, [`fit`](jitterid_estimate::fit)
    /// reports them at the start.
    fn evaluate<S: Signal + Clone, J: JitterModel + Clone, N: NoiseModel>(
        &self,
        data: &LikelihoodData,
        model: &ModelStructure<S, J, N>,
        noise_std: f64,
        gradient: GradientRequest,
    ) -> Result<Evaluation, MlError>;
}

/// Checks that the jitter's reach fits in a record on `grid` ([`reach_beyond`]).
pub(crate) fn check_reach<J: JitterModel + ?Sized>(
    jitter: &J,
    grid: &SampleGrid,
) -> Result<(), MlError> {
    match reach_beyond(jitter, grid) {
        Some((lo, hi, duration)) => Err(MlError::ReachExceedsRecord { lo, hi, duration }),
        None => Ok(()),
    }
}

impl LikelihoodCriterion for ExactMl {
    fn name(&self) -> &'static str {
        "exact-ml"
    }

    fn supports_coloured_noise(&self) -> bool {
        false
    }

    /// The same quadrature with sub-intervals of `8σ_v` (at least), a window of `6.5σ_v` (at
    /// most) and the shortcut taken where its interpolant is converged to `1e-8` (at least):
    /// about `1e-8` of every `p(y_k)` instead of `1e-13`, so
    /// `1e-8 N` of `−log L` (`2e-6` for 200 samples, next to the first pass's `1e-3`).
    fn screening(&self) -> Option<Self> {
        Some(ExactMl {
            resolution: self.resolution.max(SCREEN_RESOLUTION),
            window: self.window.min(SCREEN_WINDOW),
            shortcut_tolerance: self.shortcut_tolerance.max(SCREEN_SHORTCUT_TOLERANCE),
            ..*self
        })
    }

    fn prepare<S: Signal + Clone, J: JitterModel + Clone, N: NoiseModel>(
        &self,
        structure: &ModelStructure<S, J, N>,
        record: &Record,
    ) -> LikelihoodData {
        let table = (!structure.estimate_signal).then(|| {
            signal_table(
                &structure.signal,
                record.grid(),
                structure.jitter.reach(),
                false,
            )
        });
        LikelihoodData {
            record: record.clone(),
            table,
        }
    }

    fn evaluate<S: Signal + Clone, J: JitterModel + Clone, N: NoiseModel>(
        &self,
        data: &LikelihoodData,
        model: &ModelStructure<S, J, N>,
        noise_std: f64,
        gradient: GradientRequest,
    ) -> Result<Evaluation, MlError> {
        let per = self.per_sample(data, model, noise_std, gradient.signal, gradient.noise_std)?;
        let ns = model.signal.num_params();
        let mut nll = 0.0;
        let mut gs = vec![0.0; if gradient.signal { ns } else { 0 }];
        let mut gsig = 0.0;
        for (lp, g) in &per {
            nll -= lp;
            if let Some(g) = g {
                for (a, b) in gs.iter_mut().zip(g) {
                    *a -= b;
                }
                gsig -= g[g.len() - 1];
            }
        }
        Ok(Evaluation {
            nll,
            signal_gradient: gradient.signal.then_some(gs),
            noise_std_gradient: gradient.noise_std.then_some(gsig),
        })
    }
}

impl ExactMl {
    /// `log p(y_k)` of every sample, with (when asked) the per-sample gradient
    /// `[∂/∂θ_signal…, ∂/∂σ_v]`.
    pub(crate) fn per_sample<S: Signal + Clone, J: JitterModel + Clone, N: NoiseModel>(
        &self,
        data: &LikelihoodData,
        model: &ModelStructure<S, J, N>,
        noise_std: f64,
        signal_grad: bool,
        sigma_grad: bool,
    ) -> Result<Vec<(f64, Option<Vec<f64>>)>, MlError> {
        self.validate()?;
        if !model.noise.is_white() {
            return Err(MlError::ColouredNoise {
                criterion: "exact-ml",
            });
        }
        let sigma = model.noise_std.unwrap_or(noise_std);
        if !(sigma.is_finite() && sigma > 0.0) {
            return Err(MlError::NoNoise { value: sigma });
        }
        let record = &data.record;
        check_reach(&model.jitter, record.grid())?;
        let grid = record.grid();
        let rate = model.signal.rate();
        let prep = JitterPrep::new(&model.jitter, rate);
        let own;
        let ns = model.signal.num_params();
        let (table, channels) = match (&data.table, signal_grad) {
            (Some(t), false) => (t, 0),
            _ => {
                own = signal_table(&model.signal, grid, model.jitter.reach(), signal_grad);
                (&own, if signal_grad { ns } else { 0 })
            }
        };
        let breaks = {
            let mut b = model.signal.breakpoints();
            b.sort_by(f64::total_cmp);
            b
        };
        let sm = SampleModel {
            opts: *self,
            signal: SignalEval {
                signal: &model.signal,
                table,
                grad_channels: channels,
            },
            jitter: &prep,
            breaks: &breaks,
            sigma,
        };
        let want = signal_grad || sigma_grad;
        let glen = channels + 1;
        // Taken along to the worker threads: a spent budget leaves the remaining samples' log
        // densities NaN (unfinished), which the fit's budget then reports.
        let budget = jitterid_numeric::budget::current();
        let one = |scratch: &mut Scratch, k: usize| {
            if budget.as_ref().is_some_and(|b| b.is_spent()) {
                return Ok((f64::NAN, want.then(|| vec![f64::NAN; glen])));
            }
            let y = record.y()[k];
            let too_large = |_: RuleTooLarge| MlError::QuadratureTooLarge {
                limit: MAX_SAMPLE_NODES,
                noise_std: sigma,
            };
            if want {
                let mut g = vec![0.0; glen];
                let lp = sm
                    .log_p(grid.time(k), y, Some(&mut g), scratch)
                    .map_err(too_large)?;
                Ok((lp, Some(g)))
            } else {
                let lp = sm
                    .log_p(grid.time(k), y, None, scratch)
                    .map_err(too_large)?;
                Ok((lp, None))
            }
        };
        let n = grid.len();
        // Collected as a `Result`: the first over-large rule stops the other samples' work.
        let out: Vec<(f64, Option<Vec<f64>>)> = if self.parallel && n >= 64 {
            (0..n)
                .into_par_iter()
                .with_min_len(16)
                .map_init(Scratch::default, one)
                .collect::<Result<_, MlError>>()?
        } else {
            let mut scratch = Scratch::default();
            (0..n)
                .map(|k| one(&mut scratch, k))
                .collect::<Result<_, MlError>>()?
        };
        if let Some((index, (lp, _))) = out.iter().enumerate().find(|(_, (lp, _))| !lp.is_finite())
        {
            return Err(MlError::LikelihoodUnderflow {
                index,
                y: record.y()[index],
                log_p: *lp,
            });
        }
        if let Some((index, v)) = out.iter().enumerate().find_map(|(k, (_, g))| {
            g.as_ref()
                .and_then(|g| g.iter().find(|v| !v.is_finite()).map(|v| (k, *v)))
        }) {
            return Err(MlError::NonFinite {
                what: "likelihood gradient of sample",
                index,
                value: v,
            });
        }
        Ok(out)
    }

    /// `log p(y_k)` of every sample of `record` under `structure` with measurement-noise
    /// level `noise_std` (used when the structure does not fix it).
    ///
    /// # Errors
    ///
    /// Coloured noise, `σ_v = 0`, a reach wider than the record, a sample whose likelihood
    /// underflows (see [`MlError`]).
    pub fn log_likelihoods<S: Signal + Clone, J: JitterModel + Clone, N: NoiseModel>(
        &self,
        structure: &ModelStructure<S, J, N>,
        record: &Record,
        noise_std: f64,
    ) -> Result<Vec<f64>, MlError> {
        let data = LikelihoodData {
            record: record.clone(),
            table: None,
        };
        Ok(self
            .per_sample(&data, structure, noise_std, false, false)?
            .into_iter()
            .map(|(lp, _)| lp)
            .collect())
    }
}
