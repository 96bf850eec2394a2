//! `jitterid design`: the study layer's design search ([`jitterid_study::design`]) on the
//! experiment's `[design]` section, printed as a table or JSON.
//!
//! The front end parses `--criterion` and prints; the prediction, the search and every
//! judgement of the ranges are the library's.

use crate::commands::{fmt_num, name_width};
use crate::exit::Outcome;
use crate::output::OutputSet;
use jitterid_study::design::{design as run_design, Design, Plan};
use jitterid_study::error::StudyResult;
use jitterid_study::experiment::{DesignCriterion, ReadOptions};
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
    let _ = write!(
        s,
        "interval = {} s, samples = {}",
        fmt_num(d.interval),
        d.samples
    );
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
    let plan = Plan::read(&o.experiment, &o.read)?;
    let report = run_design(&plan, criterion.as_ref())?;
    if o.json || o.out.is_some() {
        let text = serde_json::to_string_pretty(&report.json())
            .map_err(|e| study_err!("JSON: {e}"))?
            + "\n";
        if let Some(path) = &o.out {
            let mut outputs = OutputSet::new();
            outputs.file(path, text);
            outputs.commit()?;
            return Ok(Outcome::success(format!("wrote {}\n", path.display())));
        }
        return Ok(Outcome::success(text));
    }
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
    let _ = writeln!(out, "baseline: {}", design_text(&report.baseline));
    let w = name_width(p.names.iter().map(String::as_str));
    let _ = writeln!(
        out,
        "{:<w$}  {:>14}  {:>14}",
        "parameter", "designed std", "baseline std"
    );
    let base = report.baseline_prediction.as_ref().ok();
    for (i, name) in p.names.iter().enumerate() {
        let b = base.and_then(|(bp, _)| bp.std.get(i).copied());
        let _ = writeln!(
            out,
            "{name:<w$}  {:>14}  {:>14}",
            fmt_num(p.std[i]),
            b.map_or("–".into(), fmt_num)
        );
    }
    let _ = writeln!(
        out,
        "{:<w$}  {:>14}  {:>14}",
        "criterion",
        fmt_num(report.value),
        base.map_or("–".into(), |(_, v)| fmt_num(*v))
    );
    if let Err(why) = &report.baseline_prediction {
        let _ = writeln!(out, "baseline not predicted: {why}");
    }
    Ok(Outcome::success(out))
}
