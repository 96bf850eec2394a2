//! The figures of `validate --plot`: the records against the model, the correlation tests, the Bode
//! diagram and the step response with their bands.

use super::response;
use super::{samples_series, too_many_markers};
use crate::svg::{figure, Panel, Series, Style, BLUE, GREY, RED};
use jitterid::estimate::validation::{BodePoint, CorrelationTest, StepPoint};
use jitterid::signal::SampleGrid;

/// One record of `validate --plot`: its samples, the model's expected samples and the checks.
pub struct RecordPlot<'a> {
    /// Which record (`estimation` or `validation`).
    pub role: &'a str,
    /// The record's file.
    pub name: &'a str,
    /// The record's sampling grid.
    pub grid: &'a SampleGrid,
    /// The samples `y_k`.
    pub y: &'a [f64],
    /// The model's expected samples `m_k`.
    pub expected: &'a [f64],
    /// Normalised fit of `m_k` to `y_k`, in percent.
    pub fit_percent: f64,
    /// Autocorrelation of the standardised residuals.
    pub whiteness: &'a CorrelationTest,
    /// Their cross-correlation with the input, if there is one.
    pub cross: Option<&'a CorrelationTest>,
}

/// Everything `validate --plot` draws from.
pub struct ValidatePlots<'a> {
    /// The experiment's title (or file).
    pub title: String,
    /// The estimation record.
    pub estimation: RecordPlot<'a>,
    /// The validation record, if given.
    pub validation: Option<RecordPlot<'a>>,
    /// The fitted system's frequency response (the `--bode` CSV's points), if rational.
    pub bode: Option<&'a [BodePoint]>,
    /// Its unit-step response, if rational.
    pub step: Option<&'a [StepPoint]>,
}

/// The `validate` figures: model vs data in time, residual correlations, and for a rational
/// system the Bode diagram and the step response with their bands.
pub fn validate_figures(p: &ValidatePlots<'_>) -> Vec<(String, String)> {
    let records: Vec<&RecordPlot<'_>> = std::iter::once(&p.estimation)
        .chain(p.validation.as_ref())
        .collect();
    let mut out = vec![
        ("time.svg".to_string(), time_figure(&records, &p.title)),
        (
            "correlations.svg".to_string(),
            correlation_figure(&records, &p.title),
        ),
    ];
    if let Some(b) = p.bode {
        let heading = "Bode diagram of the fitted system";
        let fig = response::bode_figure(("fitted model", b), &[], &[], heading, &p.title);
        out.push(("bode.svg".to_string(), fig));
    }
    if let Some(s) = p.step {
        let heading = "Unit-step response of the fitted system";
        let fig = response::step_figure(("fitted model", s), &[], heading, &p.title);
        out.push(("step.svg".to_string(), fig));
    }
    out
}

/// How many samples the zoomed panel of a long record shows, as markers.
const ZOOM: usize = 120;

/// `y_k` as points and `m_k` as a line against time, one panel per record; a record too long
/// for markers is drawn as its envelope, with a second panel of its first [`ZOOM`] samples.
fn time_figure(records: &[&RecordPlot<'_>], title: &str) -> String {
    let mut panels = Vec::new();
    for r in records {
        let t: Vec<f64> = r.grid.times().collect();
        panels.push(time_panel(
            r,
            &t,
            format!("{} record {}: fit {:.1} %", r.role, r.name, r.fit_percent),
        ));
        if too_many_markers(r.y.len()) && r.y.len() > ZOOM {
            panels.push(time_panel(
                &RecordPlot {
                    y: &r.y[..ZOOM],
                    expected: &r.expected[..ZOOM.min(r.expected.len())],
                    ..**r
                },
                &t[..ZOOM],
                format!("{} record {}: its first {ZOOM} samples", r.role, r.name),
            ));
        }
    }
    figure(
        "Model vs data: samples y_k and the model's expected samples m_k",
        title,
        &panels,
        1,
    )
}

/// One panel of `y_k` (markers, or their envelope when many) and `m_k` (a line) at times `t`.
fn time_panel(r: &RecordPlot<'_>, t: &[f64], heading: String) -> Panel {
    let pts = |v: &[f64]| t.iter().copied().zip(v.iter().copied()).collect();
    let dense = r.y.len() > 400;
    // Room above the data for the legend, which would hide samples in any corner.
    let (lo, hi) =
        r.y.iter()
            .chain(r.expected)
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
    let span = if hi > lo { hi - lo } else { 1.0 };
    Panel {
        yrange: (lo <= hi).then_some((lo - 0.04 * span, hi + 0.3 * span)),
        title: heading,
        xlabel: "time (s)".into(),
        ylabel: "y".into(),
        series: vec![
            samples_series("data y_k", GREY, pts(r.y)).with_opacity(0.6),
            Series::line(
                &format!("model m_k (fit {:.1} %)", r.fit_percent),
                BLUE,
                pts(r.expected),
            )
            .with_width(if dense { 1.0 } else { 1.6 }),
        ],
        ..Default::default()
    }
}

/// The ±bound lines of a correlation test across its lags (the label on the upper one).
fn bound_lines(c: &CorrelationTest, from: f64) -> [Series; 2] {
    let to = c.lags.last().map_or(1.0, |&l| l as f64);
    let line = |label: &str, b: f64| Series::dashed(label, RED, vec![(from, b), (to, b)]);
    [
        line(&format!("99 % bounds ±{:.3}", c.bound), c.bound),
        line("", -c.bound),
    ]
}

/// One correlation test as stems by lag with its 99 % bounds; `skip_zero` leaves out lag 0
/// (of an autocorrelation: 1 by construction, not tested).
fn correlation_panel(c: &CorrelationTest, heading: &str, skip_zero: bool) -> Panel {
    let pts: Vec<(f64, f64)> = c
        .lags
        .iter()
        .zip(&c.values)
        .filter(|(l, _)| !(skip_zero && **l == 0))
        .map(|(&l, &v)| (l as f64, v))
        .collect();
    let from = pts.first().map_or(0.0, |p| p.0);
    let verdict = if c.passed { "passed" } else { "failed" };
    // The verdict is the portmanteau test's; the count of lags outside is shown beside it.
    let mut series = vec![Series {
        label: format!(
            "{} = {:.1}, χ²({}) p = {:.3}: {verdict} at level {}; {} of {} lags outside",
            if c.test == "ljung-box" { "Q" } else { "S" },
            c.statistic,
            c.dof,
            c.p_value,
            c.level,
            c.outside,
            pts.len(),
        ),
        color: BLUE,
        opacity: 1.0,
        style: Style::Stems,
        points: pts,
    }];
    series.extend(bound_lines(c, from));
    let b = c.bound;
    let top = c
        .values
        .iter()
        .skip(usize::from(skip_zero))
        .fold(1.6 * b, |m, v| m.max(v.abs()));
    Panel {
        title: heading.into(),
        xlabel: "lag (samples)".into(),
        ylabel: "correlation".into(),
        yrange: Some((-1.15 * top, 1.15 * top)),
        series,
        ..Default::default()
    }
}

/// Autocorrelation of the standardised residuals and their cross-correlation with the input,
/// one row per record.
fn correlation_figure(records: &[&RecordPlot<'_>], title: &str) -> String {
    let with_input = records.iter().any(|r| r.cross.is_some());
    let mut panels = Vec::new();
    for r in records {
        panels.push(correlation_panel(
            r.whiteness,
            &format!("autocorrelation of ε_k, {} ({})", r.name, r.role),
            true,
        ));
        if with_input {
            panels.push(match r.cross {
                Some(c) => correlation_panel(
                    c,
                    &format!("cross-correlation of ε_k with u_k, {}", r.name),
                    false,
                ),
                None => Panel {
                    title: format!("no input for {}", r.name),
                    ..Default::default()
                },
            });
        }
    }
    figure(
        "Correlations of the standardised residuals ε_k (99 % bounds)",
        title,
        &panels,
        if with_input { 2 } else { 1 },
    )
}
