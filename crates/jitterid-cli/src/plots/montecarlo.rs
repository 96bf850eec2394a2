//! The figures of `montecarlo --plot`: histograms of the estimates, the Bode diagrams and jitter
//! densities of the fits.

use super::{
    bode_figure, bode_points, frequency_response, log_band, moment_figure, pdf_panel, pdf_series,
    tau_axis,
};

use crate::svg::{self, figure, Panel, Series, Style, BLACK, BLUE, RED};
use jitterid::jitter::AnyJitter;
use jitterid::signal::AnySignal;
use jitterid_study::experiment::Experiment;
use jitterid_study::fit::Structure;

/// Everything `montecarlo --plot` draws from.
pub struct McPlots<'a> {
    /// The experiment.
    pub exp: &'a Experiment,
    /// Method label.
    pub method: &'a str,
    /// Parameter names.
    pub names: &'a [String],
    /// True values.
    pub truth: &'a [Option<f64>],
    /// Estimates of the converged runs, one vector per run.
    pub values: Vec<&'a [f64]>,
    /// The true signal of the first realisation (for the first moment).
    pub true_signal: &'a AnySignal,
    /// Fitted structures of some of the first runs.
    pub fitted: Vec<&'a Structure>,
}

/// The `montecarlo` figures.
pub fn montecarlo_figures(p: &McPlots<'_>) -> Vec<(String, String)> {
    let exp = p.exp;
    let title = exp.title.clone().unwrap_or_else(|| exp.file.clone());
    let mut out = vec![("histograms.svg".to_string(), mc_histograms(p, &title))];
    if exp.system.estimate && frequency_response(p.true_signal, 0.0).is_some() {
        out.push(("bode.svg".to_string(), mc_bode(p, &title)));
    }
    if exp.jitter.estimate {
        out.push(("jitter-pdf.svg".to_string(), mc_jitter(p, &title)));
    }
    out.push((
        "moment.svg".to_string(),
        moment_figure(
            &format!("{title} (realisation 0)"),
            &exp.grid,
            p.true_signal,
            &exp.jitter.truth,
            "true",
            None,
        ),
    ));
    out
}

/// One histogram panel per parameter, with the true value and the mean.
fn mc_histograms(p: &McPlots<'_>, title: &str) -> String {
    let panels: Vec<Panel> = p
        .names
        .iter()
        .enumerate()
        .map(|(i, name)| {
            let v: Vec<f64> = p.values.iter().filter_map(|r| r.get(i).copied()).collect();
            let (bars, width) = svg::histogram(&v);
            let finite: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
            let mean = finite.iter().sum::<f64>() / finite.len().max(1) as f64;
            let mut series = vec![Series {
                label: format!("{} runs", finite.len()),
                color: BLUE,
                opacity: 0.55,
                style: Style::Bars { width },
                points: bars,
            }];
            if let Some(t) = p.truth.get(i).copied().flatten() {
                series.push(Series {
                    label: "true".into(),
                    color: BLACK,
                    opacity: 1.0,
                    style: Style::VRule { dash: None },
                    points: vec![(t, 0.0)],
                });
            }
            if !finite.is_empty() {
                series.push(Series {
                    label: "mean".into(),
                    color: RED,
                    opacity: 1.0,
                    style: Style::VRule { dash: Some("6 4") },
                    points: vec![(mean, 0.0)],
                });
            }
            Panel {
                title: name.clone(),
                xlabel: "estimate".into(),
                ylabel: "count".into(),
                y_from_zero: true,
                series,
                ..Default::default()
            }
        })
        .collect();
    let cols = if panels.len() <= 1 { 1 } else { 2 };
    figure(
        &format!(
            "Monte Carlo estimates ({}, {} converged runs)",
            p.method,
            p.values.len()
        ),
        title,
        &panels,
        cols,
    )
}

/// The label of the first of many faint estimate curves (the others stay out of the legend).
fn first_label(k: usize, method: &str) -> String {
    if k == 0 {
        format!("{method} estimates")
    } else {
        String::new()
    }
}

/// The true Bode diagram over those of the kept fits.
fn mc_bode(p: &McPlots<'_>, title: &str) -> String {
    let fs = log_band(&p.exp.grid);
    let mut mag = Vec::new();
    let mut ph = Vec::new();
    for (k, s) in p.fitted.iter().enumerate() {
        if let Some((m, a)) = bode_points(&s.signal, &fs) {
            let label = first_label(k, p.method);
            mag.push(
                Series::line(&label, BLUE, m)
                    .with_opacity(0.3)
                    .with_width(1.0),
            );
            ph.push(
                Series::line(&label, BLUE, a)
                    .with_opacity(0.3)
                    .with_width(1.0),
            );
        }
    }
    if let Some((m, a)) = bode_points(p.true_signal, &fs) {
        mag.push(Series::dashed("true", BLACK, m));
        ph.push(Series::dashed("true", BLACK, a));
    }
    let heading = format!(
        "Bode diagram, true and estimated ({} runs shown)",
        p.fitted.len()
    );
    bode_figure(&heading, title, mag, ph)
}

/// The true jitter density over those of the kept fits.
fn mc_jitter(p: &McPlots<'_>, title: &str) -> String {
    let truth = &p.exp.jitter.truth;
    let est: Vec<&AnyJitter> = p.fitted.iter().map(|s| &s.jitter).collect();
    let mut all: Vec<&AnyJitter> = vec![truth];
    all.extend(est.iter().copied());
    let taus = tau_axis(&all, &[]);
    let mut series = Vec::new();
    for (k, j) in est.iter().enumerate() {
        for s in pdf_series(&first_label(k, p.method), BLUE, j, &taus, false) {
            series.push(s.with_opacity(0.3).with_width(1.0));
        }
    }
    series.extend(pdf_series("true", BLACK, truth, &taus, true));
    figure(
        &format!(
            "Jitter density, true and estimated ({} runs shown)",
            est.len()
        ),
        title,
        &[pdf_panel(series, truth, &taus)],
        1,
    )
}
