//! `jitterid simulate`: one record of the experiment's truth, written as CSV with the input's
//! side file.

use crate::output::{self, OutputSet};
use jitterid::signal::{Input, PiecewiseConstant};
use jitterid_study::csvio::{self, Column};
use jitterid_study::error::StudyResult;
use jitterid_study::experiment::{self, InputSpec, Purpose, ReadOptions};
use jitterid_study::records::{input_side_file, side_column};
use jitterid_study::simulate::{simulate_data, SimulatedData};
use std::fmt::Write as _;
use std::path::PathBuf;

/// Options of `simulate`.
#[derive(Debug, Clone)]
pub struct SimulateOptions {
    /// The experiment file.
    pub experiment: PathBuf,
    /// How the experiment file is read (`--allow-paths-outside`, `--set`, the `[sampling]`
    /// keys a data file gives).
    pub read: ReadOptions,
    /// Master seed.
    pub seed: u64,
    /// Realisation index (the same record as Monte Carlo run `run`).
    pub run: u64,
    /// The data file to write.
    pub out: PathBuf,
    /// Whether to write the drawn jitter and noise.
    pub truth: bool,
}

/// `jitterid simulate`: one record of the experiment's truth. Returns the report line.
pub fn simulate(o: &SimulateOptions) -> StudyResult<String> {
    let exp = experiment::read_edited(&o.experiment, Purpose::Simulate, &o.read)?;
    let SimulatedData {
        t,
        y,
        u,
        tau,
        v,
        inputs,
    } = simulate_data(&exp, o.seed, o.run)?;
    let n = exp.grid.len();
    let k: Vec<usize> = (0..n).collect();
    let mut cols = vec![
        Column::Index("k", &k),
        Column::Real("t", &t),
        Column::Real("y", &y),
    ];
    // One input is the column `u`; several are named after their inputs.
    for (c, u) in exp.inputs.iter().zip(&u) {
        cols.push(Column::Real(side_column(&exp, &c.name), u));
    }
    if o.truth {
        cols.push(Column::Real("tau", &tau));
        cols.push(Column::Real("v", &v));
    }
    let mut outputs = OutputSet::new();
    outputs.file(&o.out, csvio::format(&cols));
    let mut report = format!(
        "wrote {}: {n} samples ({})",
        o.out.display(),
        cols.iter()
            .map(|c| match c {
                Column::Index(n, _) | Column::Real(n, _) => *n,
            })
            .collect::<Vec<_>>()
            .join(", ")
    );
    // The realisations of the random-binary inputs, which the experiment cannot rebuild.
    let (names, drawn): (Vec<&str>, Vec<&PiecewiseConstant>) = exp
        .inputs
        .iter()
        .zip(&inputs)
        .filter_map(|(c, u)| match (&c.spec, u) {
            (InputSpec::RandomBinary(_), Input::Piecewise(p)) => {
                Some((side_column(&exp, &c.name), p))
            }
            _ => None,
        })
        .unzip();
    if !drawn.is_empty() {
        if output::writes_through(&o.out) {
            report.push_str(
                "; the input realisation is not written (a device or FIFO has no side file)",
            );
        } else {
            let side = input_side_file(&o.out);
            if let [p] = drawn.as_slice() {
                outputs.file(&side, csvio::input_to_csv(p));
                let _ = write!(
                    report,
                    "; {}: the input's {} switch times and levels",
                    side.display(),
                    p.edges().len()
                );
            } else {
                outputs.file(&side, csvio::inputs_to_csv(&names, &drawn));
                let _ = write!(
                    report,
                    "; {}: the switch times and levels of the inputs {}",
                    side.display(),
                    names.join(", ")
                );
            }
        }
    }
    outputs.commit()?;
    Ok(report)
}
