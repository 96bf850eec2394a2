//! A design: the values of the design variables of one planned experiment, and the edits of
//! the experiment file that make it.
//!
//! A design is applied as edits of the experiment's document (`input.mean_dwell`,
//! `input.low`, `input.high`, `sampling.interval`, `sampling.samples`, a multisine's
//! `input.frequencies`, `input.amplitudes` and `input.phases`), which is then read again:
//! every candidate meets the same validation as a file written by hand (the jitter's reach
//! within the record, the input's switch limit), and nothing in the design layer has to know
//! how an experiment holds its input or grid.

use super::multisine::MultisineDesign;
use crate::experiment::{Experiment, Override};
use serde::Serialize;

/// The design variables of one experiment.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Design {
    /// The random binary input's mean dwell (s), for such an input.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mean_dwell: Option<f64>,
    /// The random binary input's `low` level, when the levels are designed (`[design] low` or
    /// `high`; both levels are then given, the fixed one at the file's value, so that a
    /// report shows the pair). Absent otherwise, so that other designs' JSON is unchanged.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub low: Option<f64>,
    /// The random binary input's `high` level, as `low`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub high: Option<f64>,
    /// The sampling interval `T` (s).
    pub interval: f64,
    /// The number of samples `N`.
    pub samples: usize,
    /// A multisine input's tones, when they are designed (`[design] band`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub multisine: Option<MultisineDesign>,
}

impl Design {
    /// The experiment's own design (the baseline a designed experiment is compared with).
    pub fn of(exp: &Experiment) -> Self {
        Design {
            mean_dwell: super::realization::mean_dwell_of(exp),
            low: None,
            high: None,
            interval: exp.grid.interval(),
            samples: exp.grid.len(),
            multisine: None,
        }
    }

    /// The document edits that turn the experiment into this design; each names the design
    /// in messages (`[design] interval = 0.5`).
    pub(crate) fn edits(&self) -> Vec<Override> {
        let edit = |path: &[&str], v: toml_edit::Value| {
            let origin = format!("[design] {} = {v}", path[path.len() - 1]);
            Override::from_source(path, v, origin)
        };
        let mut out = Vec::with_capacity(5);
        if let Some(d) = self.mean_dwell {
            out.push(edit(&["input", "mean_dwell"], d.into()));
        }
        if let Some(l) = self.low {
            out.push(edit(&["input", "low"], l.into()));
        }
        if let Some(h) = self.high {
            out.push(edit(&["input", "high"], h.into()));
        }
        out.push(edit(&["sampling", "interval"], self.interval.into()));
        out.push(edit(&["sampling", "samples"], (self.samples as i64).into()));
        if let Some(m) = &self.multisine {
            let list = |xs: &[f64]| toml_edit::Value::Array(xs.iter().copied().collect());
            out.push(edit(&["input", "frequencies"], list(&m.frequencies)));
            out.push(edit(&["input", "amplitudes"], list(&m.amplitudes)));
            out.push(edit(&["input", "phases"], list(&m.phases)));
        }
        out
    }
}
