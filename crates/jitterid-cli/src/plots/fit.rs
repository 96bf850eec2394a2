//! The figures of `fit --plot`: the Bode diagram and the step response with their bands, the
//! residuals, the spectrum, the first moment and the jitter.

use super::response::{self, Compared};
use super::{
    abs_points, moment, moment_figure, pdf_panel, pdf_series, samples_series, spectrum, tau_axis,
};

use crate::svg::{self, figure, Panel, Series, Style, BLACK, BLUE, GREEN, GREY, RED};
use jitterid::estimate::validation::{BodePoint, StepPoint};
use jitterid::jitter::AnyJitter;
use jitterid::jitter::NoJitter;
use jitterid::num_complex::Complex64;
use jitterid::signal::{AnySignal, Input, Signal};
use jitterid_study::error::StudyResult;
use jitterid_study::experiment::Experiment;
use jitterid_study::export;
use jitterid_study::fit::Structure;

/// Everything `fit --plot` draws from.
pub struct FitPlots<'a> {
    /// The experiment.
    pub exp: &'a Experiment,
    /// The data.
    pub y: &'a [f64],
    /// The known input, if any.
    pub input: Option<&'a Input>,
    /// The experiment file's model (truth when the data were simulated from it).
    pub file_model: &'a AnySignal,
    /// The naive LS fit, if the system was estimated.
    pub ls: Option<&'a Structure>,
    /// The main fit (its method's label).
    pub main: (&'a str, &'a Structure),
    /// True jitter values from the data file (`tau` column), if present.
    pub tau: Option<&'a [f64]>,
    /// The main fit's frequency response with its bands (the study layer's, as `validate
    /// --bode` writes it), if its system is rational.
    pub bode: Option<&'a [BodePoint]>,
    /// Its unit-step response with its band, if rational.
    pub step: Option<&'a [StepPoint]>,
}

/// Writes the `fit` figures; returns (file name, SVG text) pairs.
pub fn fit_figures(p: &FitPlots<'_>) -> StudyResult<Vec<(String, String)>> {
    let exp = p.exp;
    let grid = &exp.grid;
    let (main_label, main) = p.main;
    let mut out = Vec::new();
    let data = spectrum(grid, p.y);
    let title = exp.title.clone().unwrap_or_else(|| exp.file.clone());
    if let Some(b) = p.bode {
        out.push(("bode.svg".to_string(), fit_bode(p, b, &data, &title)));
    }
    if let Some(st) = p.step {
        out.push(("step.svg".to_string(), fit_step(p, st, &title)));
    }
    out.push(("residuals.svg".to_string(), residual_figure(p, &title)));
    out.push(("spectrum.svg".to_string(), fit_spectrum(p, &data, &title)));
    out.push((
        "moment.svg".to_string(),
        moment_figure(
            &title,
            grid,
            &main.signal,
            &main.jitter,
            main_label,
            Some(&exp.jitter.truth),
        ),
    ));
    let est: Vec<(&str, &AnyJitter)> = if main.estimate_jitter {
        vec![(main_label, &main.jitter)]
    } else {
        Vec::new()
    };
    out.push((
        "jitter-pdf.svg".to_string(),
        jitter_figure(&title, &exp.jitter.truth, &est, p.tau),
    ));
    Ok(out)
}

/// The label of the main fit's curves: its method, or the file's model when the system was
/// not estimated (then the curve is the file's and no other is drawn).
fn fitted_label<'a>(p: &FitPlots<'a>) -> &'a str {
    let (label, main) = p.main;
    if main.estimate_signal {
        label
    } else {
        "experiment file (system not estimated)"
    }
}

/// The models drawn beside the fit: the file's and the naive LS fit's, when the system was
/// estimated; `of` computes one model's curve (`None` when it is not rational).
fn compared<P>(p: &FitPlots<'_>, of: impl Fn(&AnySignal) -> Option<Vec<P>>) -> Vec<Compared<P>> {
    if !p.main.1.estimate_signal {
        return Vec::new();
    }
    let mut out = Vec::new();
    let mut add = |label: &str, color, dashed, s: &AnySignal| {
        if let Some(points) = of(s) {
            out.push(Compared {
                label: label.into(),
                color,
                dashed,
                points,
            });
        }
    };
    add("experiment file", BLACK, false, p.file_model);
    if let Some(ls) = p.ls {
        add("naive LS", RED, true, &ls.signal);
    }
    out
}

/// The data's empirical transfer function `Y(f)/U(f)` on the DFT grid, at the frequencies where
/// the sampled input has energy (empty without an input).
fn empirical_tf(p: &FitPlots<'_>, data: &[(f64, Complex64)]) -> Vec<(f64, Complex64)> {
    let Some(u) = p.input else {
        return Vec::new();
    };
    let grid = &p.exp.grid;
    let us: Vec<f64> = grid.times().map(|t| u.value(t)).collect();
    let uf = spectrum(grid, &us);
    let umax = uf.iter().map(|(_, z)| z.norm()).fold(0.0, f64::max);
    data.iter()
        .zip(&uf)
        .filter(|(_, (_, u))| u.norm() > 1e-3 * umax)
        .map(|((f, y), (_, u))| (*f, y / u))
        .collect()
}

/// The fit's magnitude (dB) and phase (degrees) with their ±2σ bands, beside the file's and
/// the naive LS models, over the data's empirical transfer function.
fn fit_bode(
    p: &FitPlots<'_>,
    fitted: &[BodePoint],
    data: &[(f64, Complex64)],
    title: &str,
) -> String {
    let freqs: Vec<f64> = fitted.iter().map(|b| b.f_hz).collect();
    // The same frequencies and unwrapping as the fit's curve; a model that cannot be exported
    // is left out (the fit's report names the export error).
    let others = compared(p, |s| export::bode_of(s, &freqs, None).and_then(Result::ok));
    response::bode_figure(
        (fitted_label(p), fitted),
        &others,
        &empirical_tf(p, data),
        "Bode diagram",
        title,
    )
}

/// The fit's unit-step response with its ±2σ band, beside the file's and the naive LS models.
fn fit_step(p: &FitPlots<'_>, fitted: &[StepPoint], title: &str) -> String {
    let times: Vec<f64> = fitted.iter().map(|s| s.t).collect();
    let others = compared(p, |s| export::step_of(s, &times, None).and_then(Result::ok));
    response::step_figure(
        (fitted_label(p), fitted),
        &others,
        "Unit-step response",
        title,
    )
}

/// The main fit's residuals: `y_k − m_k` against time, and `|Y(f) − μ_Y(f)|` on the DFT grid,
/// whose flatness every converged fit is checked for (with its root-mean-square level).
fn residual_figure(p: &FitPlots<'_>, title: &str) -> String {
    let grid = &p.exp.grid;
    let (label, main) = p.main;
    let m = main.signal.expected_values(grid, &main.jitter);
    let e: Vec<f64> = p.y.iter().zip(&m).map(|(y, m)| y - m).collect();
    let in_time: Vec<(f64, f64)> = grid.times().zip(e.iter().copied()).collect();
    let in_freq = abs_points(&spectrum(grid, &e));
    let rms =
        (in_freq.iter().map(|(_, a)| a * a).sum::<f64>() / in_freq.len().max(1) as f64).sqrt();
    let ends = |pts: &[(f64, f64)]| {
        let x0 = pts.first().map_or(0.0, |q| q.0);
        vec![(x0, rms), (pts.last().map_or(1.0, |q| q.0), rms)]
    };
    let zero = vec![
        (grid.start(), 0.0),
        (in_time.last().map_or(1.0, |q| q.0), 0.0),
    ];
    figure(
        &format!("Residuals of the {label} fit"),
        title,
        &[
            Panel {
                title: "y_k − m_k against time".into(),
                xlabel: "time (s)".into(),
                ylabel: "residual".into(),
                series: vec![
                    Series::dashed("", BLACK, zero).with_width(1.0),
                    samples_series("y_k − m_k", GREY, in_time).with_opacity(0.6),
                ],
                ..Default::default()
            },
            Panel {
                title: "|Y(f) − μ_Y(f)| on the DFT grid".into(),
                xlabel: "frequency (Hz)".into(),
                ylabel: "magnitude".into(),
                ylog: true,
                series: vec![
                    samples_series("|Y − μ_Y|", GREY, in_freq.clone()),
                    Series::dashed(&format!("root mean square {rms:.3e}"), BLUE, ends(&in_freq)),
                ],
                ..Default::default()
            },
        ],
        1,
    )
}

/// The data's `|Y(f)|` against the models' first moments.
fn fit_spectrum(p: &FitPlots<'_>, data: &[(f64, Complex64)], title: &str) -> String {
    let grid = &p.exp.grid;
    let (main_label, main) = p.main;
    let mut sp = vec![samples_series("data |Y(f)|", GREY, abs_points(data))];
    sp.push(Series::line(
        "experiment file, μ_Y",
        BLACK,
        abs_points(&moment(grid, p.file_model, &p.exp.jitter.truth)),
    ));
    if let Some(ls) = p.ls {
        sp.push(Series::dashed(
            "naive LS, μ_Y without jitter",
            RED,
            abs_points(&moment(grid, &ls.signal, &NoJitter)),
        ));
    }
    sp.push(
        Series::line(
            &format!("{main_label}, μ_Y"),
            BLUE,
            abs_points(&moment(grid, &main.signal, &main.jitter)),
        )
        .with_width(1.4),
    );
    figure(
        "Data |Y(f)| and model first moments |μ_Y(f)|",
        title,
        &[Panel {
            title: "|Y(f)| and |μ_Y(f)| on the DFT grid".into(),
            xlabel: "frequency (Hz)".into(),
            ylabel: "magnitude".into(),
            ylog: true,
            series: sp,
            ..Default::default()
        }],
        1,
    )
}

/// True and estimated jitter densities (point masses as stems), with a histogram of known `τ`.
fn jitter_figure(
    title: &str,
    truth: &AnyJitter,
    estimates: &[(&str, &AnyJitter)],
    tau: Option<&[f64]>,
) -> String {
    let mut all: Vec<&AnyJitter> = vec![truth];
    all.extend(estimates.iter().map(|e| e.1));
    let taus = tau_axis(&all, &[]);
    let mut series = Vec::new();
    if let Some(t) = tau {
        let (bars, width) = svg::histogram(t);
        let n = t.len().max(1) as f64;
        series.push(Series {
            label: "drawn τ (data file)".into(),
            color: GREEN,
            opacity: 0.35,
            style: Style::Bars { width },
            points: bars
                .into_iter()
                .map(|(x, c)| (x, c / (n * width)))
                .collect(),
        });
    }
    series.extend(pdf_series("experiment file", BLACK, truth, &taus, false));
    for (i, (label, j)) in estimates.iter().enumerate() {
        let color = if i == 0 { BLUE } else { RED };
        series.extend(pdf_series(
            &format!("{label} estimate"),
            color,
            j,
            &taus,
            true,
        ));
    }
    figure(
        "Jitter density",
        title,
        &[pdf_panel(series, truth, &taus)],
        1,
    )
}
