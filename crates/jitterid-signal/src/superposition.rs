//! Several inputs: the output of a multi-input system as the sum of one response per input.

use crate::registry::{SignalRegistry, SpecTable, KIND_KEY};
use crate::signal::{local_breaks, Jacobian, Signal};
use crate::spectrum::{SpectralLine, Spectrum};
use crate::{AnySignal, Input, Offset, SampleGrid, SignalError};
use jitterid_jitter::JitterModel;
use num_complex::Complex64;
use serde_json::{json, Value};

/// The registry name of a multi-input system's spec table.
pub const SUPERPOSITION_KIND: &str = "superposition";

/// One input's part of a [`Superposition`]: its name, the response `G_i u_i` it drives, and
/// whether that response's parameters are estimated.
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    /// The input's name (`u1`, `u2`, … unless named): the prefix of its parameters' names.
    pub name: String,
    /// The response to this input alone (any signal: a `zpk`, `tf` or grey-box response, with
    /// its own delay).
    pub signal: AnySignal,
    /// Whether its parameters are parameters of the sum (a fixed channel is part of the model
    /// but not of the search).
    pub estimated: bool,
}

/// `s(t) = Σᵢ sᵢ(t)`: the output of a linear system with several inputs, one response per
/// input (`sᵢ = Gᵢ uᵢ`), by superposition.
///
/// The jittered first moment is the sum of the channels' exact first moments, since an
/// expectation is linear. The second moment is not a sum: `E[(Σ sᵢ)²] = Σᵢ E[sᵢ²] +
/// 2 Σ_{i<j} E[sᵢ sⱼ]`, where the channels' own squares use their exact routes and each cross
/// term `E[sᵢ(t_k+τ) sⱼ(t_k+τ)]` the jitter's quadrature rule cut at both channels' breakpoints
/// (inside a piece between breakpoints the product of two responses is analytic, which is
/// what the rule integrates exactly to its order).
///
/// Parameters: those of each estimated channel in order, named `"{input}.{name}"`
/// (`u1.b0`, `brake.a1`); or, for channels that are one model's responses to its several
/// inputs ([`shared`](Self::shared): a grey-box model whose `B` has a column per input), that
/// model's parameters once, by their own names, each derivative the sum of the channels'. The
/// spectrum is the sum of the channels' spectra.
#[derive(Debug, Clone, PartialEq)]
pub struct Superposition {
    channels: Vec<Channel>,
    /// The start of each channel's parameters in the sum's parameter vector, and the total.
    offsets: Vec<usize>,
    /// Whether every channel has the same parameters (all start at 0).
    shared: bool,
    breakpoints: Vec<f64>,
}

impl Superposition {
    /// The sum of `channels`' responses.
    ///
    /// # Errors
    ///
    /// [`SignalError::TooFew`] for no channel, [`SignalError::InvalidKey`] (key `inputs`) for
    /// an empty or repeated input name.
    pub fn new(channels: Vec<Channel>) -> Result<Self, SignalError> {
        Self::build(channels, false)
    }

    /// The responses of one model to each of its inputs (the channels: the model with only
    /// column `i` of its `B` and `D`), whose parameters are the model's, once.
    ///
    /// # Errors
    ///
    /// Those of [`new`](Self::new), and [`SignalError::InvalidKey`] (key `channels`) for
    /// channels whose parameters' names, values or estimated flags differ.
    pub fn shared(channels: Vec<Channel>) -> Result<Self, SignalError> {
        if let Some(first) = channels.first() {
            let same = |c: &Channel| {
                c.estimated == first.estimated
                    && c.signal.param_names() == first.signal.param_names()
                    && c.signal.params() == first.signal.params()
            };
            if !channels.iter().all(same) {
                return Err(SignalError::InvalidKey {
                    kind: SUPERPOSITION_KIND.into(),
                    key: "channels".into(),
                    message: "channels that share their parameters must have the same parameters, values and estimated flags".into(),
                });
            }
        }
        Self::build(channels, true)
    }

    /// The channel whose parameters are the sum's when they are shared: the first estimated
    /// one (all have the same), `None` when none is estimated.
    fn shared_parameters(&self) -> Option<&Channel> {
        self.channels.iter().find(|c| c.estimated)
    }

    /// Whether the channels share one set of parameters ([`shared`](Self::shared)).
    pub fn is_shared(&self) -> bool {
        self.shared
    }

    fn build(channels: Vec<Channel>, shared: bool) -> Result<Self, SignalError> {
        if channels.is_empty() {
            return Err(SignalError::TooFew {
                name: "channels",
                min: 1,
                value: 0,
            });
        }
        for (i, c) in channels.iter().enumerate() {
            let bad = if c.name.is_empty() {
                Some("an input name is empty".to_string())
            } else if channels[..i].iter().any(|d| d.name == c.name) {
                Some(format!("the input name `{}` is used twice", c.name))
            } else {
                None
            };
            if let Some(message) = bad {
                return Err(SignalError::InvalidKey {
                    kind: SUPERPOSITION_KIND.into(),
                    key: "inputs".into(),
                    message,
                });
            }
        }
        let mut offsets = Vec::with_capacity(channels.len() + 1);
        let mut at = 0;
        for c in &channels {
            if shared {
                offsets.push(0);
                if c.estimated {
                    at = c.signal.num_params();
                }
            } else {
                offsets.push(at);
                if c.estimated {
                    at += c.signal.num_params();
                }
            }
        }
        offsets.push(at);
        let mut breakpoints: Vec<f64> = channels
            .iter()
            .flat_map(|c| c.signal.breakpoints())
            .collect();
        breakpoints.sort_by(f64::total_cmp);
        breakpoints.dedup();
        Ok(Self {
            channels,
            offsets,
            shared,
            breakpoints,
        })
    }

    /// The channels, in input order.
    pub fn channels(&self) -> &[Channel] {
        &self.channels
    }

    /// The range of channel `i`'s parameters in the sum's (empty for a fixed channel).
    fn range(&self, i: usize) -> std::ops::Range<usize> {
        let a = self.offsets[i];
        let b = if self.channels[i].estimated {
            a + self.channels[i].signal.num_params()
        } else {
            a
        };
        a..b
    }

    /// `E[sᵢ(t_k+τ) sⱼ(t_k+τ)]` for every instant, by the jitter's rule cut at the breakpoints
    /// of both channels.
    fn cross_moments(
        &self,
        i: usize,
        j: usize,
        grid: &SampleGrid,
        jitter: &dyn JitterModel,
    ) -> Vec<f64> {
        let (a, b) = (&self.channels[i].signal, &self.channels[j].signal);
        let mut breaks: Vec<f64> = a.breakpoints();
        breaks.extend(b.breakpoints());
        breaks.sort_by(f64::total_cmp);
        breaks.dedup();
        let (lo, hi) = jitter.reach();
        // A product's fastest rate is the sum of its factors'.
        let rate = a.rate() + b.rate();
        grid.times()
            .map(|t| {
                if jitterid_numeric::budget::spent() {
                    return f64::NAN;
                }
                let rule = jitter.rule(&local_breaks(&breaks, t, lo, hi), rate);
                rule.expect(|tau| a.value(t + tau) * b.value(t + tau))
            })
            .collect()
    }

    /// The spec table that rebuilds this sum with [`build`]: the input names, each channel's
    /// spec table and whether it is estimated.
    pub fn spec(&self) -> SpecTable {
        spec_table(
            self.channels
                .iter()
                .map(|c| (c.name.clone(), c.signal.spec(), c.estimated))
                .collect(),
            self.shared,
        )
    }

    /// Adds each estimated channel's gradient at `t` into its place in `grad` (zeroed first),
    /// returning `s(t)`: disjoint places for separate channels, the same for shared ones,
    /// whose derivatives add.
    fn accumulate_gradient(&self, t: f64, grad: &mut [f64]) -> f64 {
        grad.iter_mut().for_each(|g| *g = 0.0);
        let mut own = Vec::new();
        let mut v = 0.0;
        for (i, c) in self.channels.iter().enumerate() {
            let r = self.range(i);
            if r.is_empty() {
                v += c.signal.value(t);
                continue;
            }
            own.clear();
            own.resize(r.len(), 0.0);
            v += c.signal.value_and_gradient(t, &mut own);
            for (g, o) in grad[r].iter_mut().zip(&own) {
                *g += o;
            }
        }
        v
    }
}

impl Signal for Superposition {
    fn param_names(&self) -> Vec<String> {
        if self.shared {
            return self
                .shared_parameters()
                .map(|c| c.signal.param_names())
                .unwrap_or_default();
        }
        self.channels
            .iter()
            .filter(|c| c.estimated)
            .flat_map(|c| {
                c.signal
                    .param_names()
                    .into_iter()
                    .map(move |n| format!("{}.{n}", c.name))
            })
            .collect()
    }

    fn params(&self) -> Vec<f64> {
        if self.shared {
            return self
                .shared_parameters()
                .map(|c| c.signal.params())
                .unwrap_or_default();
        }
        self.channels
            .iter()
            .filter(|c| c.estimated)
            .flat_map(|c| c.signal.params())
            .collect()
    }

    fn with_params(&self, params: &[f64]) -> Result<Self, SignalError> {
        let expected = self.offsets[self.channels.len()];
        if params.len() != expected {
            return Err(SignalError::WrongParamCount {
                expected,
                got: params.len(),
            });
        }
        let mut channels = self.channels.clone();
        for (i, c) in channels.iter_mut().enumerate() {
            if c.estimated {
                c.signal = c.signal.with_params(&params[self.range(i)])?;
            }
        }
        Ok(Self {
            channels,
            offsets: self.offsets.clone(),
            shared: self.shared,
            breakpoints: self.breakpoints.clone(),
        })
    }

    fn value(&self, t: f64) -> f64 {
        self.channels.iter().map(|c| c.signal.value(t)).sum()
    }

    fn value_gradient(&self, t: f64, grad: &mut [f64]) {
        self.accumulate_gradient(t, grad);
    }

    fn value_and_gradient(&self, t: f64, grad: &mut [f64]) -> f64 {
        self.accumulate_gradient(t, grad)
    }

    fn breakpoints(&self) -> Vec<f64> {
        self.breakpoints.clone()
    }

    fn rate(&self) -> f64 {
        self.channels
            .iter()
            .map(|c| c.signal.rate())
            .fold(0.0, f64::max)
    }

    fn num_params(&self) -> usize {
        self.offsets[self.channels.len()]
    }

    fn expected_values(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Vec<f64> {
        let mut m = vec![0.0; grid.len()];
        for c in &self.channels {
            for (m, v) in m.iter_mut().zip(c.signal.expected_values(grid, jitter)) {
                *m += v;
            }
        }
        m
    }

    fn expected_values_gradient(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Jacobian {
        self.expected_values_and_gradient(grid, jitter).1
    }

    fn expected_values_and_gradient(
        &self,
        grid: &SampleGrid,
        jitter: &dyn JitterModel,
    ) -> (Vec<f64>, Jacobian) {
        let mut m = vec![0.0; grid.len()];
        let mut cols = vec![vec![0.0; grid.len()]; self.num_params()];
        for (i, c) in self.channels.iter().enumerate() {
            let v = if c.estimated {
                let (v, g) = c.signal.expected_values_and_gradient(grid, jitter);
                for (col, g) in cols[self.range(i)].iter_mut().zip(g) {
                    for (a, b) in col.iter_mut().zip(g) {
                        *a += b;
                    }
                }
                v
            } else {
                c.signal.expected_values(grid, jitter)
            };
            for (m, v) in m.iter_mut().zip(v) {
                *m += v;
            }
        }
        (m, cols)
    }

    fn expected_squares(&self, grid: &SampleGrid, jitter: &dyn JitterModel) -> Vec<f64> {
        let mut out = vec![0.0; grid.len()];
        for c in &self.channels {
            for (o, s) in out.iter_mut().zip(c.signal.expected_squares(grid, jitter)) {
                *o += s;
            }
        }
        for i in 0..self.channels.len() {
            for j in i + 1..self.channels.len() {
                for (o, x) in out.iter_mut().zip(self.cross_moments(i, j, grid, jitter)) {
                    *o += 2.0 * x;
                }
            }
        }
        out
    }
}

impl Spectrum for Superposition {
    fn density(&self, f: f64) -> Complex64 {
        self.channels.iter().map(|c| c.signal.density(f)).sum()
    }

    fn density_gradient(&self, f: f64, grad: &mut [Complex64]) {
        grad.iter_mut().for_each(|g| *g = Complex64::new(0.0, 0.0));
        let mut own = Vec::new();
        for i in 0..self.channels.len() {
            let r = self.range(i);
            if !r.is_empty() {
                own.clear();
                own.resize(r.len(), Complex64::new(0.0, 0.0));
                self.channels[i].signal.density_gradient(f, &mut own);
                for (g, o) in grad[r].iter_mut().zip(&own) {
                    *g += o;
                }
            }
        }
    }

    fn lines(&self) -> Vec<SpectralLine> {
        self.channels
            .iter()
            .flat_map(|c| c.signal.lines())
            .collect()
    }

    /// Each channel's rows, widened to the sum's parameters (its own columns at its place).
    fn lines_gradient(&self) -> Vec<Vec<(Complex64, f64)>> {
        let zero = (Complex64::new(0.0, 0.0), 0.0);
        let n = self.num_params();
        let mut rows = Vec::new();
        for (i, c) in self.channels.iter().enumerate() {
            let r = self.range(i);
            let own = c.signal.lines_gradient();
            for l in 0..c.signal.lines().len() {
                let mut row = vec![zero; n];
                if let Some(g) = own.get(l) {
                    for (dst, src) in row[r.clone()].iter_mut().zip(g) {
                        *dst = *src;
                    }
                }
                rows.push(row);
            }
        }
        rows
    }
}

/// The spec table of a multi-input system that [`build`] reads: each input's name, its
/// channel's spec table and whether that channel is estimated, in input order, and whether the
/// channels share their parameters. The one writer of the table's layout: a model's
/// [`Superposition::spec`] and a front end's reader of experiment files both call it.
pub fn spec_table(channels: Vec<(String, SpecTable, bool)>, shared: bool) -> SpecTable {
    let mut spec = SpecTable::new();
    spec.insert(KIND_KEY.into(), json!(SUPERPOSITION_KIND));
    let (mut names, mut specs, mut estimated) = (Vec::new(), Vec::new(), Vec::new());
    for (name, table, e) in channels {
        names.push(Value::String(name));
        specs.push(Value::Object(table));
        estimated.push(Value::Bool(e));
    }
    spec.insert("inputs".into(), Value::Array(names));
    spec.insert("channels".into(), Value::Array(specs));
    spec.insert("estimate".into(), Value::Array(estimated));
    if shared {
        spec.insert("shared".into(), json!(true));
    }
    spec
}

/// The model of a multi-input system: the sum of `channels` around the output offset `offset`
/// (a parameter when `estimate_offset`), as a run-time signal whose spec table
/// ([`AnySignal::spec`]) [`build`] reads back.
///
/// # Errors
///
/// Those of [`Superposition::new`] and [`Offset::new`].
pub fn superposition(
    channels: Vec<Channel>,
    offset: f64,
    estimate_offset: bool,
) -> Result<AnySignal, SignalError> {
    wrapped(Superposition::new(channels)?, offset, estimate_offset)
}

/// [`superposition`] of channels that share their parameters ([`Superposition::shared`]).
///
/// # Errors
///
/// Those of [`Superposition::shared`] and [`Offset::new`].
pub fn shared_superposition(
    channels: Vec<Channel>,
    offset: f64,
    estimate_offset: bool,
) -> Result<AnySignal, SignalError> {
    wrapped(Superposition::shared(channels)?, offset, estimate_offset)
}

fn wrapped(
    sum: Superposition,
    offset: f64,
    estimate_offset: bool,
) -> Result<AnySignal, SignalError> {
    // The sum has a spectrum when every channel has one.
    let spectral = sum.channels.iter().all(|c| c.signal.has_spectrum());
    let model = Offset::new(sum, offset, estimate_offset)?;
    let to_spec = |m: &Offset<Superposition>| {
        let mut spec = m.signal().spec();
        spec.remove(KIND_KEY);
        if m.offset() != 0.0 || m.estimated() {
            spec.insert("offset".into(), json!(m.offset()));
        }
        if m.estimated() {
            spec.insert("estimate_offset".into(), json!(true));
        }
        spec
    };
    Ok(if spectral {
        AnySignal::with_spectrum(SUPERPOSITION_KIND, model, to_spec)
    } else {
        AnySignal::new(SUPERPOSITION_KIND, model, to_spec)
    })
}

/// The multi-input model of a `superposition` spec table ([`superposition`]'s), each channel
/// built by `registry` from its own spec table and its input, `inputs` in the table's order.
///
/// # Errors
///
/// A malformed table ([`SignalError::MissingKey`], [`SignalError::InvalidKey`]), as many
/// inputs as channels not given (key `inputs`), and each channel's own build errors.
pub fn build(
    registry: &SignalRegistry,
    spec: &SpecTable,
    inputs: &[Input],
) -> Result<AnySignal, SignalError> {
    let invalid = |key: &str, message: String| SignalError::InvalidKey {
        kind: SUPERPOSITION_KIND.into(),
        key: key.into(),
        message,
    };
    let list = |key: &str| -> Result<&Vec<Value>, SignalError> {
        spec.get(key)
            .ok_or_else(|| SignalError::MissingKey {
                kind: SUPERPOSITION_KIND.into(),
                key: key.into(),
            })?
            .as_array()
            .ok_or_else(|| invalid(key, "expected a list".into()))
    };
    let names = list("inputs")?;
    let specs = list("channels")?;
    let estimated = list("estimate")?;
    if specs.len() != names.len() || estimated.len() != names.len() {
        return Err(invalid(
            "channels",
            format!(
                "{} channels and {} estimate flags for {} inputs",
                specs.len(),
                estimated.len(),
                names.len()
            ),
        ));
    }
    if inputs.len() != names.len() {
        return Err(invalid(
            "inputs",
            format!(
                "{} inputs given for a system with {} inputs",
                inputs.len(),
                names.len()
            ),
        ));
    }
    let mut channels = Vec::with_capacity(names.len());
    for (((name, s), e), input) in names.iter().zip(specs).zip(estimated).zip(inputs) {
        let name = name
            .as_str()
            .ok_or_else(|| invalid("inputs", format!("expected a name, found {name}")))?;
        let s = s
            .as_object()
            .ok_or_else(|| invalid("channels", format!("expected a table, found {s}")))?;
        let estimated = e
            .as_bool()
            .ok_or_else(|| invalid("estimate", format!("expected true or false, found {e}")))?;
        channels.push(Channel {
            name: name.to_string(),
            signal: registry.build(s, Some(input))?,
            estimated,
        });
    }
    let offset = match spec.get("offset") {
        None => 0.0,
        Some(v) => v
            .as_f64()
            .ok_or_else(|| invalid("offset", format!("expected a number, found {v}")))?,
    };
    let estimate_offset = spec.get("estimate_offset") == Some(&Value::Bool(true));
    if spec.get("shared") == Some(&Value::Bool(true)) {
        return shared_superposition(channels, offset, estimate_offset);
    }
    superposition(channels, offset, estimate_offset)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{binary, check_contract, Plain};
    use jitterid_jitter::{Gaussian, UniformSum};

    fn two_inputs(estimate_second: bool) -> AnySignal {
        let registry = SignalRegistry::builtin();
        let fast = serde_json::json!({"kind": "tf", "num": [2.0], "den": [1.0, 2.0]});
        let slow = serde_json::json!({"kind": "zpk", "gain": 0.3, "zeros": [-0.5], "poles": [[-0.2, 0.6]]});
        let u1: Input = binary(3, 4.0, 0.0, 60.0).unwrap().into();
        let u2: Input = binary(4, 9.0, 0.0, 60.0).unwrap().into();
        let channels = vec![
            Channel {
                name: "u1".into(),
                signal: registry
                    .build(fast.as_object().unwrap(), Some(&u1))
                    .unwrap(),
                estimated: true,
            },
            Channel {
                name: "brake".into(),
                signal: registry
                    .build(slow.as_object().unwrap(), Some(&u2))
                    .unwrap(),
                estimated: estimate_second,
            },
        ];
        superposition(channels, 0.7, true).unwrap()
    }

    #[test]
    fn parameters_are_the_estimated_channels_named_by_their_input() {
        let s = two_inputs(true);
        let names = s.param_names();
        assert_eq!(names.len(), 2 + 4 + 1);
        assert_eq!(names[..2], ["u1.b0", "u1.a0"]);
        assert!(names[2..6].iter().all(|n| n.starts_with("brake.")));
        assert_eq!(names[6], "offset");
        let fixed = two_inputs(false);
        assert_eq!(fixed.param_names(), ["u1.b0", "u1.a0", "offset"]);
        assert_eq!(fixed.params(), [2.0, 2.0, 0.7]);
    }

    #[test]
    fn the_sum_keeps_the_signal_contract() {
        let grid = SampleGrid::new(0.0, 0.5, 100).unwrap();
        for jitter in [
            Box::new(Gaussian::new(0.15).unwrap()) as Box<dyn JitterModel>,
            Box::new(UniformSum::new(2, 0.3).unwrap()),
        ] {
            check_contract(&two_inputs(true), jitter.as_ref(), &grid, 7).unwrap();
            check_contract(&two_inputs(false), jitter.as_ref(), &grid, 8).unwrap();
        }
    }

    /// The first moment is the channels' sum; the second has the cross term, checked against
    /// the default quadrature of the sum's square (an independent route: one rule over the
    /// whole value rather than exact squares plus cross terms).
    #[test]
    fn the_second_moment_has_the_cross_term() {
        let grid = SampleGrid::new(0.0, 0.5, 100).unwrap();
        let jitter = Gaussian::new(0.15).unwrap();
        let s = two_inputs(true);
        let sup = s.downcast::<Offset<Superposition>>().unwrap().signal();
        let channels = sup.channels();
        let m: Vec<f64> = s.expected_values(&grid, &jitter);
        let m1 = channels[0].signal.expected_values(&grid, &jitter);
        let m2 = channels[1].signal.expected_values(&grid, &jitter);
        for k in 0..grid.len() {
            assert!((m[k] - (0.7 + m1[k] + m2[k])).abs() < 1e-12);
        }
        let exact = sup.expected_squares(&grid, &jitter);
        // The sum through the provided (rule) route alone.
        let rule = Plain(sup.clone()).expected_squares(&grid, &jitter);
        let scale = exact.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
        for k in 0..grid.len() {
            assert!(
                (exact[k] - rule[k]).abs() < 1e-9 * scale,
                "k = {k}: {} against {}",
                exact[k],
                rule[k]
            );
        }
        // And the cross term matters: without it the squares are wrong.
        let own: Vec<f64> = (0..grid.len())
            .map(|k| {
                channels[0].signal.expected_squares(&grid, &jitter)[k]
                    + channels[1].signal.expected_squares(&grid, &jitter)[k]
            })
            .collect();
        assert!((0..grid.len()).any(|k| (own[k] - exact[k]).abs() > 1e-3 * scale));
    }

    #[test]
    fn the_spec_table_rebuilds_the_model() {
        let s = two_inputs(false);
        let u1: Input = binary(3, 4.0, 0.0, 60.0).unwrap().into();
        let u2: Input = binary(4, 9.0, 0.0, 60.0).unwrap().into();
        let back = build(SignalRegistry::builtin(), &s.spec(), &[u1.clone(), u2]).unwrap();
        assert_eq!(back.spec(), s.spec());
        assert_eq!(back.params(), s.params());
        let grid = SampleGrid::new(0.0, 0.5, 50).unwrap();
        let j = Gaussian::new(0.1).unwrap();
        assert_eq!(
            back.expected_values(&grid, &j),
            s.expected_values(&grid, &j)
        );
        let e = build(SignalRegistry::builtin(), &s.spec(), &[u1]).unwrap_err();
        assert_eq!(e.key(), Some("inputs"));
    }

    #[test]
    fn names_must_be_distinct() {
        let s = two_inputs(true);
        let sup = s.downcast::<Offset<Superposition>>().unwrap().signal();
        let mut channels = sup.channels().to_vec();
        channels[1].name = "u1".into();
        let e = Superposition::new(channels).unwrap_err();
        assert_eq!(e.key(), Some("inputs"));
        assert!(Superposition::new(Vec::new()).is_err());
    }

    /// One grey-box model with a column of `B` per input: a room heated by `u1` and cooled
    /// by the outside temperature `u2`, `ẋ = −x/(RC) + u1/C + u2/(RC)`, its two responses
    /// sharing `R` and `C`.
    fn heated_room() -> AnySignal {
        let registry = SignalRegistry::builtin();
        let column = |b: &str| {
            serde_json::json!({"kind": "grey-box", "params": {"R": 2.0, "C": 3.0},
                "a": [["-1/(R*C)"]], "b": [[b]], "c": [[1]]})
        };
        let u1: Input = binary(5, 4.0, -10.0, 60.0).unwrap().into();
        let u2: Input = binary(6, 9.0, -10.0, 60.0).unwrap().into();
        let channels = [("heater", "1/C", &u1), ("outside", "1/(R*C)", &u2)]
            .into_iter()
            .map(|(name, b, u)| Channel {
                name: name.into(),
                signal: registry
                    .build(column(b).as_object().unwrap(), Some(u))
                    .unwrap(),
                estimated: true,
            })
            .collect();
        shared_superposition(channels, 20.0, true).unwrap()
    }

    #[test]
    fn shared_channels_have_the_model_s_parameters_once() {
        let s = heated_room();
        assert_eq!(s.param_names(), ["C", "R", "offset"]);
        assert_eq!(s.params(), [3.0, 2.0, 20.0]);
        let t = s.with_params(&[4.0, 1.0, 19.0]).unwrap();
        let sum = t.downcast::<Offset<Superposition>>().unwrap().signal();
        assert!(sum.is_shared());
        assert!(sum
            .channels()
            .iter()
            .all(|c| c.signal.params() == [4.0, 1.0]));
        let grid = SampleGrid::new(0.0, 0.5, 100).unwrap();
        check_contract(&s, &Gaussian::new(0.15).unwrap(), &grid, 9).unwrap();
        // The spec table says the parameters are shared, and rebuilds the same model.
        let u1: Input = binary(5, 4.0, -10.0, 60.0).unwrap().into();
        let u2: Input = binary(6, 9.0, -10.0, 60.0).unwrap().into();
        let back = build(SignalRegistry::builtin(), &s.spec(), &[u1, u2]).unwrap();
        assert_eq!(back.param_names(), s.param_names());
        assert_eq!(back.spec(), s.spec());
    }

    #[test]
    fn channels_that_differ_cannot_share() {
        let s = heated_room();
        let sum = s.downcast::<Offset<Superposition>>().unwrap().signal();
        let mut channels = sum.channels().to_vec();
        channels[1].signal = channels[1].signal.with_params(&[3.0, 2.5]).unwrap();
        let e = Superposition::shared(channels).unwrap_err();
        assert_eq!(e.key(), Some("channels"));
    }
}
