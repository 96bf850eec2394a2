//! The prior draws of a robust design: the experiment's truth moved by the prior's spread
//! (`[design] prior_spread`, `prior_jitter_spread`), one experiment per draw.
//!
//! A design is chosen before the plant is known exactly; a robust design minimises the
//! criterion averaged over these draws instead of its value at the prior's point. Every
//! candidate design sees the same draws (common random numbers), so the search compares
//! designs, not draws.

use super::realization::realized_signal;
use crate::error::StudyResult;
use crate::experiment::{Experiment, PriorSpread};
use crate::study_err;
use jitterid::jitter::{AnyJitter, JitterModel};
use jitterid::rand::rngs::StdRng;
use jitterid::rand::{Rng, SeedableRng};
use jitterid::signal::registry::SpecTable;
use jitterid::signal::Signal;
use rand_distr::StandardNormal;

/// Where a draw is cut: three spreads, so that with a spread below 1/3 every draw keeps its
/// sign (a pole stays in its half-plane, a width stays positive).
const CUT: f64 = 3.0;

/// `1 + spread z`, `z` standard normal cut at ±[`CUT`].
fn factor(spread: f64, rng: &mut StdRng) -> f64 {
    let z: f64 = rng.sample(StandardNormal);
    1.0 + spread * z.clamp(-CUT, CUT)
}

/// One prior draw: the moved system (its spec table) and the moved jitter, each `None` where
/// the prior leaves it at the truth. A draw moves the truth alone, so the same draws serve
/// every candidate design ([`PriorDraw::apply`]).
#[derive(Debug, Clone)]
pub(crate) struct PriorDraw {
    system: Option<SpecTable>,
    jitter: Option<AnyJitter>,
}

impl PriorDraw {
    /// The same draw with the jitter left at the truth (for a prior without jitter).
    pub(crate) fn without_jitter(&self) -> PriorDraw {
        PriorDraw {
            system: self.system.clone(),
            jitter: None,
        }
    }

    /// `exp` (any design of the plan's experiment) with this draw's truth.
    pub(crate) fn apply(&self, exp: &Experiment) -> Experiment {
        let mut out = exp.clone();
        if let Some(kind) = &self.system {
            out.system.kind = kind.clone();
        }
        if let Some(j) = &self.jitter {
            out.jitter.truth = j.clone();
            out.jitter.model = j.clone();
        }
        out
    }
}

/// The `prior.draws` draws of the robust design of `exp` (its truth moved by the prior's
/// spread), drawn from master seed `seed`.
///
/// # Errors
///
/// A draw that makes the model invalid (a parameter out of its range, an unstable pole): one
/// line naming `[design] prior_spread` or `prior_jitter_spread` and the draw.
pub(crate) fn prior_draws(
    exp: &Experiment,
    prior: &PriorSpread,
    seed: u64,
) -> StudyResult<Vec<PriorDraw>> {
    // The system's parameters do not depend on the input: any realisation shows them.
    let signal = realized_signal(exp, &mut StdRng::seed_from_u64(seed))?;
    let sigma = exp.jitter.truth.std_dev();
    (0..prior.draws)
        .map(|i| {
            // A stream of its own per draw, apart from the input draws' streams.
            let mut rng = StdRng::seed_from_u64(seed ^ 0x5052_494f_525f_4452 ^ i as u64);
            let mut draw = PriorDraw {
                system: None,
                jitter: None,
            };
            if prior.system > 0.0 && exp.system.estimate {
                let moved: Vec<f64> = signal
                    .params()
                    .iter()
                    .map(|&p| p * factor(prior.system, &mut rng))
                    .collect();
                let moved = signal.with_params(&moved).map_err(|e| {
                    study_err!(
                        "{}: [design] prior_spread: prior draw {i} makes the system invalid: {e}",
                        exp.file
                    )
                })?;
                draw.system = Some(moved.spec());
            }
            if prior.jitter > 0.0 && sigma > 0.0 {
                let truth = &exp.jitter.truth;
                let moved = exp
                    .registries
                    .jitter
                    .from_std_dev(
                        truth.family(),
                        sigma * factor(prior.jitter, &mut rng),
                        &truth.spec(),
                    )
                    .map_err(|e| {
                        study_err!(
                            "{}: [design] prior_jitter_spread: prior draw {i} makes the jitter invalid: {e}",
                            exp.file
                        )
                    })?;
                draw.jitter = Some(moved);
            }
            Ok(draw)
        })
        .collect()
}

/// The `prior.draws` experiments of the robust design of `exp`: its truth moved by the prior's
/// spread, drawn from master seed `seed` (each estimated system parameter `θ(1 + s z)`, the
/// jitter's σ `σ(1 + s_τ z)`, `z` standard normal cut at ±3).
///
/// # Errors
///
/// A draw that makes the model invalid: one line naming `[design] prior_spread` or
/// `prior_jitter_spread` and the draw.
pub fn prior_experiments(
    exp: &Experiment,
    prior: &PriorSpread,
    seed: u64,
) -> StudyResult<Vec<Experiment>> {
    Ok(prior_draws(exp, prior, seed)?
        .iter()
        .map(|d| d.apply(exp))
        .collect())
}
