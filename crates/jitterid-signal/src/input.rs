//! Known inputs `u(t)` that drive a system.

use crate::error::{all_finite, increasing, positive, SignalError};
use jitterid_numeric::limits::{self, Limit};
use num_complex::Complex64;
use rand::{Rng, RngCore};
use rand_distr::{Distribution, Exp};

/// A known input signal.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Input {
    /// Piecewise constant, zero outside a finite span.
    Piecewise(PiecewiseConstant),
    /// A sum of sinusoids, in steady state.
    Tones(Multisine),
}

impl Input {
    /// `u(t)`.
    pub fn value(&self, t: f64) -> f64 {
        match self {
            Input::Piecewise(p) => p.value(t),
            Input::Tones(m) => m.value(t),
        }
    }

    /// `u(t − delay)`: a piecewise-constant input with its edges moved `delay` seconds later
    /// (what drives the rational part of a system with an input delay).
    ///
    /// # Errors
    ///
    /// [`SignalError::NotFinite`] for a NaN or infinite delay, [`SignalError::NeedsSteps`] for
    /// tones (a tone's delay is a phase).
    pub fn delayed(&self, delay: f64) -> Result<Input, SignalError> {
        crate::error::finite("delay", delay)?;
        match self {
            Input::Piecewise(p) => {
                let edges = p.edges.iter().map(|e| e + delay).collect();
                PiecewiseConstant::new(edges, p.levels.clone()).map(Input::Piecewise)
            }
            Input::Tones(_) => Err(SignalError::NeedsSteps { what: "a delay" }),
        }
    }

    /// `1` over the input's span: one step up at a piecewise input's first edge and down at
    /// its last, or, for tones (on at all times), the constant `1` as a tone of frequency 0
    /// and phase `π/2`.
    ///
    /// # Errors
    ///
    /// None for an input that was built (its span is valid); kept for the constructors'.
    pub fn unit_span(&self) -> Result<Input, SignalError> {
        Ok(match self {
            Input::Piecewise(p) => {
                let (first, last) = (p.edges[0], p.edges[p.edges.len() - 1]);
                Input::Piecewise(PiecewiseConstant::new(vec![first, last], vec![1.0])?)
            }
            Input::Tones(_) => Input::Tones(Multisine::new(vec![Tone::constant(1.0)])?),
        })
    }

    /// `u − level · 1` over the input's span ([`unit_span`](Self::unit_span)): the deviation
    /// from an operating point `level`, what a linear model around it is driven by. A tone
    /// input gets `−level` as its last tone.
    ///
    /// # Errors
    ///
    /// [`SignalError::NotFinite`] for a NaN or infinite level; for tones, the tone limit.
    pub fn deviation(&self, level: f64) -> Result<Input, SignalError> {
        crate::error::finite("level", level)?;
        Ok(match self {
            Input::Piecewise(p) => Input::Piecewise(PiecewiseConstant::new(
                p.edges.clone(),
                p.levels.iter().map(|u| u - level).collect(),
            )?),
            Input::Tones(m) => {
                let mut tones = m.tones().to_vec();
                tones.push(Tone::constant(-level));
                Input::Tones(Multisine::new(tones)?)
            }
        })
    }
}

impl From<PiecewiseConstant> for Input {
    fn from(p: PiecewiseConstant) -> Self {
        Input::Piecewise(p)
    }
}

impl From<Multisine> for Input {
    fn from(m: Multisine) -> Self {
        Input::Tones(m)
    }
}

/// A piecewise-constant input: `u(t) = levels[j]` on `[edges[j], edges[j+1])`, and zero before
/// `edges[0]` and from the last edge on. The system is at rest before `edges[0]`.
///
/// Zero outside a finite span keeps `S_c` a density: `U(f)` is entire. Put the first edge
/// before the record (a warm-up) and the last one after it to model an input that is on for the
/// whole record.
///
/// Deserializes through [`PiecewiseConstant::new`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "PiecewiseFields")]
pub struct PiecewiseConstant {
    edges: Vec<f64>,
    levels: Vec<f64>,
}

impl PiecewiseConstant {
    /// `edges` strictly increasing (`levels.len() + 1` of them), all values finite.
    pub fn new(edges: Vec<f64>, levels: Vec<f64>) -> Result<Self, SignalError> {
        if levels.is_empty() {
            return Err(SignalError::TooFew {
                name: "levels",
                min: 1,
                value: 0,
            });
        }
        if edges.len() != levels.len() + 1 {
            return Err(SignalError::WrongLength {
                name: "edges",
                expected: levels.len() + 1,
                got: edges.len(),
            });
        }
        limits::check(Limit::Switches, edges.len())?;
        increasing("edges", &edges)?;
        all_finite("levels", &levels)?;
        Ok(Self { edges, levels })
    }

    /// Zero-order hold of a sampled sequence: `u(t) = values[k]` on
    /// `[start + k·interval, start + (k+1)·interval)`.
    pub fn zero_order_hold(start: f64, interval: f64, values: &[f64]) -> Result<Self, SignalError> {
        positive("interval", interval)?;
        limits::check(Limit::Switches, values.len() + 1)?;
        let edges = (0..=values.len())
            .map(|k| start + k as f64 * interval)
            .collect();
        Self::new(edges, values.to_vec())
    }

    /// The edges `t_0 < … < t_J`.
    pub fn edges(&self) -> &[f64] {
        &self.edges
    }

    /// The levels, one per interval between edges.
    pub fn levels(&self) -> &[f64] {
        &self.levels
    }

    /// `u(t)`.
    pub fn value(&self, t: f64) -> f64 {
        // Index of the last edge ≤ t.
        let i = self.edges.partition_point(|&e| e <= t);
        if i == 0 || i == self.edges.len() {
            0.0
        } else {
            self.levels[i - 1]
        }
    }

    /// Fourier transform `U(f) = Σ_j u_j ∫_{t_j}^{t_{j+1}} e^{-i2πft} dt`, written with
    /// `sinc` so that it is exact at `f = 0` and free of cancellation at small `f`.
    pub fn spectrum(&self, f: f64) -> Complex64 {
        self.levels
            .iter()
            .zip(self.edges.windows(2))
            .map(|(&u, e)| {
                let d = e[1] - e[0];
                let mid = 0.5 * (e[0] + e[1]);
                let x = std::f64::consts::PI * f * d;
                let sinc = if x.abs() < 1e-4 {
                    1.0 - x * x / 6.0
                } else {
                    x.sin() / x
                };
                Complex64::from_polar(u * d * sinc, -std::f64::consts::TAU * f * mid)
            })
            .sum()
    }

    /// The input as steps: `u(t) = Σ_j Δu_j H(t − t_j)`, returned as `(t_j, Δu_j)` with steps of
    /// zero height dropped.
    pub fn steps(&self) -> Vec<(f64, f64)> {
        let mut out = Vec::with_capacity(self.edges.len());
        let mut prev = 0.0;
        for (j, &e) in self.edges.iter().enumerate() {
            let level = self.levels.get(j).copied().unwrap_or(0.0);
            if level != prev {
                out.push((e, level - prev));
            }
            prev = level;
        }
        out
    }
}

/// One tone `A sin(2πft + φ)`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Tone {
    /// Frequency in Hz.
    pub frequency: f64,
    /// Amplitude.
    pub amplitude: f64,
    /// Phase in radians.
    pub phase: f64,
}

impl Tone {
    /// The constant `c` as a tone: frequency 0, amplitude `c`, phase `π/2`.
    pub fn constant(c: f64) -> Self {
        Tone {
            frequency: 0.0,
            amplitude: c,
            phase: std::f64::consts::FRAC_PI_2,
        }
    }
}

/// A sum of tones `u(t) = Σ A_l sin(2πf_l t + φ_l)`, on for all time (the response is the
/// steady state).
///
/// Deserializes through [`Multisine::new`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "MultisineFields")]
pub struct Multisine {
    tones: Vec<Tone>,
}

impl Multisine {
    /// At least one tone and at most [`MAX_TONES`](limits::MAX_TONES), all values finite,
    /// frequencies ≥ 0, phases within ±[`MAX_PHASE`](limits::MAX_PHASE) rad.
    pub fn new(tones: Vec<Tone>) -> Result<Self, SignalError> {
        if tones.is_empty() {
            return Err(SignalError::TooFew {
                name: "tones",
                min: 1,
                value: 0,
            });
        }
        limits::check(Limit::Tones, tones.len())?;
        for t in &tones {
            crate::error::finite("frequency", t.frequency)?;
            if t.frequency < 0.0 {
                return Err(SignalError::NotPositive {
                    name: "frequency",
                    value: t.frequency,
                });
            }
            crate::error::finite("amplitude", t.amplitude)?;
            crate::error::finite("phase", t.phase)?;
            if !(t.phase.abs() <= limits::MAX_PHASE) {
                return Err(SignalError::OutOfRange {
                    name: "phase",
                    value: t.phase,
                    expected: "within ±1e6 rad (beyond it the tone has lost its digits)",
                });
            }
        }
        Ok(Self { tones })
    }

    /// One tone.
    pub fn sine(frequency: f64, amplitude: f64, phase: f64) -> Result<Self, SignalError> {
        Self::new(vec![Tone {
            frequency,
            amplitude,
            phase,
        }])
    }

    /// The tones.
    pub fn tones(&self) -> &[Tone] {
        &self.tones
    }

    /// `u(t)`.
    pub fn value(&self, t: f64) -> f64 {
        self.tones
            .iter()
            .map(|c| c.amplitude * (std::f64::consts::TAU * c.frequency * t + c.phase).sin())
            .sum()
    }
}

/// The largest expected number of switches of one [`RandomBinary::generate`] call: the
/// library's limit on the switches of an input.
pub const MAX_SWITCHES: f64 = limits::MAX_SWITCHES as f64;

/// The random binary input of the paper's section 4: it switches between `low` and `high` after
/// exponentially distributed dwell times of mean `mean_dwell`, at any time (not on the sample
/// grid).
///
/// Deserializes through [`RandomBinary::new`].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "RandomBinaryFields")]
pub struct RandomBinary {
    mean_dwell: f64,
    low: f64,
    high: f64,
}

impl RandomBinary {
    /// `mean_dwell > 0`, finite levels.
    pub fn new(mean_dwell: f64, low: f64, high: f64) -> Result<Self, SignalError> {
        positive("mean_dwell", mean_dwell)?;
        crate::error::finite("low", low)?;
        crate::error::finite("high", high)?;
        Ok(Self {
            mean_dwell,
            low,
            high,
        })
    }

    /// The paper's input: levels 0 and 1, mean dwell 8 s.
    pub fn paper() -> Self {
        Self {
            mean_dwell: 8.0,
            low: 0.0,
            high: 1.0,
        }
    }

    /// Mean dwell time (s).
    pub fn mean_dwell(&self) -> f64 {
        self.mean_dwell
    }

    /// The level of the input's "low" state.
    pub fn low(&self) -> f64 {
        self.low
    }

    /// The level of the input's "high" state.
    pub fn high(&self) -> f64 {
        self.high
    }

    /// One realisation on `[start, end)`: the first level is `low` or `high` with equal
    /// probability, then levels alternate. Needs `end > start` and at most [`MAX_SWITCHES`]
    /// expected switches (`(end − start)/mean_dwell`).
    pub fn generate(
        &self,
        start: f64,
        end: f64,
        rng: &mut dyn RngCore,
    ) -> Result<PiecewiseConstant, SignalError> {
        crate::error::finite("start", start)?;
        crate::error::finite("end", end)?;
        if end <= start {
            return Err(SignalError::NotIncreasing {
                name: "input span",
                index: 1,
                value: end,
                previous: start,
            });
        }
        // About `(end − start)/mean_dwell` switches: refuse a span that would hold more than an
        // input can usefully have (and a subnormal dwell, whose rate overflows).
        let expected = (end - start) / self.mean_dwell;
        if !(expected <= MAX_SWITCHES) {
            return Err(SignalError::TooManySwitches {
                expected,
                max: MAX_SWITCHES,
            });
        }
        let dwell = Exp::new(1.0 / self.mean_dwell).map_err(|_| SignalError::NotFinite {
            name: "1/mean_dwell",
            value: 1.0 / self.mean_dwell,
        })?;
        let mut high = rng.random::<bool>();
        let mut edges = vec![start];
        let mut levels = Vec::new();
        let mut t = start;
        loop {
            levels.push(if high { self.high } else { self.low });
            let next = t + dwell.sample(rng);
            // A zero-length dwell (possible in floating point) would break strict increase.
            if next >= end {
                edges.push(end);
                break;
            }
            if next > t {
                edges.push(next);
                t = next;
                high = !high;
            } else {
                levels.pop();
            }
        }
        PiecewiseConstant::new(edges, levels)
    }
}

/// The serialized form of a [`PiecewiseConstant`], validated on the way in.
#[derive(serde::Deserialize)]
struct PiecewiseFields {
    edges: Vec<f64>,
    levels: Vec<f64>,
}

impl TryFrom<PiecewiseFields> for PiecewiseConstant {
    type Error = SignalError;
    fn try_from(p: PiecewiseFields) -> Result<Self, SignalError> {
        Self::new(p.edges, p.levels)
    }
}

/// The serialized form of a [`Multisine`], validated on the way in.
#[derive(serde::Deserialize)]
struct MultisineFields {
    tones: Vec<Tone>,
}

impl TryFrom<MultisineFields> for Multisine {
    type Error = SignalError;
    fn try_from(m: MultisineFields) -> Result<Self, SignalError> {
        Self::new(m.tones)
    }
}

/// The serialized form of a [`RandomBinary`], validated on the way in.
#[derive(serde::Deserialize)]
struct RandomBinaryFields {
    mean_dwell: f64,
    low: f64,
    high: f64,
}

impl TryFrom<RandomBinaryFields> for RandomBinary {
    type Error = SignalError;
    fn try_from(r: RandomBinaryFields) -> Result<Self, SignalError> {
        Self::new(r.mean_dwell, r.low, r.high)
    }
}
