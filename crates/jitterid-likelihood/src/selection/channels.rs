//! Selection for a system with several inputs: every combination of one order per input
//! ([`ChannelOrders`]) × jitter family, each candidate the superposition of one
//! transfer function per input, started by the multi-input initializer
//! ([`fit_channels`]) and fitted jointly; screened and ranked exactly as one input's
//! candidates are ([`super::select`]).

use super::{
    bcls_from, check_fractions, fit_candidate, init_options, invalid, jitter_at, rank, with_offset,
    Candidate, ChannelOrders, Label, SelectionError, SelectionGrid, SelectionOptions, Structure,
    MAX_CANDIDATES,
};
use jitterid_estimate::{fit_channels, ChannelOrder, Record};
use jitterid_jitter::registry::JitterRegistry;
use jitterid_signal::registry::{SignalRegistry, SpecTable};
use jitterid_signal::superposition::{build, spec_table};
use jitterid_signal::{AnySignal, Input};
use rayon::prelude::*;
use serde_json::json;

/// One multi-input candidate before its fit: its `(poles, zeros)` per input and its family.
type Combination = (Vec<(usize, usize)>, String);

impl SelectionGrid {
    /// The combinations of a multi-input grid, one order of `channels` per input in input
    /// order, for each of the grid's families; rejecting bad input by key: an input without orders, an order without poles or
    /// with more zeros than poles (`orders`), an unknown family, more parameters than the
    /// record of `len` samples supports (`orders`), more than [`MAX_CANDIDATES`].
    ///
    /// # Errors
    ///
    /// [`SelectionError::InvalidKey`] naming `orders` or `families`;
    /// [`SelectionError::TooManyCandidates`].
    pub fn channel_candidates(
        &self,
        channels: &[ChannelOrders],
        registry: &JitterRegistry,
        len: usize,
    ) -> Result<Vec<Combination>, SelectionError> {
        if channels.is_empty() {
            return Err(invalid("orders", "no input has candidate orders"));
        }
        for c in channels {
            if c.orders.is_empty() {
                return Err(invalid(
                    "orders",
                    format!("input `{}`: the list is empty", c.input),
                ));
            }
            if let Some((p, z)) = c.orders.iter().find(|(p, z)| *p == 0 || z > p) {
                return Err(invalid(
                    "orders",
                    format!(
                        "input `{}`: [{p}, {z}] must be [poles, zeros] with 1 ≤ poles and zeros ≤ poles",
                        c.input
                    ),
                ));
            }
        }
        self.check_families(registry)?;
        let count = channels
            .iter()
            .map(|c| c.orders.len())
            .try_fold(self.families.len(), usize::checked_mul)
            .unwrap_or(usize::MAX);
        if count > MAX_CANDIDATES {
            return Err(SelectionError::TooManyCandidates { candidates: count });
        }
        // Each channel's linear fit needs 2n + m + 1 real equations from bins below N/2.
        for c in channels {
            let needed = c
                .orders
                .iter()
                .map(|(p, z)| 2 * p + z + 2)
                .max()
                .unwrap_or(0);
            if needed > len {
                return Err(invalid(
                    "orders",
                    format!(
                        "input `{}`: its largest order needs at least {needed} samples; the record has {len}",
                        c.input
                    ),
                ));
            }
        }
        let mut combos: Vec<Vec<(usize, usize)>> = vec![Vec::new()];
        for c in channels {
            combos = combos
                .into_iter()
                .flat_map(|head| {
                    c.orders.iter().map(move |o| {
                        let mut next = head.clone();
                        next.push(*o);
                        next
                    })
                })
                .collect();
        }
        Ok(combos
            .into_iter()
            .flat_map(|orders| {
                self.families
                    .iter()
                    .map(move |f| (orders.clone(), f.clone()))
            })
            .collect())
    }
}

/// The `tf` spec table of a fitted channel.
fn tf_table(num: &[f64], den: &[f64]) -> SpecTable {
    let mut spec = SpecTable::new();
    spec.insert("kind".into(), json!("tf"));
    spec.insert("num".into(), json!(num));
    spec.insert("den".into(), json!(den));
    spec
}

/// One BCLS fit of a multi-input candidate from the multi-input initializer's channels with
/// the jitter at `fraction · T`.
fn fit_from(
    record: &Record,
    inputs: &[Input],
    names: &[String],
    registry: &JitterRegistry,
    options: &SelectionOptions,
    (family, orders): (&str, &[(usize, usize)]),
    fraction: f64,
) -> Result<(Structure, jitterid_estimate::Fit), String> {
    let jitter = jitter_at(registry, family, record, fraction)?;
    let channels: Vec<ChannelOrder<'_>> = inputs
        .iter()
        .zip(orders)
        .map(|(input, &(poles, zeros))| ChannelOrder {
            input,
            zeros,
            poles,
        })
        .collect();
    let fits = fit_channels(record, &channels, Some(&jitter), &init_options(options))
        .map_err(|e| format!("initializer: {e}"))?;
    let spec = spec_table(
        names
            .iter()
            .zip(&fits)
            .map(|(name, f)| (name.clone(), tf_table(&f.num, &f.den), true))
            .collect(),
        false,
    );
    let build = |spec: &SpecTable| -> Result<AnySignal, String> {
        build(SignalRegistry::builtin(), spec, inputs).map_err(|e| e.to_string())
    };
    let signal = build(&with_offset(spec, &build, record, &jitter, options)?)
        .map_err(|e| format!("candidate system: {e}"))?;
    bcls_from(record, family, signal, jitter)
}

/// [`select`](super::select) for a system with several inputs: fits every combination of
/// [`SelectionGrid::channel_candidates`] of `grid`'s families and `channels` on `record`,
/// driven by `inputs` (one per entry of `channels`, in order), each candidate a superposition of one transfer
/// function per input (parameters `"{input}.b0"`, `"{input}.a0"`, …) with the options'
/// output offset; ranked best first as one input's candidates are. A candidate's `poles` and
/// `zeros` count all its channels'; `channels` gives them per input.
///
/// # Errors
///
/// Those of [`SelectionGrid::channel_candidates`]; [`SelectionError::InvalidKey`] (key
/// `inputs`) when the inputs do not match the grid's, and (key `orders`) with the options'
/// delay or free response, which the multi-input candidates do not carry.
pub fn select_channels(
    record: &Record,
    inputs: &[Input],
    grid: &SelectionGrid,
    channels: &[ChannelOrders],
    registry: &JitterRegistry,
    options: &SelectionOptions,
) -> Result<Vec<Candidate>, SelectionError> {
    check_fractions(options)?;
    if inputs.len() != channels.len() {
        return Err(invalid(
            "inputs",
            format!(
                "{} inputs for a grid of {} inputs",
                inputs.len(),
                channels.len()
            ),
        ));
    }
    if options.delay.is_some() || options.initial_state {
        return Err(invalid(
            "orders",
            "the candidates of several inputs carry no input delay and no free response",
        ));
    }
    let list = grid.channel_candidates(channels, registry, record.y().len())?;
    let names: Vec<String> = channels.iter().map(|c| c.input.clone()).collect();
    let budget = jitterid_numeric::budget::current();
    let out: Vec<Candidate> = list
        .into_par_iter()
        .map(|(orders, family)| {
            jitterid_numeric::budget::run_with(budget.clone(), || {
                let fit_at = |fraction| {
                    fit_from(
                        record,
                        inputs,
                        &names,
                        registry,
                        options,
                        (&family, &orders),
                        fraction,
                    )
                };
                let label = Label {
                    poles: orders.iter().map(|o| o.0).sum(),
                    zeros: orders.iter().map(|o| o.1).sum(),
                    channels: names
                        .iter()
                        .zip(&orders)
                        .map(|(n, &(p, z))| (n.clone(), p, z))
                        .collect(),
                    family: family.clone(),
                };
                fit_candidate(record, options, label, &fit_at)
            })
        })
        .collect();
    Ok(rank(record, registry, options, out))
}
