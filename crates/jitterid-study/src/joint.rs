//! Joint fits of several records of one system (a system-identification toolbox's `merge`):
//! each record with its own input, length and start, the experiment's parameters shared, the
//! first-moment criterion summed over the records with every sample weighing alike
//! ([`jitterid::estimate::estimate_joint`]).

use crate::csvio;
use crate::error::StudyResult;
use crate::experiment::Experiment;
use crate::fit::{self, Fit, Raw};
use crate::records::{read_data, read_input_on};
use crate::study_err;
use crate::Watch;
use jitterid::estimate::{estimate_joint, MeasuredRecord, Record};
use jitterid::signal::{Input, SampleGrid};
use std::path::Path;

/// One record of a joint fit: its samples on its own grid, and its input.
#[derive(Debug, Clone)]
pub struct JointRecord {
    /// The data file's name, for messages.
    pub name: String,
    /// The record's grid.
    pub grid: SampleGrid,
    /// Its samples.
    pub y: Vec<f64>,
    /// Its inputs, in order (the experiment's own, or for a random-binary experiment the
    /// record's side file).
    pub inputs: Vec<Input>,
}

/// The records of the data files `paths`: the first on the experiment's grid (as for one
/// record), each other on the grid of its own `t` column (every instant checked), or without a
/// `t` column on the experiment's start and interval with its own length. Each record's input
/// is the experiment's known input (records on one clock share one input file) or, for a
/// random-binary experiment, the record's side file `<stem>.input.csv`.
///
/// # Errors
///
/// A file cannot be read, a `t` column is not a uniform grid, or an input is missing.
pub fn read_records(exp: &Experiment, paths: &[&Path]) -> StudyResult<Vec<JointRecord>> {
    let mut out = Vec::with_capacity(paths.len());
    for (i, path) in paths.iter().enumerate() {
        let (name, grid, y) = if i == 0 {
            let d = read_data(exp, path)?;
            (d.name, exp.grid, d.y)
        } else {
            let table = csvio::read(path)?;
            let grid = match table.optional("t") {
                Some(_) => *csvio::record_from_table(&table, None)?.grid(),
                None => {
                    let n = table.column("y")?.len();
                    SampleGrid::new(exp.grid.start(), exp.grid.interval(), n)
                        .map_err(|e| study_err!("{}: {e}", table.name))?
                }
            };
            (table.name.clone(), grid, table.column("y")?.to_vec())
        };
        let inputs = read_input_on(exp, path, None, &grid)?;
        out.push(JointRecord {
            name,
            grid,
            y,
            inputs,
        });
    }
    Ok(out)
}

/// Fits the experiment's model to all `records` at once, with the experiment's first-moment
/// method, started at the experiment's values.
///
/// # Errors
///
/// A likelihood method, a criterion that weights by a noise model (its floor is a per-record
/// quantity), or a profiled jitter order (each is fitted one record at a time); records whose
/// models differ; the estimator's errors.
pub fn fit_joint(exp: &Experiment, records: &[JointRecord], watch: &Watch) -> StudyResult<Fit> {
    let method = exp.estimate.method;
    let refuse = |why: &str| {
        study_err!(
            "{}: a joint fit of {} records with method {}: {why}",
            exp.file,
            records.len(),
            method.as_str()
        )
    };
    if fit::profiled(exp) {
        return Err(refuse(
            "a profiled uniform-sum order (`[jitter] n_range`) is fitted one record at a time",
        ));
    }
    let structures = records
        .iter()
        .map(|r| fit::structure(exp, fit::signal_of(exp, &r.inputs)?, method))
        .collect::<StudyResult<Vec<_>>>()?;
    let first = structures
        .first()
        .ok_or_else(|| refuse("no record was given"))?;
    let criterion = fit::criterion_of(exp, first, method);
    let moment = criterion.as_first_moment().ok_or_else(|| {
        refuse("the likelihoods fit one record at a time; use a first-moment method (ls, bcls)")
    })?;
    if moment.uses_noise_model() {
        return Err(refuse(
            "a criterion weighted by the noise model fits one record at a time; use ls or bcls",
        ));
    }
    let measured = records
        .iter()
        .map(|r| {
            let record =
                Record::new(r.grid, r.y.clone()).map_err(|e| study_err!("{}: {e}", r.name))?;
            let m = MeasuredRecord::new(r.name.clone(), record);
            // The record's input serves the initializer and the validation of one-input
            // models; a joint fit uses neither, but a single input is kept as it always was.
            Ok(match r.inputs.as_slice() {
                [u] => m.with_input(u.clone()),
                _ => m,
            })
        })
        .collect::<StudyResult<Vec<_>>>()?;
    let opts = fit::options(exp, &criterion, 0, true, watch)?;
    let budget = crate::budget_of(exp, watch.cancel.clone());
    let e = budget
        .run(|| estimate_joint(&structures, &measured, moment, &opts))
        .map_err(|e| match budget.stop() {
            Some(stop) => refuse(&format!("stopped before the search could begin: {stop}")),
            None => refuse(&e.to_string()),
        })?;
    let fitted = first
        .with_params(&e.params)
        .map_err(|e| refuse(&e.to_string()))?;
    fit::reported(exp, first, method, Raw::of(e, fitted, None)).map_err(|m| refuse(&m))
}
