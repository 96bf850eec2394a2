//! Experiment design from Python: the study layer's design search
//! ([`jitterid_study::design`]) on an experiment's `[design]` section, the numbers of
//! `jitterid design --json [--criterion] [--budget] [--jitter-blind] [--write-input]
//! [--dac-rate]`.

use crate::errors::value_error;
use crate::experiment::Experiment;
use jitterid_study::design::{design as run_design, designed_input, jitter_blind, Plan};
use jitterid_study::experiment::{
    budget_edit, dac_rate_edit, derived_edit, DesignCriterion, ReadOptions,
};
use jitterid_study::Registries;
use pyo3::prelude::*;

/// The design of `experiment` (which has a `[design]` section) for `criterion` (`"d"`, `"a"`,
/// `"param:NAME"`; the section's by default) on the record `budget` (`"duration=SECONDS"` or
/// `"samples=N"`, replacing the section's), with the jitter-blind design beside it when
/// `jitter_blind`: `design --json`'s text. With `input_name`, also the designed input's CSV
/// text and the experiment text that reads it from a file of that name (`--write-input`); a
/// designed multisine's CSV is its sample sequence at `dac_rate` Hz (`--dac-rate`, replacing
/// `[design] dac_rate`). With `derived`, the derived quantities reported (`--derived`,
/// `[design] derived`).
#[pyfunction]
#[pyo3(signature = (experiment, criterion, jitter_blind_design, budget, input_name, derived=None, dac_rate=None))]
// One argument per keyword of `jitterid.design` (and PyO3's token): grouping them would only
// move the same list into a struct that Python cannot see.
#[allow(clippy::too_many_arguments)]
pub fn design(
    py: Python<'_>,
    experiment: &Experiment,
    criterion: Option<String>,
    jitter_blind_design: bool,
    budget: Option<String>,
    input_name: Option<String>,
    derived: Option<Vec<String>>,
    dac_rate: Option<f64>,
) -> PyResult<(String, Option<(String, String)>)> {
    let criterion = criterion
        .map(|c| DesignCriterion::parse(&c).map_err(|e| value_error(format!("criterion: {e}"))))
        .transpose()?;
    let mut options = ReadOptions {
        paths: experiment.paths(),
        ..ReadOptions::default()
    };
    if let Some(b) = budget {
        options
            .overrides
            .push(budget_edit(&b).map_err(value_error)?);
    }
    if let Some(names) = derived {
        let origin = format!("derived={names:?}");
        options.overrides.push(derived_edit(&names, origin));
    }
    if let Some(rate) = dac_rate {
        options.overrides.push(dac_rate_edit(rate));
    }
    let (file, text, dir) = experiment.source();
    let plan = Plan::parse(
        &Registries::builtin(),
        file,
        text.to_string(),
        dir,
        &options,
    )
    .map_err(value_error)?;
    py.detach(|| {
        let mut report = run_design(&plan, criterion.as_ref())?;
        if jitter_blind_design {
            report.jitter_blind = Some(jitter_blind(&plan, &report.criterion)?);
        }
        let written = input_name
            .map(|name| designed_input(&plan, &report.design, &name))
            .transpose()?
            .map(|w| (w.csv, w.experiment));
        let json = serde_json::to_string(&report.json())
            .map_err(|e| jitterid_study::study_err!("JSON: {e}"))?;
        Ok((json, written))
    })
    .map_err(|e: jitterid_study::error::StudyError| value_error(e))
}
