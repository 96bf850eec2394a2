//! A small hand-written SVG plotter: panels with linear or logarithmic axes, lines, markers,
//! bars, vertical rules, filled bands and a legend.
//!
//! Kept hand-written rather than drawn with `plotters` (checked with plotters 0.3.7 and its SVG
//! backend, issue 26): that backend has no dash pattern (a dashed line becomes one `<polyline>`
//! per dash, 50 for a ±bound line), no `<path>` (bands are `<polygon>`), integer stroke widths
//! and coordinates, and upper-case colours; the figure tests (`tests/validate.rs`) find the
//! dashed 99 % bounds, the stems, the bands and the solid model lines by exactly those marks.
//!
//! Why one file of about 900 lines (a tenth of them its tests): the plotter is one concept, and
//! its axes, ticks, panels and legend share private geometry (plot-area transforms, tick
//! spacing, text metrics) that a split would have to make public.

use std::fmt::Write as _;

/// Palette: true/file model, naive LS, BCLS/ML, data, extra.
pub const BLACK: &str = "#222222";
/// Naive LS.
pub const RED: &str = "#d62728";
/// BCLS.
pub const BLUE: &str = "#1f77b4";
/// Data.
pub const GREY: &str = "#8c8c8c";
/// Extra.
pub const GREEN: &str = "#2ca02c";
/// Extra.
pub const ORANGE: &str = "#ff7f0e";

/// How a series is drawn.
#[derive(Debug, Clone, PartialEq)]
pub enum Style {
    /// A polyline; `dash` is an SVG dash array.
    Line {
        /// Stroke width.
        width: f64,
        /// Dash pattern.
        dash: Option<&'static str>,
    },
    /// Circles.
    Markers {
        /// Radius.
        radius: f64,
    },
    /// Bars from 0 to `y`, centred at `x`, of width `width` (data units).
    Bars {
        /// Width.
        width: f64,
    },
    /// Vertical rules at each `x` across the whole panel.
    VRule {
        /// Dash pattern.
        dash: Option<&'static str>,
    },
    /// Stems from 0 to `y` with a dot at the top (point masses).
    Stems,
    /// A filled area between the points `(x, lo)` and `(x, upper)` (a confidence band); `upper`
    /// has one value per point.
    Band {
        /// The upper edge, at the points' `x`.
        upper: Vec<f64>,
    },
}

/// One data series.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend label (empty: not in the legend).
    pub label: String,
    /// Colour.
    pub color: &'static str,
    /// Opacity in `[0, 1]`.
    pub opacity: f64,
    /// Drawing style.
    pub style: Style,
    /// Points `(x, y)`; non-finite points are skipped (a line breaks there).
    pub points: Vec<(f64, f64)>,
}

impl Series {
    /// A solid line.
    pub fn line(label: &str, color: &'static str, points: Vec<(f64, f64)>) -> Self {
        Self {
            label: label.into(),
            color,
            opacity: 1.0,
            style: Style::Line {
                width: 1.8,
                dash: None,
            },
            points,
        }
    }
    /// A dashed line.
    pub fn dashed(label: &str, color: &'static str, points: Vec<(f64, f64)>) -> Self {
        Self {
            label: label.into(),
            color,
            opacity: 1.0,
            style: Style::Line {
                width: 1.8,
                dash: Some("6 4"),
            },
            points,
        }
    }
    /// Markers.
    pub fn markers(label: &str, color: &'static str, points: Vec<(f64, f64)>) -> Self {
        Self {
            label: label.into(),
            color,
            opacity: 0.75,
            style: Style::Markers { radius: 2.2 },
            points,
        }
    }
    /// A filled band between `lo` and `hi` at each `x`, from `(x, lo, hi)` triples.
    pub fn band(label: &str, color: &'static str, points: &[(f64, f64, f64)]) -> Self {
        Self {
            label: label.into(),
            color,
            opacity: 0.22,
            style: Style::Band {
                upper: points.iter().map(|p| p.2).collect(),
            },
            points: points.iter().map(|p| (p.0, p.1)).collect(),
        }
    }
    /// Sets the opacity.
    pub fn with_opacity(mut self, o: f64) -> Self {
        self.opacity = o;
        self
    }
    /// Sets the line width.
    pub fn with_width(mut self, w: f64) -> Self {
        if let Style::Line { width, .. } = &mut self.style {
            *width = w;
        }
        self
    }
}

/// One panel.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Panel {
    /// Title above the panel.
    pub title: String,
    /// x-axis label.
    pub xlabel: String,
    /// y-axis label.
    pub ylabel: String,
    /// Logarithmic x axis.
    pub xlog: bool,
    /// Logarithmic y axis.
    pub ylog: bool,
    /// Forced y range.
    pub yrange: Option<(f64, f64)>,
    /// Whether y = 0 must be inside the range (bars, densities).
    pub y_from_zero: bool,
    /// The series, drawn in order.
    pub series: Vec<Series>,
}

/// `s` as XML text or attribute value: markup characters escaped, and the characters XML 1.0
/// forbids (control characters other than tab and line ends, U+FFFE, U+FFFF; a title can hold
/// them through TOML's `\u` escapes) replaced by U+FFFD, so that the file stays well-formed.
fn esc(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\t' | '\n' | '\r' => out.push(c),
            c if c < ' ' || c == '\u{fffe}' || c == '\u{ffff}' => out.push('\u{fffd}'),
            c => out.push(c),
        }
    }
    out
}

/// A compact label for a tick value.
fn fmt_tick(v: f64, step: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    if !(1e-3..1e5).contains(&a) {
        let s = format!("{v:.1e}");
        return s.replace(".0e", "e");
    }
    let decimals = (0..8)
        .find(|&d| {
            let x = step * 10f64.powi(d);
            (x - x.round()).abs() < 1e-6 * x.abs().max(1.0)
        })
        .unwrap_or(8) as usize;
    format!("{v:.decimals$}")
}

/// Nice linear ticks covering `[lo, hi]`.
fn linear_ticks(lo: f64, hi: f64) -> (f64, f64, Vec<f64>, f64) {
    let span = (hi - lo).abs().max(f64::MIN_POSITIVE);
    let raw = span / 5.0;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 2.5, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| span / s <= 6.0)
        .unwrap_or(10.0 * mag);
    let a = (lo / step).floor() * step;
    let b = (hi / step).ceil() * step;
    let mut ticks = Vec::new();
    let mut i = 0;
    loop {
        let t = a + i as f64 * step;
        if t > b + step * 1e-9 || i > 100 {
            break;
        }
        ticks.push(if t.abs() < step * 1e-9 { 0.0 } else { t });
        i += 1;
    }
    (a, b, ticks, step)
}

/// Data range of the finite values, widened when degenerate.
fn range(values: impl Iterator<Item = f64>, log: bool) -> Option<(f64, f64)> {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for v in values {
        if v.is_finite() && (!log || v > 0.0) {
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    if lo > hi {
        return None;
    }
    if log {
        if hi / lo < 1.5 {
            return Some((lo / 1.5, hi * 1.5));
        }
        return Some((lo, hi));
    }
    if hi - lo <= 1e-12 * hi.abs().max(lo.abs()).max(1e-300) {
        let d = if hi == 0.0 { 1.0 } else { 0.1 * hi.abs() };
        return Some((lo - d, hi + d));
    }
    Some((lo, hi))
}

struct Axis {
    lo: f64,
    hi: f64,
    log: bool,
    ticks: Vec<(f64, String)>,
}

impl Axis {
    fn new(lo: f64, hi: f64, log: bool) -> Self {
        if log {
            // A tight range with ticks at 1, 2, 5 × 10^k (only decades when there are many).
            let (a, b) = (lo.log10(), hi.log10());
            let pad = 0.03 * (b - a).max(0.1);
            let (a, b) = (a - pad, b + pad);
            let decades = b - a;
            let mantissas: &[f64] = if decades > 4.0 {
                &[1.0]
            } else if decades > 1.5 {
                &[1.0, 3.0]
            } else {
                &[1.0, 2.0, 5.0]
            };
            let mut ticks = Vec::new();
            let mut e = a.floor() as i32;
            while f64::from(e) <= b.ceil() && ticks.len() < 40 {
                for m in mantissas {
                    let v = m * 10f64.powi(e);
                    let l = v.log10();
                    if l >= a && l <= b {
                        ticks.push((v, fmt_tick(v, v)));
                    }
                }
                e += 1;
            }
            Axis {
                lo: 10f64.powf(a),
                hi: 10f64.powf(b),
                log,
                ticks,
            }
        } else {
            // The given range (already padded by the caller), with the nice ticks inside it.
            let (_, _, t, step) = linear_ticks(lo, hi);
            let eps = 1e-9 * step;
            Axis {
                lo,
                hi,
                log,
                ticks: t
                    .into_iter()
                    .filter(|v| *v >= lo - eps && *v <= hi + eps)
                    .map(|v| (v, fmt_tick(v, step)))
                    .collect(),
            }
        }
    }

    /// Position in `[0, 1]`.
    fn frac(&self, v: f64) -> f64 {
        if self.log {
            (v.log10() - self.lo.log10()) / (self.hi.log10() - self.lo.log10())
        } else {
            (v - self.lo) / (self.hi - self.lo)
        }
    }
}

const PANEL_W: f64 = 520.0;
const PANEL_H: f64 = 300.0;
const LEFT: f64 = 70.0;
const RIGHT: f64 = 20.0;
const TOP: f64 = 36.0;
const BOTTOM: f64 = 48.0;

fn truncate(s: &str, max: usize) -> String {
    if s.chars().count() <= max {
        s.to_string()
    } else {
        let mut t: String = s.chars().take(max.saturating_sub(1)).collect();
        t.push('…');
        t
    }
}

/// Renders panels in a grid of `cols` columns under a figure title and a subtitle.
pub fn figure(title: &str, subtitle: &str, panels: &[Panel], cols: usize) -> String {
    let cols = cols.max(1).min(panels.len().max(1));
    let rows = panels.len().div_ceil(cols).max(1);
    let cell_w = PANEL_W + LEFT + RIGHT;
    let cell_h = PANEL_H + TOP + BOTTOM;
    let width = cell_w * cols as f64;
    let head = 48.0;
    let height = cell_h * rows as f64 + head;
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" viewBox="0 0 {width} {height}" font-family="DejaVu Sans, Helvetica, Arial, sans-serif" font-size="12">"#
    );
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{}" y="21" text-anchor="middle" font-size="15" font-weight="bold">{}</text>"#,
        width / 2.0,
        esc(&truncate(title, (width / 9.0) as usize))
    );
    let _ = writeln!(
        s,
        r##"<text x="{}" y="39" text-anchor="middle" font-size="11" fill="#555">{}</text>"##,
        width / 2.0,
        esc(&truncate(subtitle, (width / 6.6) as usize))
    );
    for (i, p) in panels.iter().enumerate() {
        let ox = (i % cols) as f64 * cell_w + LEFT;
        let oy = (i / cols) as f64 * cell_h + TOP + head;
        panel(&mut s, p, ox, oy, i);
    }
    s.push_str("</svg>\n");
    s
}

/// Where a panel's data go on the page: its origin and size, and the two axes.
struct Frame {
    ox: f64,
    oy: f64,
    w: f64,
    h: f64,
    xa: Axis,
    ya: Axis,
}

impl Frame {
    fn px(&self, x: f64) -> f64 {
        self.ox + self.xa.frac(x) * self.w
    }

    fn py(&self, y: f64) -> f64 {
        self.oy + self.h - self.ya.frac(y) * self.h
    }

    /// Whether a point can be drawn (finite, and positive on a logarithmic axis).
    fn ok(&self, x: f64, y: f64) -> bool {
        x.is_finite() && y.is_finite() && (!self.xa.log || x > 0.0) && (!self.ya.log || y > 0.0)
    }

    /// The baseline of bars and stems: 0, or the bottom of a logarithmic axis.
    fn base(&self) -> f64 {
        if self.ya.log {
            self.ya.lo
        } else {
            0.0
        }
    }
}

fn panel(s: &mut String, p: &Panel, ox: f64, oy: f64, id: usize) {
    let (w, h) = (PANEL_W, PANEL_H);
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" text-anchor="middle" font-size="13">{}</text>"#,
        ox + w / 2.0,
        oy - 10.0,
        esc(&p.title)
    );
    let (xr, yr) = data_ranges(p);
    let _ = writeln!(
        s,
        r##"<rect x="{ox}" y="{oy}" width="{w}" height="{h}" fill="#ffffff" stroke="#444" stroke-width="1"/>"##
    );
    let (Some((x0, x1)), Some((y0, y1))) = (xr, yr) else {
        let _ = writeln!(
            s,
            r##"<text x="{}" y="{}" text-anchor="middle" fill="#888">no finite data</text>"##,
            ox + w / 2.0,
            oy + h / 2.0
        );
        return;
    };
    let f = Frame {
        ox,
        oy,
        w,
        h,
        xa: Axis::new(x0, x1, p.xlog),
        ya: Axis::new(y0, y1, p.ylog),
    };
    grid_and_labels(s, p, &f);
    let _ = writeln!(
        s,
        r#"<clipPath id="clip{id}"><rect x="{ox}" y="{oy}" width="{w}" height="{h}"/></clipPath><g clip-path="url(#clip{id})">"#
    );
    for se in &p.series {
        match &se.style {
            Style::Line { width, dash } => line(s, &f, se, *width, *dash),
            Style::Markers { radius } => markers(s, &f, se, *radius),
            Style::Bars { width } => bars(s, &f, se, *width),
            Style::VRule { dash } => vrules(s, &f, se, *dash),
            Style::Stems => stems(s, &f, se),
            Style::Band { upper } => band(s, &f, se, upper),
        }
    }
    s.push_str("</g>\n");
    legend(s, p, &f);
}

/// A data range `(lo, hi)`, `None` where no point can be drawn.
type Span = Option<(f64, f64)>;

/// The padded x and y ranges of a panel's data.
fn data_ranges(p: &Panel) -> (Span, Span) {
    let xs = p.series.iter().flat_map(|se| {
        let half = match se.style {
            Style::Bars { width } => width / 2.0,
            _ => 0.0,
        };
        se.points
            .iter()
            .flat_map(|q| [q.0 - half, q.0 + half])
            .collect::<Vec<_>>()
    });
    let ys = p
        .series
        .iter()
        .filter(|se| !matches!(se.style, Style::VRule { .. }))
        .flat_map(|se| {
            let mut v: Vec<f64> = se.points.iter().map(|q| q.1).collect();
            if let Style::Band { upper } = &se.style {
                v.extend(upper);
            }
            v
        });
    let xr = range(xs, p.xlog).map(|(a, b)| {
        if p.xlog {
            (a, b)
        } else {
            let pad = 0.02 * (b - a);
            (a - pad, b + pad)
        }
    });
    let yr = match p.yrange {
        Some(r) => Some(r),
        None => range(ys, p.ylog).map(|(a, b)| {
            if p.y_from_zero && !p.ylog {
                let (a, b) = (a.min(0.0), b.max(0.0));
                (a, b + 0.08 * (b - a))
            } else if p.ylog {
                (a, b)
            } else {
                let pad = 0.04 * (b - a);
                (a - pad, b + pad)
            }
        }),
    };
    (xr, yr)
}

/// Grid lines, tick labels and the axis labels.
fn grid_and_labels(s: &mut String, p: &Panel, f: &Frame) {
    let (ox, oy, w, h) = (f.ox, f.oy, f.w, f.h);
    for (v, label) in &f.xa.ticks {
        let x = f.px(*v);
        let _ = writeln!(
            s,
            r##"<line x1="{x:.1}" y1="{oy}" x2="{x:.1}" y2="{}" stroke="#e6e6e6"/><text x="{x:.1}" y="{}" text-anchor="middle">{}</text>"##,
            oy + h,
            oy + h + 16.0,
            esc(label)
        );
    }
    for (v, label) in &f.ya.ticks {
        let y = f.py(*v);
        let _ = writeln!(
            s,
            r##"<line x1="{ox}" y1="{y:.1}" x2="{}" y2="{y:.1}" stroke="#e6e6e6"/><text x="{}" y="{:.1}" text-anchor="end">{}</text>"##,
            ox + w,
            ox - 6.0,
            y + 4.0,
            esc(label)
        );
    }
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" text-anchor="middle">{}</text>"#,
        ox + w / 2.0,
        oy + h + 36.0,
        esc(&p.xlabel)
    );
    let _ = writeln!(
        s,
        r#"<text transform="translate({},{}) rotate(-90)" text-anchor="middle">{}</text>"#,
        ox - 52.0,
        oy + h / 2.0,
        esc(&p.ylabel)
    );
}

fn dash_attr(dash: Option<&str>) -> String {
    dash.map(|d| format!(r#" stroke-dasharray="{d}""#))
        .unwrap_or_default()
}

/// A polyline, broken where a point cannot be drawn.
fn line(s: &mut String, f: &Frame, se: &Series, width: f64, dash: Option<&str>) {
    let dash = dash_attr(dash);
    let op = se.opacity;
    let mut run: Vec<String> = Vec::new();
    let flush = |run: &mut Vec<String>, s: &mut String| {
        if run.len() >= 2 {
            let _ = writeln!(
                s,
                r#"<polyline fill="none" stroke="{}" stroke-opacity="{op}" stroke-width="{width}"{dash} stroke-linejoin="round" points="{}"/>"#,
                se.color,
                run.join(" ")
            );
        }
        run.clear();
    };
    for &(x, y) in &se.points {
        if f.ok(x, y) {
            run.push(format!(
                "{:.1},{:.1}",
                f.px(x),
                f.py(y).clamp(f.oy - 2.0 * f.h, f.oy + 3.0 * f.h)
            ));
        } else {
            flush(&mut run, s);
        }
    }
    flush(&mut run, s);
}

/// A filled band: one closed path per run of points whose both edges can be drawn (along the
/// lower edge, back along the upper one), outlined so that a narrow band stays visible.
fn band(s: &mut String, f: &Frame, se: &Series, upper: &[f64]) {
    let clamp = |y: f64| f.py(y).clamp(f.oy - 2.0 * f.h, f.oy + 3.0 * f.h);
    let mut run: Vec<(f64, f64, f64)> = Vec::new();
    let flush = |run: &mut Vec<(f64, f64, f64)>, s: &mut String| {
        if run.len() >= 2 {
            let lower = run.iter().map(|(x, lo, _)| format!("{x:.1},{lo:.1}"));
            let upper = run.iter().rev().map(|(x, _, hi)| format!("{x:.1},{hi:.1}"));
            let d: Vec<String> = lower.chain(upper).collect();
            let _ = writeln!(
                s,
                r#"<path fill="{0}" fill-opacity="{1}" stroke="{0}" stroke-opacity="{2}" stroke-width="0.7" d="M{3}Z"/>"#,
                se.color,
                se.opacity,
                (2.5 * se.opacity).min(1.0),
                d.join(" L")
            );
        }
        run.clear();
    };
    for (&(x, lo), &hi) in se.points.iter().zip(upper) {
        if f.ok(x, lo) && f.ok(x, hi) {
            run.push((f.px(x), clamp(lo), clamp(hi)));
        } else {
            flush(&mut run, s);
        }
    }
    flush(&mut run, s);
}

fn markers(s: &mut String, f: &Frame, se: &Series, radius: f64) {
    for &(x, y) in se.points.iter().filter(|&&(x, y)| f.ok(x, y)) {
        let _ = writeln!(
            s,
            r#"<circle cx="{:.1}" cy="{:.1}" r="{radius}" fill="{}" fill-opacity="{}"/>"#,
            f.px(x),
            f.py(y),
            se.color,
            se.opacity
        );
    }
}

fn bars(s: &mut String, f: &Frame, se: &Series, width: f64) {
    let base = f.base();
    for &(x, y) in &se.points {
        if f.ok(x, y) && f.ok(x - width / 2.0, y) {
            let (xa, xb) = (f.px(x - width / 2.0), f.px(x + width / 2.0));
            let (ya, yb) = (f.py(y), f.py(base));
            let _ = writeln!(
                s,
                r#"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="{}" fill-opacity="{}" stroke="white" stroke-width="0.5"/>"#,
                xa.min(xb),
                ya.min(yb),
                (xb - xa).abs(),
                (yb - ya).abs(),
                se.color,
                se.opacity
            );
        }
    }
}

fn vrules(s: &mut String, f: &Frame, se: &Series, dash: Option<&str>) {
    let dash = dash_attr(dash);
    for &(x, _) in &se.points {
        if x.is_finite() && (!f.xa.log || x > 0.0) {
            let _ = writeln!(
                s,
                r#"<line x1="{0:.1}" y1="{1}" x2="{0:.1}" y2="{2}" stroke="{3}" stroke-opacity="{4}" stroke-width="2"{dash}/>"#,
                f.px(x),
                f.oy,
                f.oy + f.h,
                se.color,
                se.opacity
            );
        }
    }
}

fn stems(s: &mut String, f: &Frame, se: &Series) {
    let base = f.base();
    for &(x, y) in se.points.iter().filter(|&&(x, y)| f.ok(x, y)) {
        let _ = writeln!(
            s,
            r#"<line x1="{0:.1}" y1="{1:.1}" x2="{0:.1}" y2="{2:.1}" stroke="{3}" stroke-opacity="{4}" stroke-width="2"/><circle cx="{0:.1}" cy="{1:.1}" r="3.5" fill="{3}" fill-opacity="{4}"/>"#,
            f.px(x),
            f.py(y),
            f.py(base),
            se.color,
            se.opacity
        );
    }
}

/// The legend, in the corner that hides the fewest points.
fn legend(s: &mut String, p: &Panel, f: &Frame) {
    let entries: Vec<&Series> = p.series.iter().filter(|se| !se.label.is_empty()).collect();
    if entries.is_empty() {
        return;
    }
    let lw = entries
        .iter()
        .map(|e| e.label.chars().count())
        .max()
        .unwrap_or(0) as f64
        * 6.8
        + 40.0;
    let lh = entries.len() as f64 * 16.0 + 8.0;
    let (lx, ly) = legend_corner(p, f, lw, lh);
    let _ = writeln!(
        s,
        r##"<rect x="{lx:.1}" y="{ly:.1}" width="{lw:.1}" height="{lh:.1}" fill="white" fill-opacity="0.85" stroke="#bbb"/>"##
    );
    for (i, e) in entries.iter().enumerate() {
        let y = ly + 14.0 + i as f64 * 16.0;
        let _ = writeln!(
            s,
            r#"{}<text x="{:.1}" y="{y:.1}">{}</text>"#,
            legend_symbol(e, lx, y),
            lx + 32.0,
            esc(&e.label)
        );
    }
}

/// Top right, top left, bottom right, bottom left: the first that hides the fewest points.
fn legend_corner(p: &Panel, f: &Frame, lw: f64, lh: f64) -> (f64, f64) {
    let (ox, oy, w, h) = (f.ox, f.oy, f.w, f.h);
    let corners = [
        (ox + w - lw - 8.0, oy + 8.0),
        (ox + 8.0, oy + 8.0),
        (ox + w - lw - 8.0, oy + h - lh - 8.0),
        (ox + 8.0, oy + h - lh - 8.0),
    ];
    let hides = |se: &Series, (cx, cy): (f64, f64), x: f64, y: f64| -> bool {
        if !f.ok(x, y) && !matches!(se.style, Style::VRule { .. }) {
            return false;
        }
        let gx = f.px(x);
        let inside_x = gx >= cx - 4.0 && gx <= cx + lw + 4.0;
        match se.style {
            Style::VRule { .. } => inside_x,
            Style::Bars { .. } | Style::Stems => inside_x && f.py(y) <= cy + lh + 4.0,
            _ => {
                let gy = f.py(y);
                inside_x && gy >= cy - 4.0 && gy <= cy + lh + 4.0
            }
        }
    };
    let hidden = |c: (f64, f64)| -> usize {
        p.series
            .iter()
            .map(|se| {
                se.points
                    .iter()
                    .filter(|&&(x, y)| hides(se, c, x, y))
                    .count()
            })
            .sum()
    };
    corners
        .iter()
        .copied()
        .enumerate()
        .min_by_key(|(i, c)| (hidden(*c), *i))
        .map_or(corners[0], |x| x.1)
}

/// The legend's sample of a series' style, ending at the baseline `y`.
fn legend_symbol(e: &Series, lx: f64, y: f64) -> String {
    match &e.style {
        Style::Markers { .. } => format!(
            r#"<circle cx="{:.1}" cy="{:.1}" r="3" fill="{}"/>"#,
            lx + 16.0,
            y - 4.0,
            e.color
        ),
        Style::Bars { .. } | Style::Band { .. } => format!(
            r#"<rect x="{:.1}" y="{:.1}" width="14" height="9" fill="{}" fill-opacity="{}"/>"#,
            lx + 9.0,
            y - 9.0,
            e.color,
            e.opacity
        ),
        Style::Line { dash, .. } | Style::VRule { dash } => format!(
            r#"<line x1="{:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" stroke="{}" stroke-width="2"{}/>"#,
            lx + 6.0,
            y - 4.0,
            lx + 26.0,
            y - 4.0,
            e.color,
            dash_attr(*dash)
        ),
        Style::Stems => format!(
            r#"<line x1="{0:.1}" y1="{1:.1}" x2="{0:.1}" y2="{2:.1}" stroke="{3}" stroke-width="2"/>"#,
            lx + 16.0,
            y - 10.0,
            y,
            e.color
        ),
    }
}

/// The min/max envelope of points in order of `x`, in runs of `⌈n / buckets⌉` consecutive
/// points (at most `buckets` runs, the last one shorter): `(x at the run's middle, least y,
/// greatest y)` per run. A long record drawn point by point is
/// a tangle of overlapping markers; its envelope shows the same spread, and every extreme
/// sample stays inside it. Non-finite values are left out of a run; a run without a finite
/// value is left out.
pub fn envelope(points: &[(f64, f64)], buckets: usize) -> Vec<(f64, f64, f64)> {
    let buckets = buckets.clamp(1, points.len().max(1));
    let size = points.len().div_ceil(buckets).max(1);
    points
        .chunks(size)
        .filter_map(|run| {
            let finite = run.iter().filter(|p| p.0.is_finite() && p.1.is_finite());
            let (lo, hi) = finite
                .clone()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                    (a.min(p.1), b.max(p.1))
                });
            let xs: Vec<f64> = finite.map(|p| p.0).collect();
            let x = (xs.first()? + xs.last()?) / 2.0;
            Some((x, lo, hi))
        })
        .collect()
}

/// A histogram of `values` with about `√n` bins (at most 30): bar centres, counts, bin width.
pub fn histogram(values: &[f64]) -> (Vec<(f64, f64)>, f64) {
    let v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return (Vec::new(), 1.0);
    }
    let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if v.iter().all(|x| x.fract() == 0.0) && hi - lo <= 40.0 {
        // Whole numbers (the profiled n): one bar per value.
        let mut counts = vec![0usize; (hi - lo) as usize + 1];
        for x in &v {
            counts[(x - lo) as usize] += 1;
        }
        return (
            counts
                .iter()
                .enumerate()
                .map(|(i, &c)| (lo + i as f64, c as f64))
                .collect(),
            0.9,
        );
    }
    let bins = ((v.len() as f64).sqrt().ceil() as usize).clamp(1, 30);
    let width = if hi > lo {
        (hi - lo) / bins as f64
    } else {
        (lo.abs() * 0.01).max(1e-6)
    };
    let mut counts = vec![0usize; bins];
    for x in &v {
        let i = if hi > lo {
            (((x - lo) / width) as usize).min(bins - 1)
        } else {
            0
        };
        counts[i] += 1;
    }
    let base = if hi > lo { lo } else { lo - width / 2.0 };
    (
        counts
            .iter()
            .enumerate()
            .map(|(i, &c)| (base + (i as f64 + 0.5) * width, c as f64))
            .collect(),
        width,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn figure_is_wellformed_even_without_data() {
        let p = Panel {
            title: "t <&>".into(),
            series: vec![Series::line("a", BLUE, vec![(f64::NAN, 1.0)])],
            ..Default::default()
        };
        let s = figure("x", "y", &[p], 1);
        assert!(s.starts_with("<svg") && s.ends_with("</svg>\n"));
        assert!(s.contains("no finite data") && s.contains("t &lt;&amp;&gt;"));
        assert_eq!(
            esc("a\u{1}\u{1b}\tb\u{ffff}é"),
            "a\u{fffd}\u{fffd}\tb\u{fffd}é"
        );
    }

    #[test]
    fn ticks_are_nice() {
        let (_, _, t, step) = linear_ticks(0.013, 0.48);
        assert_eq!(step, 0.1);
        assert!(t.len() >= 5 && t.len() <= 7);
        let (h, w) = histogram(&[1.5, 2.5, 3.5, 4.5]);
        assert_eq!(h.len(), 2);
        assert!((w - 1.5).abs() < 1e-12);
        let (h, _) = histogram(&[0.0, 0.0, 3.0]);
        assert_eq!(h, vec![(0.0, 2.0), (1.0, 0.0), (2.0, 0.0), (3.0, 1.0)]);
    }

    /// The envelope keeps every sample's extremes: each run's band holds its points, the
    /// runs cover all points in order, and a run of non-finite values is left out.
    #[test]
    fn the_envelope_holds_every_point() {
        let pts: Vec<(f64, f64)> = (0..601)
            .map(|k| (k as f64, (k as f64 * 0.7).sin() * (1.0 + k as f64 / 100.0)))
            .collect();
        let env = envelope(&pts, 150);
        let size = 601usize.div_ceil(150);
        assert_eq!((size, env.len()), (5, 121));
        for (run, &(x, lo, hi)) in pts.chunks(size).zip(&env) {
            assert!(run.iter().all(|p| p.1 >= lo && p.1 <= hi), "{x}");
            assert!(run.iter().any(|p| p.1 == lo) && run.iter().any(|p| p.1 == hi));
            assert!(x >= run[0].0 && x <= run[run.len() - 1].0);
        }
        let gap = [(0.0, 1.0), (1.0, f64::NAN), (2.0, f64::NAN), (3.0, 2.0)];
        assert_eq!(envelope(&gap, 4), vec![(0.0, 1.0, 1.0), (3.0, 2.0, 2.0)]);
        assert!(envelope(&[], 10).is_empty());
    }

    /// The band is one closed path around both edges, broken where an edge cannot be drawn,
    /// and its upper edge widens the y range.
    #[test]
    fn a_band_is_a_closed_path_per_drawable_run() {
        let pts = [
            (1.0, 0.0, 1.0),
            (2.0, 0.5, 2.0),
            (3.0, f64::NAN, 2.0),
            (4.0, 0.0, 1.0),
            (5.0, 0.0, 10.0),
        ];
        let p = Panel {
            series: vec![Series::band("±2σ", BLUE, &pts)],
            ..Default::default()
        };
        let (_, yr) = data_ranges(&p);
        assert!(yr.unwrap().1 >= 10.0, "{yr:?}");
        let s = figure("x", "y", &[p], 1);
        assert_eq!(s.matches("<path ").count(), 2, "{s}");
        let first = s.split("<path ").nth(1).unwrap();
        // Four corners: two along the lower edge, two back along the upper one.
        let d = first
            .split(" d=\"M")
            .nth(1)
            .unwrap()
            .split('Z')
            .next()
            .unwrap();
        assert_eq!(d.split(" L").count(), 4, "{d}");
        // The legend shows a filled swatch.
        assert!(s.contains("±2σ"));
    }
}
