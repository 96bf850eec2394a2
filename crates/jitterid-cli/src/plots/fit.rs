//! The figures of `fit --plot`: the Bode diagram, the spectrum, the first moment and the jitter.

use super::{
    abs_points, bode_figure, bode_points, frequency_response, log_band, moment, moment_figure,
    pdf_panel, pdf_series, spectrum, tau_axis,
};

use crate::svg::{self, figure, Panel, Series, Style, BLACK, BLUE, GREEN, GREY, RED};
use jitterid::jitter::AnyJitter;
use jitterid::jitter::NoJitter;
use jitterid::num_complex::Complex64;
use jitterid::signal::{AnySignal, Input};
use jitterid_study::error::StudyResult;
use jitterid_study::experiment::Experiment;
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
