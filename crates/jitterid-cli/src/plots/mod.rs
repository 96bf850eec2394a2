//! The figures of `fit --plot`, `montecarlo --plot` and `validate --plot`, one module each,
//! with the curves and panels they share (spectra, Bode diagrams, densities, long records)
//! here and the fitted system's responses with their bands in `response`.

mod fit;
mod montecarlo;
mod response;
mod validate;

pub use fit::{fit_figures, FitPlots};
pub use montecarlo::{montecarlo_figures, McPlots};
pub use validate::{validate_figures, RecordPlot, ValidatePlots};

/// The subfolder of `--plot DIR` that `fit` writes its figures into: each command has its own,
/// so that one folder never holds the figures of two commands' experiments side by side.
pub const FIT_DIR: &str = "fit";
/// The subfolder of `--plot DIR` for `montecarlo`'s figures.
pub const MONTECARLO_DIR: &str = "montecarlo";
/// The subfolder of `--plot DIR` for `validate`'s figures.
pub const VALIDATE_DIR: &str = "validate";

/// Every figure `fit` may draw (which it draws depends on the model): those not drawn are
/// removed from its subfolder, so that it never shows an earlier run's beside this one's.
pub const FIT_FIGURES: [&str; 6] = [
    "bode.svg",
    "jitter-pdf.svg",
    "moment.svg",
    "residuals.svg",
    "spectrum.svg",
    "step.svg",
];
/// Every figure `montecarlo` may draw.
pub const MONTECARLO_FIGURES: [&str; 4] =
    ["bode.svg", "histograms.svg", "jitter-pdf.svg", "moment.svg"];
/// Every figure `validate` may draw.
pub const VALIDATE_FIGURES: [&str; 4] = ["bode.svg", "correlations.svg", "step.svg", "time.svg"];

use crate::svg::{self, figure, Panel, Series, Style, BLACK, BLUE, ORANGE};
use jitterid::jitter::AnyJitter;
use jitterid::jitter::{JitterModel, NoJitter};
use jitterid::num_complex::Complex64;
use jitterid::signal::{AnySignal, SampleGrid, Signal};
use jitterid::window::{transform, DirichletWindow, FrequencySet};
use jitterid_study::export;

/// Above this many points a data series is drawn as its min/max envelope: a few hundred
/// markers on a panel 520 pixels wide already overlap into a tangle.
const MAX_MARKERS: usize = 250;

/// Runs of an envelope: about two and a half pixels each across a panel.
const ENVELOPE_RUNS: usize = 200;

/// Whether `n` data points are drawn as their envelope rather than as markers.
fn too_many_markers(n: usize) -> bool {
    n > MAX_MARKERS
}

/// Data points as markers, or as their min/max envelope when there are more than
/// [`MAX_MARKERS`] (the label says how many points each run of the envelope holds).
fn samples_series(label: &str, color: &'static str, points: Vec<(f64, f64)>) -> Series {
    if !too_many_markers(points.len()) {
        return Series::markers(label, color, points);
    }
    let per_run = points.len().div_ceil(ENVELOPE_RUNS);
    let env = svg::envelope(&points, ENVELOPE_RUNS);
    Series::band(&format!("{label}: min–max of every {per_run}"), color, &env).with_opacity(0.5)
}

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
    // The signals drawn were built from the spec tables that `tf_of` rebuilds, so a rebuild
    // cannot fail here; the fit's report names any export error.
    export::tf_of(signal)
        .ok()
        .flatten()
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

/// Magnitude (linear, log scale) and phase panels of a Bode diagram of several models without
/// bands (`montecarlo`'s estimates).
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
