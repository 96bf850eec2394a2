//! Monte Carlo studies and the merge of their shards, as `jitterid montecarlo --json` and
//! `jitterid merge --json` give them.

use crate::errors::{json_text, study_error, value_error};
use crate::experiment::Experiment;
use crate::watching::{run_watched, Reporter, Stopped};
use jitterid_study::merge::merge_values;
use jitterid_study::montecarlo::{run_study, Keep, McJson, Shard, DEFAULT_SEED};
use jitterid_study::{RunsDone, Watch};
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// Runs `runs` realisations of `experiment` with `method` (the file's if `None`) under master
/// `seed`, or shard `(index, count)` of them, on `threads` worker threads; returns the result
/// as JSON text (that of `jitterid montecarlo --json`).
///
/// The study runs on its own threads without the GIL while this thread looks for Python
/// signals every [`SIGNAL_POLL`](crate::watching::SIGNAL_POLL) and calls `progress(done,
/// total)` as realisations finish (`done` increasing, ending at `total`): Ctrl-C, or an exception raised by `progress`, stops the
/// study before its next realisations and is raised once the running ones end; a
/// `KeyboardInterrupt`'s `__cause__` says how many ran.
#[pyfunction]
#[pyo3(signature = (experiment, runs = 128, seed = DEFAULT_SEED, shard = None, method = None, threads = None, progress = None))]
#[allow(clippy::too_many_arguments)]
pub fn montecarlo(
    py: Python<'_>,
    experiment: &Experiment,
    runs: u64,
    seed: u64,
    shard: Option<(u64, u64)>,
    method: Option<&str>,
    threads: Option<usize>,
    progress: Option<Bound<'_, PyAny>>,
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
    if let Some(p) = &progress {
        if !p.is_callable() {
            return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                "progress: expected a callable progress(done, total) or None, found {}",
                p.get_type().name()?
            )));
        }
    }
    let cancel = Arc::new(AtomicBool::new(false));
    let watched = progress.is_some();
    let work = |reporter: Reporter<RunsDone>| {
        let watch = Watch {
            cancel: Some(Arc::clone(&cancel)),
            runs: watched.then(|| {
                Arc::new(move |done: RunsDone| reporter.report(done))
                    as Arc<dyn Fn(RunsDone) + Send + Sync>
            }),
            ..Watch::none()
        };
        run_study(&exp, runs, seed, shard, threads, Keep::default(), &watch).map(|s| s.json)
    };
    // Worker threads count their realisations in one order and may report them in another:
    // a count below one already passed on is not passed on again, so the callback sees
    // increasing counts, ending at the total.
    let mut reported = 0;
    let on_event = |done: RunsDone| -> PyResult<()> {
        if let Some(p) = &progress {
            if done.done > reported {
                reported = done.done;
                p.call1((done.done, done.total))?;
            }
        }
        Ok(())
    };
    let j = match run_watched(py, &cancel, work, on_event) {
        Ok(Some(study)) => study.map_err(study_error)?,
        Ok(None) => {
            return Err(PyRuntimeError::new_err(
                "the Monte Carlo study's thread panicked",
            ))
        }
        Err(Stopped { error, outcome }) => {
            // The stopped study's report (how many realisations ran) is the signal's cause.
            if let Some(Err(stopped)) = outcome {
                if error.cause(py).is_none() {
                    error.set_cause(py, Some(PyRuntimeError::new_err(stopped.to_string())));
                }
            }
            return Err(error);
        }
    };
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
