//! Every figure the command line writes (`fit`, `montecarlo` and `validate --plot`) parsed as
//! XML: one `<svg>` root in the SVG namespace with drawn elements and text, and a title full of
//! markup and control characters shown as text, not read as markup.

mod common;

use common::{example, example_with, files_in, run, s, scratch, stderr};
use std::path::Path;

/// The experiment's title: XML's five special characters, characters XML 1.0 forbids (U+0001,
/// ESC) and non-ASCII text.
const TITLE: &str = r#"a <b> & "c" 'd' \u0001\u001b ε ☃"#;
/// How the figures show it: the forbidden characters replaced by U+FFFD.
const SHOWN: &str = "a <b> & \"c\" 'd' \u{fffd}\u{fffd} ε ☃";

/// Parses every SVG file of `dir` (there must be `expected` of them) and checks its content;
/// `titled` says whether the figures carry the experiment's title.
fn check_figures(dir: &Path, expected: &[&str], titled: bool) {
    assert_eq!(files_in(dir), expected, "{}", dir.display());
    for f in expected {
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

#[test]
fn every_figure_is_well_formed_svg_with_the_title_as_text() {
    let dir = scratch("figures-xml");
    let exp = dir.join("e.toml");
    // A TOML basic string: its `\u` escapes make the control characters.
    let title = format!(r#"title = "{}""#, TITLE.replace('"', "\\\""));
    let text = example_with("table2.toml", "title =", &title);
    std::fs::write(&exp, text).unwrap();
    let data = dir.join("d.csv");
    let ok = |args: &[&str]| {
        let o = run(args);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    };
    ok(&["simulate", s(&exp), "--out", s(&data)]);

    let fit = dir.join("fit");
    ok(&["fit", s(&exp), "--data", s(&data), "--plot", s(&fit)]);
    check_figures(
        &fit,
        &["bode.svg", "jitter-pdf.svg", "moment.svg", "spectrum.svg"],
        true,
    );

    let mc = dir.join("mc");
    ok(&["montecarlo", s(&exp), "--runs", "3", "--plot", s(&mc)]);
    check_figures(&mc, &["bode.svg", "histograms.svg", "moment.svg"], true);

    // A jitter estimated: the Monte Carlo densities.
    let mc1 = dir.join("mc1");
    let table1 = example("table1-uniform-n2-a0.5.toml");
    ok(&["montecarlo", &table1, "--runs", "2", "--plot", s(&mc1)]);
    check_figures(
        &mc1,
        &["histograms.svg", "jitter-pdf.svg", "moment.svg"],
        false,
    );

    let val = dir.join("validate");
    ok(&["validate", s(&exp), "--data", s(&data), "--plot", s(&val)]);
    check_figures(
        &val,
        &["bode.svg", "correlations.svg", "step.svg", "time.svg"],
        true,
    );
}
