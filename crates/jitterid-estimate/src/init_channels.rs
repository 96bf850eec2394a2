//! Initial values for a system with several inputs, `y = Σᵢ Gᵢ uᵢ`: the single-input
//! initializer ([`fit_rational`]) of each channel on the record less the other channels'
//! current responses, channel after channel, until the responses stop changing
//! (backfitting, a Gauss–Seidel iteration on the channels).
//!
//! Why backfitting and not one joint linear fit: the channels have their own denominators, so
//! a joint equation-error fit needs the common denominator `Π Aᵢ` and a partial-fraction split
//! afterwards, which is ill conditioned where two channels have nearby poles. Each channel's
//! own fit is the tested single-input initializer, and the channels' inputs are independent
//! signals, so the other channels' responses left in a channel's record at the first sweep act
//! as noise that the next sweeps remove: each sweep shrinks the error by the inputs' cross
//! coherence in the fitted band.

use crate::data::Record;
use crate::init::{fit_rational, InitError, InitOptions, RationalFit};
use jitterid_jitter::{JitterModel, NoJitter};
use jitterid_signal::{Input, LtiResponse, Signal, TransferFunction};

/// Most sweeps over the channels.
pub const MAX_SWEEPS: usize = 20;

/// The sweeps stop when no channel's expected samples change by more than this fraction of
/// the record's RMS: far below the accuracy of a start (a few per cent, see
/// the initializer's module docs), so the last sweep changes nothing a fit would notice.
const SETTLED: f64 = 1e-6;

/// One channel of [`fit_channels`]: the input as the channel's system sees it (delayed by its
/// delay), its numbers of zeros and of poles.
#[derive(Debug, Clone, Copy)]
pub struct ChannelOrder<'a> {
    /// The input driving the channel.
    pub input: &'a Input,
    /// Number of zeros.
    pub zeros: usize,
    /// Number of poles.
    pub poles: usize,
}

/// One rational fit per channel of `y = Σᵢ Gᵢ uᵢ` from `record` (see the module docs), with
/// the samples' mean damped by `jitter` when given and `options` as for one input (with
/// [`InitOptions::offset`] every channel leaves out the bin `f = 0`).
///
/// # Errors
///
/// Those of [`fit_rational`] for any channel, and [`InitError::NonFinite`] when the record
/// less the other channels' responses is not finite.
pub fn fit_channels(
    record: &Record,
    channels: &[ChannelOrder<'_>],
    jitter: Option<&dyn JitterModel>,
    options: &InitOptions,
) -> Result<Vec<RationalFit>, InitError> {
    let grid = record.grid();
    let y = record.y();
    let scale = (y.iter().map(|v| v * v).sum::<f64>() / y.len().max(1) as f64).sqrt();
    let mean_of: &dyn JitterModel = jitter.unwrap_or(&NoJitter);
    // The channels' expected samples `m_k` under the jitter, all zero before the first sweep.
    let mut responses = vec![vec![0.0; y.len()]; channels.len()];
    let mut fits: Vec<Option<RationalFit>> = vec![None; channels.len()];
    for _ in 0..MAX_SWEEPS {
        let mut change = 0.0f64;
        for (i, c) in channels.iter().enumerate() {
            let rest: Vec<f64> = (0..y.len())
                .map(|k| {
                    let others: f64 = (0..channels.len())
                        .filter(|&j| j != i)
                        .map(|j| responses[j][k])
                        .sum();
                    y[k] - others
                })
                .collect();
            let own =
                Record::new(*grid, rest).map_err(|_| InitError::NonFinite { frequency: 0.0 })?;
            let fit = fit_rational(&own, c.input, jitter, c.zeros, c.poles, options)?;
            let model = TransferFunction::new(&fit.num, &fit.den)?;
            let m = LtiResponse::new(model, c.input.clone()).expected_values(grid, mean_of);
            let moved = m
                .iter()
                .zip(&responses[i])
                .map(|(a, b)| (a - b).powi(2))
                .sum::<f64>()
                / y.len().max(1) as f64;
            change = change.max(moved.sqrt());
            responses[i] = m;
            fits[i] = Some(fit);
        }
        if !(change > SETTLED * scale) {
            break;
        }
    }
    // Every channel was fitted at least once (the loop runs at least one sweep).
    Ok(fits.into_iter().flatten().collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use jitterid_jitter::UniformSum;
    use jitterid_signal::{simulate, RandomBinary, SampleGrid};
    use rand::SeedableRng;

    /// Two channels of different dynamics on one seeded record: each channel's start is close
    /// to its truth, though the other channel's response is five times the noise.
    #[test]
    fn two_channels_are_separated() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(11);
        let u1: Input = RandomBinary::new(6.0, 0.0, 1.0)
            .unwrap()
            .generate(0.0, 401.0, &mut rng)
            .unwrap()
            .into();
        let u2: Input = RandomBinary::new(10.0, -1.0, 1.0)
            .unwrap()
            .generate(0.0, 401.0, &mut rng)
            .unwrap()
            .into();
        let g1 = TransferFunction::new(&[0.5], &[1.0, 0.5]).unwrap();
        let g2 = TransferFunction::new(&[0.2, 0.1], &[1.0, 0.5, 0.1525]).unwrap();
        let jitter = UniformSum::new(2, 0.5 / 3f64.sqrt()).unwrap();
        let grid = SampleGrid::new(0.0, 1.0, 400).unwrap();
        let d1 = simulate(
            &LtiResponse::new(g1, u1.clone()),
            &jitter,
            &grid,
            0.0,
            &mut rng,
        )
        .unwrap();
        let d2 = simulate(
            &LtiResponse::new(g2, u2.clone()),
            &jitter,
            &grid,
            0.01,
            &mut rng,
        )
        .unwrap();
        let y: Vec<f64> = d1.y.iter().zip(&d2.y).map(|(a, b)| a + b).collect();
        let record = Record::new(grid, y).unwrap();
        let channels = [
            ChannelOrder {
                input: &u1,
                zeros: 0,
                poles: 1,
            },
            ChannelOrder {
                input: &u2,
                zeros: 1,
                poles: 2,
            },
        ];
        let fits =
            fit_channels(&record, &channels, Some(&jitter), &InitOptions::default()).unwrap();
        assert_eq!(fits.len(), 2);
        // A start is accurate to a few per cent (module docs of `init`): 10 % of each
        // coefficient, the tolerance the single-input initializer's tests hold.
        let close = |got: &[f64], want: &[f64]| {
            got.iter()
                .zip(want)
                .all(|(g, w)| (g - w).abs() <= 0.1 * w.abs().max(0.1))
        };
        assert!(close(&fits[0].num, &[0.5]), "{:?}", fits[0]);
        assert!(close(&fits[0].den, &[1.0, 0.5]), "{:?}", fits[0]);
        assert!(close(&fits[1].num, &[0.2, 0.1]), "{:?}", fits[1]);
        assert!(close(&fits[1].den, &[1.0, 0.5, 0.1525]), "{:?}", fits[1]);
    }
}
