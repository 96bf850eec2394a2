//! Monte Carlo studies and the merge of their shards, as `jitterid montecarlo --json` and
//! `jitterid merge --json` give them.

use crate::errors::{json_text, value_error};
use crate::experiment::Experiment;
use jitterid_study::merge::merge_values;
use jitterid_study::montecarlo::{run_study, Keep, McJson, Shard, DEFAULT_SEED};
use jitterid_study::Watch;
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// How often a running study looks for Ctrl-C (and any other Python signal).
const SIGNAL_POLL: Duration = Duration::from_millis(50);

/// Runs `runs` realisations of `experiment` with `method` (the file's if `None`) under master
/// `seed`, or shard `(index, count)` of them, on `threads` worker threads; returns the result
/// as JSON text (that of `jitterid montecarlo --json`).
///
/// The study runs on its own threads without the GIL while this thread looks for Python
/// signals every [`SIGNAL_POLL`]: Ctrl-C stops the study before its next realisations and
/// raises `KeyboardInterrupt` once the running ones end, its `__cause__` saying how many ran.
#[pyfunction]
#[pyo3(signature = (experiment, runs = 128, seed = DEFAULT_SEED, shard = None, method = None, threads = None))]
pub fn montecarlo(
    py: Python<'_>,
    experiment: &Experiment,
    runs: u64,
    seed: u64,
    shard: Option<(u64, u64)>,
    method: Option<&str>,
    threads: Option<usize>,
) -> PyResult<String> {
    let exp = experiment.for_method(method)?;
    let shard = shard
        .map(|(index, count)| {
            if count > 0 && index < count {
                Ok(Shard { index, count })
            } else {
                Err(value_error(format!(
                    "shard: expected (i, n) with 0 <= i < n, found ({index}, {count})"
                )))
            }
        })
        .transpose()?;
    let cancel = Arc::new(AtomicBool::new(false));
    let watch = Watch {
        cancel: Some(Arc::clone(&cancel)),
        ..Watch::none()
    };
    let j = std::thread::scope(|scope| -> PyResult<McJson> {
        let study = scope.spawn(|| {
            run_study(&exp, runs, seed, shard, threads, Keep::default(), &watch).map(|s| s.json)
        });
        while !study.is_finished() {
            py.detach(|| std::thread::sleep(SIGNAL_POLL));
            if let Err(signal) = py.check_signals() {
                cancel.store(true, Ordering::Relaxed);
                // The stopped study's report (how many realisations ran) is the signal's cause.
                if let Ok(Err(stopped)) = py.detach(|| study.join()) {
                    signal.set_cause(py, Some(PyRuntimeError::new_err(stopped.to_string())));
                }
                return Err(signal);
            }
        }
        study
            .join()
            .map_err(|_| PyRuntimeError::new_err("the Monte Carlo study's thread panicked"))?
            .map_err(value_error)
    })?;
    json_text(&j)
}

/// Merges shard results (JSON texts of sharded `montecarlo` results) into the result of the
/// unsharded study, checking that they belong together and are whole.
#[pyfunction]
pub fn merge(shards: Vec<String>) -> PyResult<String> {
    let parts = shards
        .iter()
        .enumerate()
        .map(|(i, text)| {
            serde_json::from_str::<McJson>(text)
                .map(|j| (format!("shard result {i}"), j))
                .map_err(|e| {
                    value_error(format!(
                        "shard result {i}: not a Monte Carlo shard result: {e}"
                    ))
                })
        })
        .collect::<PyResult<Vec<_>>>()?;
    json_text(&merge_values(parts).map_err(value_error)?)
}
