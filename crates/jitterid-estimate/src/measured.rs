//! [`MeasuredRecord`]: what a measurement holds — the samples, the requested instants, the input
//! that drove the system, an optional known noise level and a name.
//!
//! [`Record`] stays the numerics' view (grid and samples, what a criterion compares with the
//! model); a measured record adds what belongs to the experiment rather than to the criterion.
//! Keeping them apart leaves every fit path and `Record`'s serde format unchanged, and lets a
//! model fitted on one record be evaluated on another: rebuild its signal with
//! [`AnySignal::with_input`](jitterid_signal::AnySignal::with_input) and this record's
//! [`input`](MeasuredRecord::input).

use crate::data::Record;
use crate::EstimateError;
use jitterid_signal::{Input, PiecewiseConstant, SampleGrid};

/// One measured record: samples on a grid, the input and what else is known about it.
#[derive(Debug, Clone)]
pub struct MeasuredRecord {
    name: String,
    record: Record,
    input: Option<Input>,
    noise_std: Option<f64>,
}

/// How a record's input is laid out: records fitted jointly to one system must agree on it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum InputLayout {
    /// No input (a free signal such as a sinusoid).
    None,
    /// One piecewise-constant input channel.
    Piecewise,
    /// One multisine input channel.
    Tones,
}

impl std::fmt::Display for InputLayout {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            InputLayout::None => "no input",
            InputLayout::Piecewise => "one piecewise-constant input",
            InputLayout::Tones => "one multisine input",
        })
    }
}

impl MeasuredRecord {
    /// A record named `name` (used in messages), without input or known noise level.
    pub fn new(name: impl Into<String>, record: Record) -> Self {
        MeasuredRecord {
            name: name.into(),
            record,
            input: None,
            noise_std: None,
        }
    }

    /// The record with the input that drove the system.
    pub fn with_input(mut self, input: Input) -> Self {
        self.input = Some(input);
        self
    }

    /// The record with input samples `u_k` held from `t_k` to `t_{k+1}` (zero-order hold, one
    /// sample per instant of the grid).
    ///
    /// # Errors
    ///
    /// [`EstimateError::DataLength`] if there is not one input sample per instant;
    /// [`EstimateError::Signal`] if a sample is not finite.
    pub fn with_held_input(self, u: &[f64]) -> Result<Self, EstimateError> {
        let grid = self.grid();
        if u.len() != grid.len() {
            return Err(EstimateError::DataLength {
                expected: grid.len(),
                got: u.len(),
            });
        }
        let held = PiecewiseConstant::zero_order_hold(grid.start(), grid.interval(), u)?;
        Ok(self.with_input(Input::Piecewise(held)))
    }

    /// The record with a known measurement-noise standard deviation.
    ///
    /// # Errors
    ///
    /// [`EstimateError::BadNoiseStd`] unless `std` is finite and `>= 0`.
    pub fn with_noise_std(mut self, std: f64) -> Result<Self, EstimateError> {
        if !(std.is_finite() && std >= 0.0) {
            return Err(EstimateError::BadNoiseStd { value: std });
        }
        self.noise_std = Some(std);
        Ok(self)
    }

    /// The record's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The samples on their grid, as the criteria see them.
    pub fn record(&self) -> &Record {
        &self.record
    }

    /// The requested instants `t0 + kT`.
    pub fn grid(&self) -> &SampleGrid {
        self.record.grid()
    }

    /// The samples `y_k`.
    pub fn y(&self) -> &[f64] {
        self.record.y()
    }

    /// The input, if the record has one.
    pub fn input(&self) -> Option<&Input> {
        self.input.as_ref()
    }

    /// The known measurement-noise standard deviation, if any.
    pub fn noise_std(&self) -> Option<f64> {
        self.noise_std
    }

    /// The layout of the input.
    pub fn input_layout(&self) -> InputLayout {
        match &self.input {
            None => InputLayout::None,
            Some(Input::Piecewise(_)) => InputLayout::Piecewise,
            Some(Input::Tones(_)) => InputLayout::Tones,
        }
    }
}
