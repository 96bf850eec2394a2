//! `jitterid design`: the study layer's design search ([`jitterid_study::design`]) on the
//! experiment's `[design]` section, printed as a table or JSON.
//!
//! The front end parses `--criterion` and prints; the prediction, the search and every
//! judgement of the ranges are the library's.

use crate::commands::{fmt_num, name_width};
use crate::exit::Outcome;
use crate::output::OutputSet;
use crate::progress::DesignTicker;
use jitterid_study::design::{
    design as run_design, designed_input, jitter_blind, Design, DesignReport, Plan,
};
use jitterid_study::error::StudyResult;
use jitterid_study::experiment::{
    budget_edit, dac_rate_edit, derived_edit, DesignCriterion, ReadOptions,
};
use jitterid_study::study_err;
use std::fmt::Write as _;
use std::path::PathBuf;

/// Options of `design`.
#[derive(Debug, Clone)]
pub struct DesignOptions {
    /// The experiment file, with a `[design]` section.
    pub experiment: PathBuf,
    /// How the experiment file is read (`--allow-paths-outside`, `--set`).
    pub read: ReadOptions,
    /// The criterion (`d`, `a`, `param:NAME`), replacing `[design] criterion`.
    pub criterion: Option<String>,
    /// The budget (`duration=SECONDS` or `samples=N`), replacing `[design] duration`/`samples`.
    pub budget: Option<String>,
    /// The derived quantities reported (`--derived`), replacing `[design] derived`.
    pub derived: Option<Vec<String>>,
    /// Also design with the jitter ignored, evaluated under the true prior.
    pub jitter_blind: bool,
    /// Write the designed input (CSV) to this file and the experiment reading it beside it
    /// (the same name with `.toml`).
    pub write_input: Option<PathBuf>,
    /// The DAC rate (Hz) of a designed multisine's sample sequence, replacing `[design]
    /// dac_rate`.
    pub dac_rate: Option<f64>,
    /// Print JSON instead of a table.
    pub json: bool,
    /// Write the JSON to this file instead of standard output.
    pub out: Option<PathBuf>,
}

fn design_text(d: &Design) -> String {
    let mut s = String::new();
    if let Some(m) = d.mean_dwell {
        let _ = write!(s, "mean_dwell = {} s, ", fmt_num(m));
    }
    if let (Some(low), Some(high)) = (d.low, d.high) {
        let _ = write!(s, "low = {}, high = {}, ", fmt_num(low), fmt_num(high));
    }
    let _ = write!(
        s,
        "interval = {} s, samples = {}",
        fmt_num(d.interval),
        d.samples
    );
    if let Some(m) = &d.multisine {
        let _ = write!(
            s,
            ", multisine of {} tones: power = {}, crest factor = {}, peak = {}",
            m.frequencies.len(),
            fmt_num(m.power),
            fmt_num(m.crest_factor),
            fmt_num(m.peak())
        );
    }
    s
}

/// The tones of a design's multisine, one line each, indented.
fn tones_text(d: &Design) -> String {
    let mut s = String::new();
    if let Some(m) = &d.multisine {
        let _ = writeln!(
            s,
            "  {:>14}  {:>14}  {:>14}",
            "frequency (Hz)", "amplitude", "phase (rad)"
        );
        for t in m.tones() {
            let _ = writeln!(
                s,
                "  {:>14}  {:>14}  {:>14}",
                fmt_num(t.frequency),
                fmt_num(t.amplitude),
                fmt_num(t.phase)
            );
        }
    }
    s
}

/// `jitterid design`.
pub fn design(o: &DesignOptions) -> StudyResult<Outcome> {
    let criterion = o
        .criterion
        .as_deref()
        .map(DesignCriterion::parse)
        .transpose()
        .map_err(|e| study_err!("--criterion: {e}"))?;
    // The input file's name and the experiment's path, checked before the search.
    let written_names = match &o.write_input {
        None => None,
        Some(path) => {
            let experiment = path.with_extension("toml");
            match path.file_name().and_then(|n| n.to_str()) {
                Some(n) if experiment != *path => Some((n.to_string(), experiment)),
                _ => {
                    return Err(study_err!(
                        "--write-input {}: expected a CSV file name (the experiment is written beside it with the extension .toml)",
                        path.display()
                    ))
                }
            }
        }
    };
    let mut read = o.read.clone();
    if let Some(b) = &o.budget {
        read.overrides.push(budget_edit(b)?);
    }
    if let Some(names) = &o.derived {
        let origin = format!("--derived {}", names.join(","));
        read.overrides.push(derived_edit(names, origin));
    }
    if let Some(rate) = o.dac_rate {
        read.overrides.push(dac_rate_edit(rate));
    }
    // The spinner watches the searches (the jitter-blind one too) and is cleared before
    // anything is printed; the numbers do not depend on it.
    let ticker = DesignTicker::start();
    let plan = Plan::read(&o.experiment, &read)?.with_observer(ticker.observer());
    let mut report = run_design(&plan, criterion.as_ref())?;
    if o.jitter_blind {
        report.jitter_blind = Some(jitter_blind(&plan, &report.criterion)?);
    }
    drop(ticker);
    let mut outputs = OutputSet::new();
    let mut wrote = Vec::new();
    if let (Some(path), Some((name, experiment))) = (&o.write_input, &written_names) {
        let written = designed_input(&plan, &report.design, name)?;
        outputs.file(path, written.csv);
        outputs.file(experiment, written.experiment);
        wrote.push(path.display().to_string());
        wrote.push(experiment.display().to_string());
    }
    let text = if o.json || o.out.is_some() {
        serde_json::to_string_pretty(&report.json()).map_err(|e| study_err!("JSON: {e}"))? + "\n"
    } else {
        table(&plan, &report)
    };
    let text = match &o.out {
        Some(path) => {
            outputs.file(path, text);
            wrote.insert(0, path.display().to_string());
            String::new()
        }
        None => text,
    };
    outputs.commit()?;
    // Stdout holds the JSON alone when it is printed; what was written goes after a table.
    let notes = if wrote.is_empty() || (o.json && o.out.is_none()) {
        String::new()
    } else {
        format!("wrote {}\n", wrote.join(", "))
    };
    Ok(Outcome::success(text + &notes))
}

/// The table of a design report.
fn table(plan: &Plan, report: &DesignReport) -> String {
    let p = &report.prediction;
    let mut out = format!(
        "design of {} for {} (criterion {}, {} input draw{} per design, {} designs evaluated)\n",
        plan.baseline.file,
        report.estimator.as_str(),
        report.criterion,
        report.draws,
        if report.draws == 1 { "" } else { "s" },
        report.evaluations
    );
    let _ = writeln!(out, "designed: {}", design_text(&report.design));
    out += &tones_text(&report.design);
    let _ = writeln!(out, "baseline: {}", design_text(&report.baseline));
    out += &tones_text(&report.baseline);
    let blind = report.jitter_blind.as_ref();
    if let Some(b) = blind {
        let _ = writeln!(
            out,
            "jitter-blind: {} (its stds under the true, jittered prior)",
            design_text(&b.design)
        );
    }
    // Under [design] jitter_exponent each design has its own jitter: say which.
    if let Some(designed) = report.jitter_std_of(p) {
        let at = |x: Option<f64>| x.map_or("–".into(), fmt_num);
        let base = report.baseline_jitter_std();
        let blind_std = blind.map_or(String::new(), |b| {
            format!(
                ", jitter-blind {} s",
                at(report.jitter_std_of(&b.prediction))
            )
        });
        let _ = writeln!(
            out,
            "jitter σ at each design's interval (jitter_exponent {}): designed {} s, baseline {} s{blind_std}",
            report.jitter_exponent,
            fmt_num(designed),
            at(base)
        );
    }
    let derived_names: Vec<String> = report.derived_of(p).into_iter().map(|d| d.name).collect();
    let w = name_width(p.names.iter().chain(&derived_names).map(String::as_str));
    let blind_head = if blind.is_some() {
        format!("  {:>14}", "jitter-blind")
    } else {
        String::new()
    };
    let _ = writeln!(
        out,
        "{:<w$}  {:>14}  {:>14}{blind_head}",
        "parameter", "designed std", "baseline std"
    );
    let base = report.baseline_prediction.as_ref().ok();
    let cell = |x: Option<f64>| x.map_or("–".into(), fmt_num);
    let blind_cell = |x: Option<f64>| blind.map_or(String::new(), |_| format!("  {:>14}", cell(x)));
    for (i, name) in p.names.iter().enumerate() {
        let b = base.and_then(|(bp, _)| bp.std.get(i).copied());
        let j = blind.and_then(|b| b.prediction.std_of(name));
        let _ = writeln!(
            out,
            "{name:<w$}  {:>14}  {:>14}{}",
            fmt_num(p.std[i]),
            cell(b),
            blind_cell(j)
        );
    }
    // Derived quantities by the delta method, each design's own.
    let named = |list: Vec<jitterid_study::design::PredictedStd>, name: &str| {
        list.into_iter()
            .find(|d| d.name == name)
            .and_then(|d| d.std)
    };
    for d in report.derived_of(p) {
        let b = base.and_then(|(bp, _)| named(report.derived_of(bp), &d.name));
        let j = blind.and_then(|bl| named(report.derived_of(&bl.prediction), &d.name));
        let _ = writeln!(
            out,
            "{:<w$}  {:>14}  {:>14}{}",
            d.name,
            cell(d.std),
            cell(b),
            blind_cell(j)
        );
    }
    let _ = writeln!(
        out,
        "{:<w$}  {:>14}  {:>14}{}",
        "criterion",
        fmt_num(report.value),
        cell(base.map(|(_, v)| *v)),
        blind_cell(blind.map(|b| b.value))
    );
    if let Some(p) = &report.prior {
        let _ = writeln!(
            out,
            "robust: the criterion is the mean over {} prior draws (system parameters ±{} relative, jitter σ ±{} relative); the stds are at the prior's values",
            p.draws,
            fmt_num(p.system),
            fmt_num(p.jitter)
        );
    }
    if let Err(why) = &report.baseline_prediction {
        let _ = writeln!(out, "baseline not predicted: {why}");
    }
    out
}
