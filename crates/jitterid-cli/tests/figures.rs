//! Every figure the command line writes (`fit`, `montecarlo` and `validate --plot`) parsed as
//! XML: one `<svg>` root in the SVG namespace with drawn elements and text, and a title full of
//! markup and control characters shown as text, not read as markup. Each command writes into
//! its own subfolder of `--plot DIR`. A few figures are rendered by a real SVG renderer
//! (resvg) to a PNG that must show the data's colours; a long record is drawn as an envelope
//! with a zoomed panel instead of hundreds of overlapping markers.

mod common;

use common::{example, example_with, files_in, run, s, scratch, stderr};
use jitterid_cli::plots::{FIT_FIGURES, MONTECARLO_FIGURES, VALIDATE_FIGURES};
use std::path::{Path, PathBuf};

/// The experiment's title: XML's five special characters, characters XML 1.0 forbids (U+0001,
/// ESC) and non-ASCII text.
const TITLE: &str = r#"a <b> & "c" 'd' \u0001\u001b ε ☃"#;
/// How the figures show it: the forbidden characters replaced by U+FFFD.
const SHOWN: &str = "a <b> & \"c\" 'd' \u{fffd}\u{fffd} ε ☃";

/// Parses every SVG file of `dir` (there must be `expected` of them, among the command's
/// `may_draw`) and checks its content; `titled` says whether the figures carry the
/// experiment's title.
fn check_figures(dir: &Path, expected: &[&str], may_draw: &[&str], titled: bool) {
    assert_eq!(files_in(dir), expected, "{}", dir.display());
    for f in expected {
        assert!(may_draw.contains(f), "{f} is not in the command's list");
        let text = std::fs::read_to_string(dir.join(f)).unwrap();
        let doc = roxmltree::Document::parse(&text)
            .unwrap_or_else(|e| panic!("{f} is not well-formed XML: {e}"));
        let root = doc.root_element();
        assert_eq!(root.tag_name().name(), "svg", "{f}");
        assert_eq!(
            root.tag_name().namespace(),
            Some("http://www.w3.org/2000/svg"),
            "{f}"
        );
        let count = |name: &str| {
            doc.descendants()
                .filter(|n| n.tag_name().name() == name)
                .count()
        };
        let drawn = ["polyline", "circle", "rect", "path", "line"]
            .iter()
            .map(|n| count(n))
            .sum::<usize>();
        // More than the background, the frames and the legend boxes: grid lines and data.
        assert!(drawn >= 8, "{f}: {drawn} drawn elements");
        let texts: Vec<&str> = doc
            .descendants()
            .filter(|n| n.tag_name().name() == "text")
            .filter_map(|n| n.text())
            .collect();
        assert!(texts.len() > 5, "{f}: {} texts", texts.len());
        if titled {
            assert!(
                texts.iter().any(|t| t.contains(SHOWN)),
                "{f}: the title is not shown as text: {texts:?}"
            );
        }
    }
}

/// Runs the command line, which must succeed.
fn ok(args: &[&str]) {
    let o = run(args);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
}

/// Writes the experiment `text` to `exp` and simulates its record `d.csv` beside it.
fn simulated(exp: &Path, text: &str) -> PathBuf {
    std::fs::write(exp, text).unwrap();
    let data = exp.with_file_name("d.csv");
    ok(&["simulate", s(exp), "--out", s(&data)]);
    data
}

#[test]
fn every_figure_is_well_formed_svg_with_the_title_as_text() {
    let dir = scratch("figures-xml");
    let exp = dir.join("e.toml");
    // A TOML basic string: its `\u` escapes make the control characters.
    let title = format!(r#"title = "{}""#, TITLE.replace('"', "\\\""));
    let data = simulated(&exp, &example_with("table2.toml", "title =", &title));

    // `fit` and `montecarlo` into one folder: each in its own subfolder.
    let figs = dir.join("figs");
    ok(&["fit", s(&exp), "--data", s(&data), "--plot", s(&figs)]);
    ok(&["montecarlo", s(&exp), "--runs", "3", "--plot", s(&figs)]);
    assert_eq!(files_in(&figs), ["fit", "montecarlo"]);
    let fit = figs.join("fit");
    // A rational system, estimated: every figure `fit` can draw.
    check_figures(&fit, &FIT_FIGURES, &FIT_FIGURES, true);
    let mc = figs.join("montecarlo");
    let mc_figures = ["bode.svg", "histograms.svg", "moment.svg"];
    check_figures(&mc, &mc_figures, &MONTECARLO_FIGURES, true);

    // The fit's Bode diagram in dB and degrees, with its two ±2σ bands, the data's empirical
    // transfer function, the file's and the naive LS models; its step response with its band.
    let bode = std::fs::read_to_string(fit.join("bode.svg")).unwrap();
    assert!(bode.contains("magnitude (dB)") && bode.contains("phase (degrees)"));
    assert_eq!(bode.matches("<path ").count(), 2, "two bands");
    for label in [
        "±2σ band",
        "data Y/U",
        "experiment file",
        "naive LS",
        "bcls",
    ] {
        assert!(bode.contains(label), "bode.svg: no {label}");
    }
    let step = std::fs::read_to_string(fit.join("step.svg")).unwrap();
    assert_eq!(step.matches("<path ").count(), 1, "one band");
    let residuals = std::fs::read_to_string(fit.join("residuals.svg")).unwrap();
    assert!(residuals.contains("y_k − m_k") && residuals.contains("|Y(f) − μ_Y(f)|"));
    render_shows_data(&fit.join("bode.svg"));

    // A jitter estimated, the system known: the Monte Carlo densities and no Bode diagram.
    // Into the same folder: the earlier study's bode.svg goes, so that the folder shows one
    // study.
    let table1 = example("table1-uniform-n2-a0.5.toml");
    ok(&["montecarlo", &table1, "--runs", "2", "--plot", s(&figs)]);
    check_figures(
        &mc,
        &["histograms.svg", "jitter-pdf.svg", "moment.svg"],
        &MONTECARLO_FIGURES,
        false,
    );
    assert_eq!(files_in(&figs), ["fit", "montecarlo"]);

    let val = dir.join("validate");
    ok(&["validate", s(&exp), "--data", s(&data), "--plot", s(&val)]);
    check_figures(
        &val.join("validate"),
        &["bode.svg", "correlations.svg", "step.svg", "time.svg"],
        &VALIDATE_FIGURES,
        true,
    );
}

/// Renders `svg` with resvg, through a PNG, and checks that the picture is not blank: some of
/// its pixels are not white and some are the blue of the fitted model's curves.
fn render_shows_data(svg: &Path) {
    use resvg::tiny_skia::{Pixmap, Transform};
    let text = std::fs::read_to_string(svg).unwrap();
    let tree = resvg::usvg::Tree::from_str(&text, &resvg::usvg::Options::default())
        .unwrap_or_else(|e| panic!("{}: resvg cannot read it: {e}", svg.display()));
    let size = tree.size().to_int_size();
    let mut pixmap = Pixmap::new(size.width(), size.height()).expect("a figure has a size");
    resvg::render(&tree, Transform::default(), &mut pixmap.as_mut());
    let png = pixmap.encode_png().expect("PNG encoding");
    // Kept beside the figure, for a reader of a failed run to look at.
    std::fs::write(svg.with_extension("png"), &png).unwrap();
    let image = Pixmap::decode_png(&png).expect("the PNG decodes");
    assert_eq!(
        (image.width(), image.height()),
        (size.width(), size.height())
    );
    let pixels = image.pixels();
    let inked = pixels
        .iter()
        .filter(|p| p.alpha() > 0 && (p.red(), p.green(), p.blue()) != (255, 255, 255))
        .count();
    // The fitted curves' blue #1f77b4 (allowing for antialiasing and the bands' blend).
    let blue = pixels
        .iter()
        .filter(|p| {
            let (r, g, b) = (
                i32::from(p.red()),
                i32::from(p.green()),
                i32::from(p.blue()),
            );
            b > 150 && b - r > 80 && (g - 119).abs() < 40
        })
        .count();
    let total = pixels.len();
    assert!(
        inked * 100 > total && blue > 200,
        "{}: {inked} of {total} pixels drawn, {blue} blue",
        svg.display()
    );
}

/// A record of 600 samples: its samples in time and its 299 DFT bins drawn as min/max
/// envelopes (no marker per sample), with a zoomed panel of the first 120 samples as markers.
#[test]
fn a_long_record_is_drawn_as_an_envelope_with_a_zoomed_panel() {
    let dir = scratch("figures-long");
    let exp = dir.join("e.toml");
    let data = simulated(
        &exp,
        &example_with("table2.toml", "samples =", "samples = 600"),
    );
    let figs = dir.join("figs");
    ok(&["validate", s(&exp), "--data", s(&data), "--plot", s(&figs)]);
    ok(&["fit", s(&exp), "--data", s(&data), "--plot", s(&figs)]);

    let time = std::fs::read_to_string(figs.join("validate/time.svg")).unwrap();
    assert!(time.contains("data y_k: min–max of every 3"), "no envelope");
    assert!(time.contains("its first 120 samples"), "no zoomed panel");
    // The zoomed panel's markers and the legend's: none for the other 480 samples.
    let markers = time.matches("<circle").count();
    assert!((120..=125).contains(&markers), "{markers} markers");
    render_shows_data(&figs.join("validate/time.svg"));

    let spectrum = std::fs::read_to_string(figs.join("fit/spectrum.svg")).unwrap();
    assert!(spectrum.contains("data |Y(f)|") && spectrum.matches("<circle").count() < 10);
    let residuals = std::fs::read_to_string(figs.join("fit/residuals.svg")).unwrap();
    assert!(residuals.contains("y_k − m_k: min–max of every 3"));
}
