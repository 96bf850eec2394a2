//! `jitterid validate`: the study layer's validation, printed as JSON or written to `--out`
//! with the frequency-response CSV and the figures, all at once.

use super::fmt_num;
use crate::exit::Outcome;
use crate::output::OutputSet;
use crate::plots::{self, RecordPlot, ValidatePlots};
use jitterid::estimate::validation::CorrelationTest;
use jitterid_study::bode_inputs::bode_text;
use jitterid_study::error::StudyResult;
use jitterid_study::experiment::{self, Experiment, Purpose, ReadOptions};
use jitterid_study::fit::Structure;
use jitterid_study::study_err;
use jitterid_study::validate::{
    frequency_response, step, validate as run_validation, RecordReport,
    ValidateOptions as StudyValidateOptions, ValidatedRecord, Validation,
};
use jitterid_study::Watch;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Options of `validate`.
#[derive(Debug, Clone)]
pub struct ValidateOptions {
    /// The experiment file.
    pub experiment: PathBuf,
    /// How the experiment file is read (`--allow-paths-outside`, `--set`, the `[sampling]`
    /// keys a data file gives).
    pub read: ReadOptions,
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
    /// Print JSON instead of the table (the `--out` file is JSON either way).
    pub json: bool,
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
    let exp = experiment::read_edited(&o.experiment, Purpose::Estimate(None), &o.read)?;
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
        let text = bode_text(&v.fitted, &exp.grid, v.covariance.as_deref(), "--bode")?;
        outputs.file(path, text);
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
    let json = || -> StudyResult<String> {
        Ok(serde_json::to_string_pretty(&v.json()).map_err(|e| study_err!("JSON: {e}"))? + "\n")
    };
    let printed = match &o.out {
        Some(path) => {
            outputs.file(path, json()?);
            String::new()
        }
        None if o.json => json()?,
        None => validate_text(&exp, &v, o.model.as_deref()),
    };
    outputs.commit()?;
    Ok(Outcome::success(printed))
}

/// The human-readable report of `validate`: one column per record, one row per check, the
/// verdicts at the level beside the statistics they come from.
fn validate_text(exp: &Experiment, v: &Validation, model: Option<&Path>) -> String {
    let mut records = vec![("estimation", &v.estimation.report)];
    if let Some(r) = &v.validation {
        records.push(("validation", &r.report));
    }
    let mut rows: Vec<(String, Vec<String>)> = Vec::new();
    let mut row = |name: &str, cell: &dyn Fn(&RecordReport) -> String| {
        rows.push((name.into(), records.iter().map(|(_, r)| cell(r)).collect()));
    };
    row("record", &|r| r.record.clone());
    row("samples", &|r| r.samples.to_string());
    row("fit percent", &|r| format!("{:.2} %", r.fit_percent));
    row("whiteness", &|r| verdict(&r.whiteness));
    row("  statistic", &|r| statistic(&r.whiteness));
    row("  lags outside", &|r| lags(&r.whiteness));
    if exp.inputs.len() > 1 {
        // One block per input of a multi-input system, named by the input.
        for (i, c) in exp.inputs.iter().enumerate() {
            let test =
                move |r: &RecordReport| r.input_correlations.get(i).and_then(|x| x.test.clone());
            row(&format!("correlation with {}", c.name), &|r| {
                test(r).map_or("– (constant)".into(), |t| verdict(&t))
            });
            row("  statistic", &|r| {
                test(r).map_or("–".into(), |t| statistic(&t))
            });
            row("  lags outside", &|r| {
                test(r).map_or("–".into(), |t| lags(&t))
            });
        }
    } else {
        row("input correlation", &|r| {
            r.cross_correlation
                .as_ref()
                .map_or("– (no input)".into(), verdict)
        });
        row("  statistic", &|r| {
            r.cross_correlation.as_ref().map_or("–".into(), statistic)
        });
        row("  lags outside", &|r| {
            r.cross_correlation.as_ref().map_or("–".into(), lags)
        });
    }
    row("flatness", &|r| {
        r.flatness.map_or("–".into(), |f| format!("{f:.2}"))
    });
    row("removed directions", &|r| r.removed_directions.to_string());
    if v.validation
        .as_ref()
        .is_some_and(|r| r.report.initial_state.is_some())
    {
        row("initial state", &|r| {
            r.initial_state.as_ref().map_or("–".into(), |q| {
                q.iter().map(|x| fmt_num(*x)).collect::<Vec<_>>().join(", ")
            })
        });
    }
    let w0 = rows
        .iter()
        .map(|(n, _)| n.chars().count())
        .max()
        .unwrap_or(0);
    let widths: Vec<usize> = (0..records.len())
        .map(|i| {
            rows.iter()
                .map(|(_, c)| c[i].chars().count())
                .chain([records[i].0.len()])
                .max()
                .unwrap_or(0)
        })
        .collect();
    let mut out = String::new();
    let source = model.map_or_else(
        || format!("fitted here with {}", exp.estimate.method.as_str()),
        |m| format!("from {}", m.display()),
    );
    let _ = writeln!(
        out,
        "validation of the model {source} ({}), tests at level {}",
        exp.file, v.level
    );
    let mut line = format!("{:<w0$}", "");
    for ((role, _), w) in records.iter().zip(&widths) {
        let _ = write!(line, "  {role:<w$}");
    }
    let _ = writeln!(out, "{}", line.trim_end());
    for (name, cells) in &rows {
        let mut line = format!("{name:<w0$}");
        for (c, w) in cells.iter().zip(&widths) {
            let _ = write!(line, "  {c:<w$}");
        }
        let _ = writeln!(out, "{}", line.trim_end());
    }
    out
}

/// A test's verdict at its level.
fn verdict(t: &CorrelationTest) -> String {
    if t.passed { "passed" } else { "FAILED" }.into()
}

/// A portmanteau statistic with its law and p-value.
fn statistic(t: &CorrelationTest) -> String {
    let symbol = if t.test == "ljung-box" { "Q" } else { "S" };
    format!(
        "{symbol} = {:.2}, χ²({}), p = {:.3}",
        t.statistic, t.dof, t.p_value
    )
}

/// How many lags lie outside the bounds, of how many tested, and how many the per-lag rule
/// allows. An autocorrelation's lag 0 is 1 by construction and not tested.
fn lags(t: &CorrelationTest) -> String {
    let auto = t.test == "ljung-box";
    let tested = t.lags.iter().filter(|&&l| !(auto && l == 0)).count();
    format!(
        "{} of {tested} (±{:.3}; {} allowed)",
        t.outside, t.bound, t.allowed
    )
}
