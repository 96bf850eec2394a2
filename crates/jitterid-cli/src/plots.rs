//! The figures of `fit --plot` and `montecarlo --plot`.

use crate::error::CliResult;
use crate::experiment::Experiment;
use crate::export;
use crate::fitting::Structure;
use crate::svg::{self, figure, Panel, Series, Style, BLACK, BLUE, GREEN, GREY, ORANGE, RED};
use jitterid::jitter::AnyJitter;
use jitterid::jitter::{JitterModel, NoJitter};
use jitterid::num_complex::Complex64;
use jitterid::signal::{AnySignal, Input, SampleGrid, Signal};
use jitterid::window::{transform, DirichletWindow, FrequencySet};

/// `|X(f)|` of a sequence on the grid at the DFT frequencies (zero excluded).
fn spectrum(grid: &SampleGrid, x: &[f64]) -> Vec<(f64, Complex64)> {
    let set = FrequencySet::dft(grid);
    match transform(grid, &DirichletWindow, x, &set) {
        Ok(v) => set
            .frequencies()
            .iter()
            .copied()
            .zip(v)
            .filter(|(f, _)| *f > 0.0)
            .collect(),
        Err(_) => Vec::new(),
    }
}

/// `μ_Y(f)` of a signal under a jitter (the DTFT of `m_k`).
fn moment(
    grid: &SampleGrid,
    signal: &AnySignal,
    jitter: &dyn JitterModel,
) -> Vec<(f64, Complex64)> {
    spectrum(grid, &signal.expected_values(grid, jitter))
}

fn abs_points(v: &[(f64, Complex64)]) -> Vec<(f64, f64)> {
    v.iter().map(|(f, z)| (*f, z.norm())).collect()
}

/// Log-spaced frequencies over the DFT band.
fn log_band(grid: &SampleGrid) -> Vec<f64> {
    let lo = 1.0 / grid.duration();
    let hi = 0.5 / grid.interval();
    let m = 300;
    (0..=m)
        .map(|i| lo * (hi / lo).powf(i as f64 / m as f64))
        .collect()
}

/// Points of a curve.
type Curve = Vec<(f64, f64)>;

/// `G(i2πf)` of a rational system, `None` for other signals.
fn frequency_response(signal: &AnySignal, f: f64) -> Option<Complex64> {
    export::tf_of(signal).map(|tf| tf.response(Complex64::new(0.0, std::f64::consts::TAU * f)))
}

/// Magnitude and unwrapped phase (degrees) of `G(i2πf)`.
fn bode_points(signal: &AnySignal, fs: &[f64]) -> Option<(Curve, Curve)> {
    let mut mag = Vec::with_capacity(fs.len());
    let mut phase = Vec::with_capacity(fs.len());
    let mut prev: Option<f64> = None;
    for &f in fs {
        let g = frequency_response(signal, f)?;
        mag.push((f, g.norm()));
        // Unwrapped phase in degrees.
        let mut p = g.arg().to_degrees();
        if let Some(q) = prev {
            while p - q > 180.0 {
                p -= 360.0;
            }
            while p - q < -180.0 {
                p += 360.0;
            }
        }
        prev = Some(p);
        phase.push((f, p));
    }
    Some((mag, phase))
}

/// A τ axis covering the given jitters (mean ± 5 standard deviations of the widest).
fn tau_axis(jitters: &[&AnyJitter], extra: &[f64]) -> Vec<f64> {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for j in jitters {
        let (m, s) = (j.mean(), j.std_dev());
        let (a, b) = j.reach();
        let s = if s > 0.0 { s } else { 0.1 };
        lo = lo.min(a.max(m - 5.0 * s)).min(m - 1.2 * s);
        hi = hi.max(b.min(m + 5.0 * s)).max(m + 1.2 * s);
    }
    for &x in extra {
        if x.is_finite() {
            lo = lo.min(x);
            hi = hi.max(x);
        }
    }
    if !(lo.is_finite() && hi.is_finite() && hi > lo) {
        lo = -1.0;
        hi = 1.0;
    }
    let pad = 0.05 * (hi - lo);
    let (lo, hi) = (lo - pad, hi + pad);
    let m = 400;
    (0..=m)
        .map(|i| lo + (hi - lo) * i as f64 / m as f64)
        .collect()
}

fn pdf_series(
    label: &str,
    color: &'static str,
    j: &AnyJitter,
    taus: &[f64],
    dashed: bool,
) -> Vec<Series> {
    let mut out = Vec::new();
    if !j.pieces().is_empty() {
        let pts = taus.iter().map(|&t| (t, j.pdf(t))).collect();
        out.push(if dashed {
            Series::dashed(label, color, pts)
        } else {
            Series::line(label, color, pts)
        });
    }
    let atoms = j.atoms();
    if !atoms.is_empty() {
        out.push(Series {
            label: if out.is_empty() {
                format!("{label} (point masses)")
            } else {
                String::new()
            },
            color,
            opacity: 0.9,
            style: Style::Stems,
            points: atoms.iter().map(|a| (a.position, a.mass)).collect(),
        });
    }
    out
}

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
}

/// Writes the `fit` figures; returns (file name, SVG text) pairs.
pub fn fit_figures(p: &FitPlots<'_>) -> CliResult<Vec<(String, String)>> {
    let exp = p.exp;
    let grid = &exp.grid;
    let (main_label, main) = p.main;
    let mut out = Vec::new();
    let data = spectrum(grid, p.y);
    let title = exp.title.clone().unwrap_or_else(|| exp.file.clone());
    if frequency_response(p.file_model, 0.0).is_some() {
        out.push(("bode.svg".to_string(), fit_bode(p, &data, &title)));
    }
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

/// `|G|` and phase of the file's, LS and main models, over the data's `Y/U`.
fn fit_bode(p: &FitPlots<'_>, data: &[(f64, Complex64)], title: &str) -> String {
    let grid = &p.exp.grid;
    let (main_label, main) = p.main;
    let fs = log_band(grid);
    let mut mag = Vec::new();
    let mut ph = Vec::new();
    if let Some(u) = p.input {
        let us: Vec<f64> = grid.times().map(|t| u.value(t)).collect();
        let uf = spectrum(grid, &us);
        let umax = uf.iter().map(|(_, z)| z.norm()).fold(0.0, f64::max);
        let etfe: Vec<(f64, Complex64)> = data
            .iter()
            .zip(&uf)
            .filter(|(_, (_, u))| u.norm() > 1e-3 * umax)
            .map(|((f, y), (_, u))| (*f, y / u))
            .collect();
        mag.push(
            Series::markers(
                "data Y/U",
                GREY,
                etfe.iter().map(|(f, z)| (*f, z.norm())).collect(),
            )
            .with_opacity(0.45),
        );
    }
    let mut add = |label: &str, color: &'static str, dashed: bool, s: &AnySignal| {
        if let Some((m, ph_)) = bode_points(s, &fs) {
            if dashed {
                mag.push(Series::dashed(label, color, m));
                ph.push(Series::dashed(label, color, ph_));
            } else {
                mag.push(Series::line(label, color, m));
                ph.push(Series::line(label, color, ph_));
            }
        }
    };
    add("experiment file", BLACK, false, p.file_model);
    if let Some(ls) = p.ls {
        add("naive LS", RED, true, &ls.signal);
    }
    if main.estimate_signal {
        add(main_label, BLUE, false, &main.signal);
    }
    bode_figure("Bode diagram", title, mag, ph)
}

/// Magnitude and phase panels of a Bode diagram.
fn bode_figure(heading: &str, title: &str, mag: Vec<Series>, ph: Vec<Series>) -> String {
    figure(
        heading,
        title,
        &[
            Panel {
                title: "magnitude |G(i2πf)|".into(),
                xlabel: "frequency (Hz)".into(),
                ylabel: "|G|".into(),
                xlog: true,
                ylog: true,
                series: mag,
                ..Default::default()
            },
            Panel {
                title: "phase".into(),
                xlabel: "frequency (Hz)".into(),
                ylabel: "phase (degrees)".into(),
                xlog: true,
                series: ph,
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
    let mut sp = vec![Series::markers("data |Y(f)|", GREY, abs_points(data))];
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

/// `|μ_Y(f)|` with and without the jitter's damping, and `|γ(f)|`.
fn moment_figure(
    title: &str,
    grid: &SampleGrid,
    signal: &AnySignal,
    jitter: &AnyJitter,
    label: &str,
    reference: Option<&AnyJitter>,
) -> String {
    let damped = moment(grid, signal, jitter);
    let undamped = moment(grid, signal, &NoJitter);
    let fs: Vec<f64> = damped.iter().map(|x| x.0).collect();
    let dense = fs.len() > 300;
    let mut gam = vec![Series::line(
        &format!("|γ(f)|, {label}"),
        BLUE,
        fs.iter().map(|&f| (f, jitter.cf(f).norm())).collect(),
    )];
    if let Some(r) = reference {
        gam.push(Series::dashed(
            "|γ(f)|, experiment file",
            BLACK,
            fs.iter().map(|&f| (f, r.cf(f).norm())).collect(),
        ));
    }
    figure(
        "Jitter damping of the first moment",
        title,
        &[
            Panel {
                title: format!("|μ_Y(f)| of the {label} model"),
                xlabel: "frequency (Hz)".into(),
                ylabel: "magnitude".into(),
                ylog: true,
                series: vec![
                    Series::line("with jitter damping", BLUE, abs_points(&damped))
                        .with_width(if dense { 1.4 } else { 2.4 }),
                    Series::dashed("without jitter (γ ≡ 1)", ORANGE, abs_points(&undamped))
                        .with_width(if dense { 1.0 } else { 1.8 }),
                ],
                ..Default::default()
            },
            Panel {
                title: "jitter characteristic function".into(),
                xlabel: "frequency (Hz)".into(),
                ylabel: "|γ(f)|".into(),
                yrange: Some((0.0, 1.05)),
                series: gam,
                ..Default::default()
            },
        ],
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

/// The panel of densities `p(τ)`, its y range set by the `reference` density.
fn pdf_panel(series: Vec<Series>, reference: &AnyJitter, taus: &[f64]) -> Panel {
    Panel {
        title: "p(τ)".into(),
        xlabel: "τ (s)".into(),
        ylabel: "density (1/s)".into(),
        y_from_zero: true,
        yrange: pdf_yrange(reference, taus),
        series,
        ..Default::default()
    }
}

/// A y range for densities that an estimate collapsing to a spike cannot squash: up to 2.5
/// times the peak of the reference density (automatic if it has no density part).
fn pdf_yrange(reference: &AnyJitter, taus: &[f64]) -> Option<(f64, f64)> {
    if reference.pieces().is_empty() {
        return None;
    }
    let peak = taus.iter().map(|&t| reference.pdf(t)).fold(0.0, f64::max);
    (peak.is_finite() && peak > 0.0).then_some((0.0, 2.5 * peak))
}

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
