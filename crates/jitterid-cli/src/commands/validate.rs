//! `jitterid validate`: the study layer's validation, printed as JSON or written to `--out`
//! with the frequency-response CSV and the figures, all at once.

use crate::exit::Outcome;
use crate::output::OutputSet;
use crate::plots::{self, RecordPlot, ValidatePlots};
use jitterid_study::error::StudyResult;
use jitterid_study::experiment::{self, Experiment, Paths, Purpose};
use jitterid_study::fit::Structure;
use jitterid_study::study_err;
use jitterid_study::validate::{
    bode_csv, frequency_response, step, validate as run_validation,
    ValidateOptions as StudyValidateOptions, ValidatedRecord,
};
use jitterid_study::Watch;
use std::path::{Path, PathBuf};

/// Options of `validate`.
#[derive(Debug, Clone)]
pub struct ValidateOptions {
    /// The experiment file.
    pub experiment: PathBuf,
    /// Where the files the experiment file names may be (`--allow-paths-outside`).
    pub paths: Paths,
    /// The estimation record.
    pub data: PathBuf,
    /// Its input realisation (a random-binary experiment), default `<data>.input.csv`.
    pub input: Option<PathBuf>,
    /// The level of the residual tests' verdicts.
    pub level: f64,
    /// A validation record (same `T`, its own input side file).
    pub validation: Option<PathBuf>,
    /// A `fit --json` output to validate instead of fitting.
    pub model: Option<PathBuf>,
    /// Write the frequency-response CSV here.
    pub bode: Option<PathBuf>,
    /// Write the JSON here instead of standard output.
    pub out: Option<PathBuf>,
    /// Write the SVG figures into this directory.
    pub plot: Option<PathBuf>,
}

/// What the figures draw of one record.
fn record_plot<'a>(role: &'a str, r: &'a ValidatedRecord) -> RecordPlot<'a> {
    RecordPlot {
        role,
        name: &r.report.record,
        grid: &r.grid,
        y: &r.y,
        expected: &r.expected,
        fit_percent: r.report.fit_percent,
        whiteness: &r.report.whiteness,
        cross: r.report.cross_correlation.as_ref(),
    }
}

/// Adds the figures of `--plot DIR` (into `DIR/validate/`) to the outputs (the Bode diagram on
/// the `--bode` CSV's frequencies; it and the step response only for a rational system).
fn stage_figures(
    dir: &Path,
    outputs: &mut OutputSet,
    exp: &Experiment,
    fitted: &Structure,
    cov: Option<&[Vec<f64>]>,
    estimation: RecordPlot<'_>,
    validation: Option<RecordPlot<'_>>,
) -> StudyResult<()> {
    let bode = frequency_response(fitted, &exp.grid, cov, "--plot")?;
    let step = step(fitted, &exp.grid, cov)?;
    let figs = plots::validate_figures(&ValidatePlots {
        title: exp.title.clone().unwrap_or_else(|| exp.file.clone()),
        estimation,
        validation,
        bode: bode.as_deref(),
        step: step.as_deref(),
    });
    outputs.figures(
        &dir.join(plots::VALIDATE_DIR),
        figs,
        &plots::VALIDATE_FIGURES,
    );
    Ok(())
}

/// `jitterid validate`: the JSON, printed or written to `--out` with the CSV and the figures,
/// all at once.
pub fn validate(o: &ValidateOptions) -> StudyResult<Outcome> {
    let exp = experiment::read_with(&o.experiment, Purpose::Estimate(None), o.paths)?;
    let v = run_validation(
        &exp,
        &o.data,
        &StudyValidateOptions {
            validation: o.validation.as_deref(),
            model: o.model.as_deref(),
            input: o.input.as_deref(),
            level: o.level,
        },
        &Watch::none(),
    )?;
    let mut outputs = OutputSet::new();
    if let Some(path) = &o.bode {
        let points = frequency_response(&v.fitted, &exp.grid, v.covariance.as_deref(), "--bode")?
            .ok_or_else(|| {
            study_err!("--bode: the system is not a rational transfer function")
        })?;
        outputs.file(path, bode_csv(&points));
    }
    if let Some(dir) = &o.plot {
        stage_figures(
            dir,
            &mut outputs,
            &exp,
            &v.fitted,
            v.covariance.as_deref(),
            record_plot("estimation", &v.estimation),
            v.validation.as_ref().map(|r| record_plot("validation", r)),
        )?;
    }
    let text = serde_json::to_string_pretty(&v.json()).map_err(|e| study_err!("JSON: {e}"))? + "\n";
    let printed = match &o.out {
        Some(path) => {
            outputs.file(path, text);
            String::new()
        }
        None => text,
    };
    outputs.commit()?;
    Ok(Outcome::success(printed))
}
