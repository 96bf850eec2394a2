//! Measured records: a data file's samples checked against an experiment's grid, and the
//! record's input (the experiment's own, or a random-binary realisation's side file).

use crate::csvio;
use crate::error::StudyResult;
use crate::experiment::{self, Experiment, InputSpec, Paths, Purpose};
use crate::inputs;
use crate::study_err;
use jitterid::signal::Input;
use std::path::{Path, PathBuf};

/// The side file holding the input of a simulated record: `data.csv` → `data.input.csv`.
pub fn input_side_file(data: &Path) -> PathBuf {
    csvio::input_side_file(data)
}

/// The samples of a data file, checked against the experiment's grid.
pub fn read_data(exp: &Experiment, path: &Path) -> StudyResult<csvio::Table> {
    let table = csvio::read(path)?;
    let y = table.column("y")?;
    let n = exp.grid.len();
    if y.len() != n {
        return Err(study_err!(
            "{}: has {} data rows, expected {n} (the experiment's [sampling] samples)",
            table.name,
            y.len()
        ));
    }
    if let Some(k) = table.optional("k") {
        if let Some(i) = (0..n).find(|&i| k[i] != i as f64) {
            return Err(study_err!(
                "{}:{}: column `k`: expected {i} (rows in order from 0), found {}",
                table.name,
                table.lines[i],
                k[i]
            ));
        }
    }
    if let Some(t) = table.optional("t") {
        let tol = 1e-6 * exp.grid.interval();
        if let Some(i) =
            (0..n).find(|&i| (t[i] - exp.grid.time(i)).abs() > tol + 1e-12 * t[i].abs())
        {
            return Err(study_err!(
                "{}:{}: column `t`: expected {} (t0 + kT of the experiment's [sampling]), found {}",
                table.name,
                table.lines[i],
                exp.grid.time(i),
                t[i]
            ));
        }
    }
    Ok(table)
}

/// The experiment of `path` with the command line's iteration and wall-clock budgets, where
/// given; `paths` says where the files it names may be.
pub fn read_experiment(
    path: &Path,
    purpose: Purpose,
    paths: Paths,
    max_iterations: Option<u64>,
    time_limit: Option<f64>,
) -> StudyResult<Experiment> {
    let mut exp = experiment::read_with(path, purpose, paths)?;
    if let Some(t) = time_limit {
        if !(t.is_finite() && t >= 0.0) {
            return Err(study_err!(
                "--time-limit: expected a number of seconds >= 0, found {t}"
            ));
        }
        exp.estimate.max_seconds = Some(t);
    }
    if let Some(n) = max_iterations {
        if n == 0 {
            return Err(study_err!(
                "--max-iterations: expected at least 1 iteration, found 0"
            ));
        }
        exp.estimate.max_iterations = Some(n);
    }
    Ok(exp)
}

/// The input of the record in `data`: the experiment's known input, or for a random-binary
/// experiment the realisation in `input` (default: the side file of `data`).
pub fn read_input(
    exp: &Experiment,
    data: &Path,
    input: Option<&Path>,
) -> StudyResult<Option<Input>> {
    Ok(match &exp.input {
        InputSpec::None => None,
        InputSpec::Known(i) => Some(i.clone()),
        InputSpec::RandomBinary(_) => {
            let side = input.map_or_else(|| input_side_file(data), Path::to_path_buf);
            if !side.exists() {
                return Err(study_err!(
                    "{}: cannot read: file does not exist; the experiment's input is random-binary, so fit reads the input realisation written by `jitterid simulate` (or give --input FILE with columns t,u)",
                    side.display()
                ));
            }
            let t = csvio::read(&side)?;
            Some(Input::Piecewise(inputs::piecewise_from_table(
                &t, "t", "u", &exp.grid,
            )?))
        }
    })
}
