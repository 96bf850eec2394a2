//! `jitterid fit`: the study layer's fit of one record, printed as a table or JSON, with its
//! figures.

use super::{fmt_num, name_width};
use crate::exit::{Outcome, Status};
use crate::output::OutputSet;
use crate::plots;
use crate::progress::Ticker;
use jitterid::estimate::Record;
use jitterid::signal::{AnySignal, Input};
use jitterid_study::error::StudyResult;
use jitterid_study::experiment::{Experiment, Method, Purpose, ReadOptions};
use jitterid_study::export;
use jitterid_study::fit::{self, fit_json_noted, fit_record, Fit};
use jitterid_study::joint::{fit_joint, read_records};
use jitterid_study::notes::{status, Notes};
use jitterid_study::records::{read_data, read_data_and_tau, read_experiment, read_input};
use jitterid_study::select::InitChoice;
use jitterid_study::study_err;
use jitterid_study::validate::{frequency_response, signal_covariance, step};
use jitterid_study::Watch;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Options of `fit`.
#[derive(Debug, Clone)]
pub struct FitRequest {
    /// The experiment file.
    pub experiment: PathBuf,
    /// How the experiment file is read (`--allow-paths-outside`, `--set`, the `[sampling]`
    /// keys a data file gives).
    pub read: ReadOptions,
    /// The data files: one record, or several fitted jointly.
    pub data: Vec<PathBuf>,
    /// The input file (for a random-binary experiment), default `<data>.input.csv`.
    pub input: Option<PathBuf>,
    /// Method override.
    pub method: Option<Method>,
    /// JSON output.
    pub json: bool,
    /// Plot directory.
    pub plot: Option<PathBuf>,
    /// The start: the experiment's values or the data-driven initializer's.
    pub init: InitChoice,
    /// Exit 0 even when the fit did not converge.
    pub accept_unconverged: bool,
    /// Iteration limit (overrides `[estimate] max_iterations`).
    pub max_iterations: Option<u64>,
    /// Wall-clock budget of the fit in seconds.
    pub time_limit: Option<f64>,
}

/// `jitterid fit`: the text to print, and exit status [`Status::NotConverged`] when the fit did
/// not converge (unless `accept_unconverged`).
pub fn fit(o: &FitRequest) -> StudyResult<Outcome> {
    let mut exp = read_experiment(
        &o.experiment,
        Purpose::Estimate(o.method),
        &o.read,
        o.max_iterations,
        o.time_limit,
    )?;
    exp.estimate.likelihood_start = o.init.likelihood_start();
    let method = exp.estimate.method;
    let data_file = match o.data.as_slice() {
        [one] => one,
        several => return fit_several(o, &exp, several),
    };
    // The jitter column is kept only for the figures that draw it.
    let data = if o.plot.is_some() {
        read_data_and_tau(&exp, data_file)?
    } else {
        read_data(&exp, data_file)?
    };
    let (name, tau) = (data.name, data.tau);
    // The one copy of the samples: the fit, the start and the figures share it.
    let record = fit::record(&exp.grid, data.y).map_err(|e| study_err!("{name}: {e}"))?;
    let inputs = read_input(&exp, data_file, o.input.as_deref())?;
    let mut signal = fit::signal_of(&exp, &inputs)?;
    if o.init == InitChoice::Auto {
        signal = fit::data_start(&exp, &signal, &inputs, record.y(), &name)?;
    }
    let ticker = Ticker::start(&format!("fitting with {}", method.as_str()));
    let watch = Watch {
        iterations: crate::progress::active_fit_hook(),
        ..Watch::none()
    };
    let f = fit_record(&exp, signal.clone(), &record, &watch)?;
    drop(ticker);
    let notes = Notes::of(&f, &exp.grid, record.y(), &inputs);

    if let Some(dir) = &o.plot {
        let data = Samples {
            record: &record,
            tau: tau.as_deref(),
        };
        // The figures draw one input (the first of several).
        write_fit_figures(dir, &exp, &f, &signal, inputs.first(), &data)?;
    }

    report(o, &exp, &f, &notes, &name)
}

/// The report of a fit, as JSON or as the table, with the exit status of its convergence.
fn report(
    o: &FitRequest,
    exp: &Experiment,
    f: &Fit,
    notes: &Notes,
    name: &str,
) -> StudyResult<Outcome> {
    let status = Status::of_convergence(f.converged, o.accept_unconverged);
    let text = if o.json {
        serde_json::to_string_pretty(&fit_json_noted(f, notes))
            .map_err(|e| study_err!("JSON: {e}"))?
            + "\n"
    } else {
        fit_text(exp, f, notes, name, o.plot.as_deref())
    };
    Ok(Outcome { text, status })
}

/// `jitterid fit` of several records at once (`--data` repeated): the joint fit of the study
/// layer, printed as for one record.
fn fit_several(o: &FitRequest, exp: &Experiment, data: &[PathBuf]) -> StudyResult<Outcome> {
    // What belongs to one record: its figures, its input file, its data-driven start.
    for (given, flag) in [
        (o.plot.is_some(), "--plot"),
        (o.input.is_some(), "--input"),
        (o.init == InitChoice::Auto, "--init auto"),
    ] {
        if given {
            return Err(study_err!(
                "{flag}: not with several --data files (it belongs to one record; each record's input is its side file or the experiment's)"
            ));
        }
    }
    let paths: Vec<&Path> = data.iter().map(PathBuf::as_path).collect();
    let records = read_records(exp, &paths)?;
    let ticker = Ticker::start(&format!(
        "fitting {} records with {}",
        records.len(),
        exp.estimate.method.as_str()
    ));
    let watch = Watch {
        iterations: crate::progress::active_fit_hook(),
        ..Watch::none()
    };
    let f = fit_joint(exp, &records, &watch)?;
    drop(ticker);
    let names: Vec<&str> = records.iter().map(|r| r.name.as_str()).collect();
    report(o, exp, &f, &Notes::default(), &names.join(" + "))
}

/// The samples of the fitted file, as the figures draw them.
struct Samples<'a> {
    /// The record that was fitted.
    record: &'a Record,
    /// The jitter of each sample, where the file has it.
    tau: Option<&'a [f64]>,
}

/// The figures of `fit --plot DIR`, written as one set into `DIR/fit/` (the naive LS fit beside
/// the method's; the fit's responses and bands from the study layer, as `validate` draws them).
fn write_fit_figures(
    dir: &Path,
    exp: &Experiment,
    f: &Fit,
    signal: &AnySignal,
    input: Option<&Input>,
    data: &Samples<'_>,
) -> StudyResult<()> {
    let method = exp.estimate.method;
    // The naive LS fit of the system for comparison (when the system is estimated).
    let ls = if exp.system.estimate && method != Method::LS {
        let mut ls_exp = exp.clone();
        ls_exp.jitter.estimate = false;
        ls_exp.noise.estimate = false;
        fit::structure(&ls_exp, signal.clone(), Method::LS)
            .ok()
            .and_then(|ls_s| {
                fit::fit(
                    &ls_exp,
                    &ls_s,
                    data.record,
                    Method::LS,
                    0,
                    false,
                    &Watch::none(),
                )
                .ok()
            })
            .map(|f| f.fitted)
    } else if method == Method::LS {
        Some(f.fitted.clone())
    } else {
        None
    };
    let main_label = if method == Method::LS {
        "naive LS"
    } else {
        method.as_str()
    };
    let cov = signal_covariance(f);
    // The response is drawn from 1/(NT) to the Nyquist frequency 1/(2T): a record of one or
    // two samples has no such band, and its figures go without the Bode diagram.
    let bode = if exp.grid.len() > 2 {
        frequency_response(&f.fitted, &exp.grid, cov.as_deref(), "--plot")?
    } else {
        None
    };
    let step = step(&f.fitted, &exp.grid, cov.as_deref())?;
    let figs = plots::fit_figures(&plots::FitPlots {
        exp,
        y: data.record.y(),
        input,
        file_model: signal,
        ls: if method == Method::LS {
            None
        } else {
            ls.as_ref()
        },
        main: (main_label, &f.fitted),
        tau: data.tau,
        bode: bode.as_deref(),
        step: step.as_deref(),
    })?;
    let mut outputs = OutputSet::new();
    outputs.figures(&dir.join(plots::FIT_DIR), figs, &plots::FIT_FIGURES);
    outputs.commit()?;
    Ok(())
}

/// The human-readable report of `fit`.
fn fit_text(exp: &Experiment, f: &Fit, notes: &Notes, name: &str, plot: Option<&Path>) -> String {
    let method = exp.estimate.method;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "fit of {} with {} ({})",
        name,
        method.as_str(),
        exp.file
    );
    let _ = writeln!(
        out,
        "{} after {} iterations, cost {:.6e}, noise std {} ({})",
        status(f),
        f.iterations,
        f.cost,
        fmt_num(f.noise_std),
        if exp.noise.estimate {
            "estimated"
        } else {
            "known"
        }
    );
    if let Some(cause) = notes.likely_cause(f) {
        let _ = writeln!(out, "{cause}");
    }
    let w = name_width(f.params.iter().map(|p| p.name.as_str()));
    let _ = writeln!(
        out,
        "{:<w$}  {:>14}  {:>14}",
        "parameter", "estimate", "std error"
    );
    for p in &f.params {
        let _ = writeln!(
            out,
            "{:<w$}  {:>14}  {:>14}",
            p.name,
            fmt_num(p.estimate),
            p.stderr.map_or("–".into(), fmt_num)
        );
    }
    // The exported model of a delayed system is two pieces: say how they combine.
    let tf = export::tf_of(&f.fitted.signal);
    if let Err(e) = &tf {
        let _ = writeln!(out, "model: not exported: {e}");
    }
    if let (Some(d), Ok(Some(_))) = (export::delay_of(&f.fitted.signal), &tf) {
        let _ = writeln!(
            out,
            "model: G(s) e^(-sD) with input delay D = {} s (the parameter delay; --json: model.zpk, model.tf, model.ss give G, model.delay gives D)",
            fmt_num(d)
        );
    }
    // Around an input level the model is driven by u − u0 (said once, below).
    let level = export::level_of(&f.fitted.signal);
    let (u, du) = match level {
        Some(_) => ("(u - u0)", "D(u - u0)"),
        None => ("u", "Du"),
    };
    if let (Some(y0), Ok(Some(_))) = (export::offset_of(&f.fitted.signal), &tf) {
        let _ = writeln!(
            out,
            "model: y = y0 + G(s){u} with output offset y0 = {} (--json: model.offset; model.ss is x' = Ax + B{u}, y = Cx + {du} + y0)",
            fmt_num(y0)
        );
    }
    if let (Some(u0), Ok(Some(_))) = (level, &tf) {
        let _ = writeln!(
            out,
            "model: y = G(s)(u - u0) with input level u0 = {} (--json: model.level; model.ss is x' = Ax + B(u - u0))",
            fmt_num(u0)
        );
    }
    for line in notes.lines() {
        let _ = writeln!(out, "{line}");
    }
    if let Some(dir) = plot {
        let _ = writeln!(
            out,
            "figures in {}: bode.svg and step.svg (rational systems), residuals.svg, spectrum.svg, moment.svg, jitter-pdf.svg",
            dir.join(plots::FIT_DIR).display()
        );
    }
    out
}
