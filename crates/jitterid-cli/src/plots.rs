//! The figures of `fit --plot`, `montecarlo --plot` and `validate --plot`.

use crate::svg::{self, figure, Panel, Series, Style, BLACK, BLUE, GREEN, GREY, ORANGE, RED};
use jitterid::estimate::validation::{BodePoint, CorrelationTest, StepPoint};
use jitterid::jitter::AnyJitter;
use jitterid::jitter::{JitterModel, NoJitter};
use jitterid::num_complex::Complex64;
use jitterid::signal::{AnySignal, Input, SampleGrid, Signal};
use jitterid::window::{transform, DirichletWindow, FrequencySet};
use jitterid_study::error::StudyResult;
use jitterid_study::experiment::Experiment;
use jitterid_study::export;
use jitterid_study::fit::Structure;

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

/// `G(i2πf) e^{−i2πfD}` of a rational system with input delay `D` (0 without), `None` for
/// other signals.
fn frequency_response(signal: &AnySignal, f: f64) -> Option<Complex64> {
    let w = std::f64::consts::TAU * f;
    let delay = export::delay_of(signal).unwrap_or(0.0);
    export::tf_of(signal)
        .map(|tf| tf.response(Complex64::new(0.0, w)) * Complex64::from_polar(1.0, -w * delay))
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
pub fn fit_figures(p: &FitPlots<'_>) -> StudyResult<Vec<(String, String)>> {
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
        out.push(("bode.svg".to_string(), validate_bode(b, &p.title)));
    }
    if let Some(s) = p.step {
        out.push(("step.svg".to_string(), step_figure(s, &p.title)));
    }
    out
}

/// `y_k` as points and `m_k` as a line against time, one panel per record.
fn time_figure(records: &[&RecordPlot<'_>], title: &str) -> String {
    let panels: Vec<Panel> = records
        .iter()
        .map(|r| {
            let t: Vec<f64> = r.grid.times().collect();
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
                title: format!("{} record {}: fit {:.1} %", r.role, r.name, r.fit_percent),
                xlabel: "time (s)".into(),
                ylabel: "y".into(),
                series: vec![
                    Series::markers("data y_k", GREY, pts(r.y)).with_opacity(0.6),
                    Series::line(
                        &format!("model m_k (fit {:.1} %)", r.fit_percent),
                        BLUE,
                        pts(r.expected),
                    )
                    .with_width(if dense { 1.0 } else { 1.6 }),
                ],
                ..Default::default()
            }
        })
        .collect();
    figure(
        "Model vs data: samples y_k and the model's expected samples m_k",
        title,
        &panels,
        1,
    )
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
    let mut series = vec![Series {
        label: format!(
            "{} of {} lags outside (≤ {} allowed): {verdict}",
            c.outside,
            pts.len(),
            c.allowed
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

/// A central curve and, when every point has both edges, its band.
fn with_band(
    label: &str,
    centre: Vec<(f64, f64)>,
    band: Option<Vec<(f64, f64, f64)>>,
) -> Vec<Series> {
    let mut v = Vec::new();
    if let Some(b) = band {
        v.push(Series::band("±2σ band (parameter covariance)", BLUE, &b));
    }
    v.push(Series::line(label, BLUE, centre));
    v
}

/// The edges `(x, lo, hi)` of a band, `None` when a point has none (no covariance).
fn band_edges(
    points: impl Iterator<Item = (f64, Option<f64>, Option<f64>)>,
) -> Option<Vec<(f64, f64, f64)>> {
    points.map(|(x, lo, hi)| Some((x, lo?, hi?))).collect()
}

/// The note on a figure whose bands are missing.
fn band_note(has_band: bool, title: &str) -> String {
    if has_band {
        title.to_string()
    } else {
        format!("{title} — no covariance, so no bands")
    }
}

/// Magnitude (dB) and phase (degrees) of the fitted system with their ±2σ bands.
fn validate_bode(points: &[BodePoint], title: &str) -> String {
    let mag_band = band_edges(
        points
            .iter()
            .map(|p| (p.f_hz, p.magnitude_db_lo, p.magnitude_db_hi)),
    );
    let ph_band = band_edges(
        points
            .iter()
            .map(|p| (p.f_hz, p.phase_deg_lo, p.phase_deg_hi)),
    );
    let has_band = mag_band.is_some();
    let mag = with_band(
        "fitted model",
        points.iter().map(|p| (p.f_hz, p.magnitude_db)).collect(),
        mag_band,
    );
    let ph = with_band(
        "fitted model",
        points.iter().map(|p| (p.f_hz, p.phase_deg)).collect(),
        ph_band,
    );
    let panel = |title: &str, ylabel: &str, series| Panel {
        title: title.into(),
        xlabel: "frequency (Hz)".into(),
        ylabel: ylabel.into(),
        xlog: true,
        series,
        ..Default::default()
    };
    figure(
        "Bode diagram of the fitted system",
        &band_note(has_band, title),
        &[
            panel("magnitude 20 log10|G(i2πf)|", "magnitude (dB)", mag),
            panel("phase", "phase (degrees)", ph),
        ],
        1,
    )
}

/// The unit-step response of the fitted system with its ±2σ band.
fn step_figure(points: &[StepPoint], title: &str) -> String {
    let band = band_edges(points.iter().map(|p| (p.t, p.lo, p.hi)));
    let has_band = band.is_some();
    let series = with_band(
        "fitted model",
        points.iter().map(|p| (p.t, p.value)).collect(),
        band,
    );
    figure(
        "Unit-step response of the fitted system",
        &band_note(has_band, title),
        &[Panel {
            title: "response to a unit step at t = 0".into(),
            xlabel: "time after the step (s)".into(),
            ylabel: "output".into(),
            series,
            ..Default::default()
        }],
        1,
    )
}
