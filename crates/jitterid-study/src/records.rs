//! Measured records: a data file's samples checked against an experiment's grid, and the
//! record's input (the experiment's own, or a random-binary realisation's side file).

use crate::csvio;
use crate::error::StudyResult;
use crate::experiment::{self, Experiment, InputSpec, Purpose, ReadOptions};
use crate::inputs;
use crate::study_err;
use jitterid::signal::{Input, SampleGrid};
use std::path::{Path, PathBuf};

/// The side file holding the input of a simulated record: `data.csv` → `data.input.csv`.
pub fn input_side_file(data: &Path) -> PathBuf {
    csvio::input_side_file(data)
}

/// The samples of a data file, as a fit needs them: the column `y` (and the jitter `tau`,
/// where the file has one and it was asked for), checked against the experiment's grid.
#[derive(Debug, Clone, PartialEq)]
pub struct DataFile {
    /// The file's name, for messages.
    pub name: String,
    /// The samples, one per instant of the experiment's grid.
    pub y: Vec<f64>,
    /// The jitter of each sample (`tau`, written by `jitterid simulate`), when asked for and
    /// present.
    pub tau: Option<Vec<f64>>,
}

/// The samples `y` of a data file, checked against the experiment's grid (the row count, and
/// the columns `k` and `t` where present). The file is read row by row and only `y` is kept:
/// its text and its other columns are never held (a record of 10⁷ samples takes 80 MB, not
/// the half gigabyte of its text and table).
pub fn read_data(exp: &Experiment, path: &Path) -> StudyResult<DataFile> {
    read_data_columns(exp, path, false)
}

/// [`read_data`], keeping the column `tau` too where the file has one (for the figures of
/// the jitter).
pub fn read_data_and_tau(exp: &Experiment, path: &Path) -> StudyResult<DataFile> {
    read_data_columns(exp, path, true)
}

fn read_data_columns(exp: &Experiment, path: &Path, keep_tau: bool) -> StudyResult<DataFile> {
    let mut rows = csvio::open_rows(path, &path.display().to_string())?;
    let name = rows.name().to_string();
    // A missing `y` is reported after the rows are read, as a whole table's reading would:
    // a row that does not parse comes first.
    let iy = rows.index("y");
    let (ik, it) = (rows.index("k"), rows.index("t"));
    let itau = rows.index("tau").filter(|_| keep_tau);
    let n = exp.grid.len();
    let tol = 1e-6 * exp.grid.interval();
    // Reserved at the grid's length, so that a long record does not grow by doubling (up to
    // twice its size, at once, while it is copied).
    let mut y = Vec::with_capacity(n);
    let mut tau = itau.map(|_| Vec::with_capacity(n));
    // The first rows whose `k` and whose `t` are wrong: reported after the row count, which a
    // file of another experiment gets wrong first, and `k` before `t`.
    let (mut bad_k, mut bad_t): (Option<String>, Option<String>) = (None, None);
    let mut next_row = 0;
    while let Some((line, row)) = rows.next_row()? {
        let i = next_row;
        next_row += 1;
        let Some(iy) = iy.filter(|_| i < n) else {
            // Counted, not kept: the errors below say what is wrong.
            continue;
        };
        y.push(row[iy]);
        if let (Some(tau), Some(j)) = (tau.as_mut(), itau) {
            tau.push(row[j]);
        }
        if let Some(k) = ik
            .map(|j| row[j])
            .filter(|&k| bad_k.is_none() && k != i as f64)
        {
            bad_k = Some(format!(
                "{name}:{line}: column `k`: expected {i} (rows in order from 0), found {k}"
            ));
        }
        if let Some(t) = it
            .map(|j| row[j])
            .filter(|&t| bad_t.is_none() && (t - exp.grid.time(i)).abs() > tol + 1e-12 * t.abs())
        {
            bad_t = Some(format!(
                "{name}:{line}: column `t`: expected {} (t0 + kT of the experiment's [sampling]), found {t}",
                exp.grid.time(i)
            ));
        }
    }
    if rows.rows() == 0 {
        return Err(rows.no_rows_error().into());
    }
    rows.required("y")?;
    if rows.rows() != n {
        return Err(study_err!(
            "{name}: has {} data rows, expected {n} (the experiment's [sampling] samples)",
            rows.rows()
        ));
    }
    if let Some(m) = bad_k.or(bad_t) {
        return Err(study_err!("{m}"));
    }
    Ok(DataFile { name, y, tau })
}

/// The experiment of `path`, edited and read as `options` says, with the command line's
/// iteration and wall-clock budgets, where given.
pub fn read_experiment(
    path: &Path,
    purpose: Purpose,
    options: &ReadOptions,
    max_iterations: Option<u64>,
    time_limit: Option<f64>,
) -> StudyResult<Experiment> {
    let mut exp = experiment::read_edited(path, purpose, options)?;
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

/// The inputs of the record in `data`, in order: the experiment's known inputs, and for a
/// random-binary input the realisation in `input` (default: the side file of `data`), from
/// its column `u` for a single input or the column named after the input for several.
pub fn read_input(exp: &Experiment, data: &Path, input: Option<&Path>) -> StudyResult<Vec<Input>> {
    read_input_on(exp, data, input, &exp.grid)
}

/// [`read_input`] for a record on `grid` (a validation record has its own length and start).
pub fn read_input_on(
    exp: &Experiment,
    data: &Path,
    input: Option<&Path>,
    grid: &SampleGrid,
) -> StudyResult<Vec<Input>> {
    let mut table = None;
    let mut out = Vec::with_capacity(exp.inputs.len());
    for c in &exp.inputs {
        out.push(match &c.spec {
            InputSpec::Known(i) => i.clone(),
            InputSpec::RandomBinary(_) => {
                if table.is_none() {
                    let side = input.map_or_else(|| input_side_file(data), Path::to_path_buf);
                    if !side.exists() {
                        return Err(study_err!(
                            "{}: cannot read: file does not exist; the experiment's input is random-binary, so fit reads the input realisation written by `jitterid simulate` (or give --input FILE with columns {})",
                            side.display(),
                            side_columns(exp).join(",")
                        ));
                    }
                    table = Some(csvio::read(&side)?);
                }
                let t = table.as_ref().ok_or_else(|| study_err!("unreachable"))?;
                Input::Piecewise(inputs::piecewise_from_table(
                    t,
                    "t",
                    side_column(exp, &c.name),
                    grid,
                )?)
            }
        });
    }
    Ok(out)
}

/// The column of input `name` in a record's input file: `u` for the only input, its name when
/// there are several.
pub fn side_column<'a>(exp: &Experiment, name: &'a str) -> &'a str {
    if exp.inputs.len() == 1 {
        "u"
    } else {
        name
    }
}

/// The columns of a record's input file: `t`, then one per random-binary input.
pub fn side_columns(exp: &Experiment) -> Vec<String> {
    let mut cols = vec!["t".to_string()];
    cols.extend(
        exp.inputs
            .iter()
            .filter(|c| matches!(c.spec, InputSpec::RandomBinary(_)))
            .map(|c| side_column(exp, &c.name).to_string()),
    );
    cols
}
