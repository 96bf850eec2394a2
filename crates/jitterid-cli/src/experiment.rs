//! Experiment files (TOML): parsing and validation into an [`Experiment`].
//!
//! Every error is one line that names the file, the line and the key, and says what was
//! expected. The key names are documented in `docs/experiments.md`.

use crate::cli_err;
use crate::csvio;
use crate::error::{CliError, CliResult};
use crate::models::{AnyJitter, AnyNoise};
use jitterid::estimate::{ArmaNoise, Frequencies};
use jitterid::jitter::{
    ExponentialDelay, Gaussian, JitterModel, Laplace, NoJitter, Shifted, TwoPoint, UniformSum,
};
use jitterid::signal::{
    Input, Multisine, PiecewiseConstant, RandomBinary, Root, SampleGrid, Sinusoid, Tone,
    TransferFunction, Zpk,
};
use serde::Deserialize;
use std::ops::Range;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// Largest number of samples accepted.
pub const MAX_SAMPLES: i64 = 10_000_000;
/// Largest expected number of switches of a random binary input over its span.
pub const MAX_SWITCHES: f64 = 1e6;

/// How the input is obtained.
#[derive(Debug, Clone, PartialEq)]
pub enum InputSpec {
    /// No input (a sinusoid system).
    None,
    /// A random binary input, drawn per realisation from the seed.
    RandomBinary(RandomBinary),
    /// A known input.
    Known(Input),
}

/// The system kind with its parameters (the truth in `simulate`/`montecarlo`, the start in
/// `fit`).
#[derive(Debug, Clone, PartialEq)]
pub enum SystemKind {
    /// Zeros, poles, gain.
    Zpk(Zpk),
    /// Polynomial transfer function.
    Tf(TransferFunction),
    /// A sinusoid `A sin(2πft + φ)` (no input).
    Sinusoid(Sinusoid),
}

/// The `[system]` section.
#[derive(Debug, Clone, PartialEq)]
pub struct SystemSpec {
    /// The model.
    pub kind: SystemKind,
    /// Whether its parameters are estimated.
    pub estimate: bool,
}

/// The `[jitter]` section.
#[derive(Debug, Clone, PartialEq)]
pub struct JitterSpec {
    /// The family and parameters given (the truth in `simulate`/`montecarlo`).
    pub truth: AnyJitter,
    /// The model's family for fitting, started at the truth's standard deviation (equal to
    /// `truth` unless `fit_family` is given).
    pub model: AnyJitter,
    /// Whether the model's parameters are estimated.
    pub estimate: bool,
    /// For an estimated uniform-sum model: the range of `n` profiled over (inclusive).
    pub n_range: Option<(u32, u32)>,
    /// Whether the fitted family differs from the given one (its parameters have no truth).
    pub family_differs: bool,
}

/// The `[noise]` section.
#[derive(Debug, Clone, PartialEq)]
pub struct NoiseSpec {
    /// Standard deviation of the white noise `e_k` (of `v_k` itself for white noise).
    pub std: f64,
    /// The noise shape `H`.
    pub shape: AnyNoise,
    /// Whether the noise level (and, with method `bj`, the shape) is estimated.
    pub estimate: bool,
}

/// Estimation method.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// Naive least squares (jitter ignored).
    Ls,
    /// Bias-compensated least squares.
    Bcls,
    /// The Box–Jenkins frequency-domain criterion (BCLS weighted by the noise shape).
    Bj,
    /// Maximum likelihood.
    Ml,
}

impl Method {
    /// The name used in files and on the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            Method::Ls => "ls",
            Method::Bcls => "bcls",
            Method::Bj => "bj",
            Method::Ml => "ml",
        }
    }

    /// Parses a method name.
    pub fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "ls" => Method::Ls,
            "bcls" => Method::Bcls,
            "bj" => Method::Bj,
            "ml" => Method::Ml,
            _ => return None,
        })
    }
}

/// Solver kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SolverKind {
    /// Levenberg–Marquardt.
    Lm,
    /// Gauss–Newton with line search.
    GaussNewton,
    /// Nelder–Mead.
    NelderMead,
}

/// The `[estimate]` section.
#[derive(Debug, Clone, PartialEq)]
pub struct EstimateSpec {
    /// The method.
    pub method: Method,
    /// The frequency set.
    pub frequencies: Frequencies,
    /// The solver.
    pub solver: SolverKind,
    /// Number of extra, perturbed starts.
    pub multistart: usize,
    /// Relative radius of the multistart perturbations.
    pub multistart_radius: f64,
    /// Relative size of the seeded start perturbation in Monte Carlo.
    pub perturb: f64,
    /// Iteration limit of the solver (its default if `None`).
    pub max_iterations: Option<u64>,
    /// Wall-clock budget of each fit in seconds (the solver's default if `None`); set from the
    /// command line.
    pub max_seconds: Option<f64>,
}

/// A validated experiment.
#[derive(Debug, Clone, PartialEq)]
pub struct Experiment {
    /// The file's name, for messages.
    pub file: String,
    /// The directory relative paths are resolved from.
    pub dir: PathBuf,
    /// An optional title.
    pub title: Option<String>,
    /// The sampling grid.
    pub grid: SampleGrid,
    /// The input.
    pub input: InputSpec,
    /// The system.
    pub system: SystemSpec,
    /// The jitter.
    pub jitter: JitterSpec,
    /// The measurement noise.
    pub noise: NoiseSpec,
    /// How to estimate.
    pub estimate: EstimateSpec,
    /// Line of every key given, as (section, key, line).
    key_lines: Vec<(&'static str, &'static str, usize)>,
    /// Line of every section header given.
    section_lines: Vec<(&'static str, usize)>,
}

impl Experiment {
    /// An error about a key of the file: `file:line: [section] key: message`.
    pub fn error_at(&self, section: &str, key: &str, message: impl std::fmt::Display) -> CliError {
        let line = self
            .key_lines
            .iter()
            .find(|(s, k, _)| *s == section && *k == key)
            .map(|x| x.2)
            .or_else(|| {
                self.section_lines
                    .iter()
                    .find(|(s, _)| *s == section)
                    .map(|x| x.1)
            });
        match line {
            Some(l) => cli_err!("{}:{l}: [{section}] {key}: {message}", self.file),
            None => cli_err!("{}: [{section}] {key}: {message}", self.file),
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Raw sections: every key optional and spanned, unknown keys rejected.

macro_rules! section {
    ($name:ident, $title:literal { $($field:ident : $ty:ty),* $(,)? }) => {
        #[derive(Debug, Deserialize)]
        #[serde(deny_unknown_fields, rename = $title)]
        struct $name {
            $( #[serde(default)] $field: Option<Spanned<$ty>>, )*
        }
        impl $name {
            const KEYS: &'static [&'static str] = &[$(stringify!($field)),*];
            fn present(&self) -> Vec<(&'static str, Range<usize>)> {
                #[allow(unused_mut)]
                let mut v = Vec::new();
                $( if let Some(s) = &self.$field { v.push((stringify!($field), s.span())); } )*
                v
            }
        }
    };
}

section!(RawSampling, "table [sampling]" {
    interval: f64,
    samples: i64,
    start: f64,
});

section!(RawInput, "table [input]" {
    kind: String,
    mean_dwell: f64,
    low: f64,
    high: f64,
    frequency: f64,
    amplitude: f64,
    phase: f64,
    frequencies: Vec<f64>,
    amplitudes: Vec<f64>,
    phases: Vec<f64>,
    times: Vec<f64>,
    values: Vec<f64>,
    path: String,
    time_column: String,
    value_column: String,
});

section!(RawSystem, "table [system]" {
    kind: String,
    gain: f64,
    zeros: Vec<toml::Value>,
    poles: Vec<toml::Value>,
    num: Vec<f64>,
    den: Vec<f64>,
    amplitude: f64,
    frequency: f64,
    phase: f64,
    estimate: bool,
});

section!(RawJitter, "table [jitter]" {
    family: String,
    n: i64,
    a: f64,
    sigma: f64,
    scale: f64,
    d: f64,
    mean: f64,
    offset: f64,
    estimate: bool,
    fit_family: String,
    n_range: Vec<i64>,
});

section!(RawNoise, "table [noise]" {
    std: f64,
    model: String,
    c: Vec<f64>,
    d: Vec<f64>,
    estimate: bool,
});

section!(RawEstimate, "table [estimate]" {
    method: String,
    frequencies: toml::Value,
    solver: String,
    multistart: i64,
    multistart_radius: f64,
    perturb: f64,
    max_iterations: i64,
});

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, rename = "experiment file")]
struct RawExperiment {
    #[serde(default)]
    title: Option<String>,
    #[serde(default)]
    sampling: Option<RawSampling>,
    #[serde(default)]
    input: Option<RawInput>,
    #[serde(default)]
    system: Option<RawSystem>,
    #[serde(default)]
    jitter: Option<RawJitter>,
    #[serde(default)]
    noise: Option<RawNoise>,
    #[serde(default)]
    estimate: Option<RawEstimate>,
}

const SECTIONS: &[&str] = &[
    "title", "sampling", "input", "system", "jitter", "noise", "estimate",
];

fn keys_of(section: &str) -> &'static [&'static str] {
    match section {
        "sampling" => RawSampling::KEYS,
        "input" => RawInput::KEYS,
        "system" => RawSystem::KEYS,
        "jitter" => RawJitter::KEYS,
        "noise" => RawNoise::KEYS,
        "estimate" => RawEstimate::KEYS,
        _ => SECTIONS,
    }
}

// ---------------------------------------------------------------------------------------------
// Locating errors in the text.

/// 1-based line of a byte offset.
fn line_of(text: &str, offset: usize) -> usize {
    let end = offset.min(text.len());
    text.as_bytes()[..end]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// The section header in force at `line` (the last `[name]` at or before it).
fn section_at(text: &str, line: usize) -> Option<String> {
    text.lines()
        .take(line)
        .filter_map(|l| {
            let l = l.trim();
            let inner = l.strip_prefix('[')?.split(']').next()?.trim();
            (!inner.starts_with('[') && !inner.is_empty()).then(|| inner.to_string())
        })
        .last()
}

/// The bare key defined on `line`, if the line reads `key = …`.
fn key_on_line(text: &str, line: usize) -> Option<String> {
    let l = text.lines().nth(line.checked_sub(1)?)?;
    let (k, _) = l.split_once('=')?;
    let k = k.trim();
    (!k.is_empty()
        && k.chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-' || c == '.'))
    .then(|| k.to_string())
}

fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for i in 1..=a.len() {
        let mut cur = vec![i; b.len() + 1];
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            cur[j] = (prev[j] + 1).min(cur[j - 1] + 1).min(prev[j - 1] + cost);
        }
        prev = cur;
    }
    prev[b.len()]
}

fn suggestion(unknown: &str, known: &[&'static str]) -> Option<&'static str> {
    known
        .iter()
        .map(|k| (edit_distance(unknown, k), *k))
        .filter(|(d, k)| *d <= 2 && *d < k.len())
        .min()
        .map(|x| x.1)
}

/// Turns a TOML/serde error into one located line.
fn toml_error(file: &str, text: &str, e: &toml::de::Error) -> CliError {
    let line = e.span().map(|s| line_of(text, s.start));
    let section = line.and_then(|l| section_at(text, l));
    let mut msg = e.message().trim().to_string();
    let mut key = line.and_then(|l| key_on_line(text, l));
    if let Some(rest) = msg.strip_prefix("unknown field `") {
        let name = rest.split('`').next().unwrap_or("").to_string();
        let known = keys_of(section.as_deref().unwrap_or(""));
        let list = known
            .iter()
            .filter(|k| **k != "title" || section.is_none())
            .map(|k| k.to_string())
            .collect::<Vec<_>>()
            .join(", ");
        msg = match suggestion(&name, known) {
            Some(s) => {
                format!("unknown key `{name}` (did you mean `{s}`?); expected one of {list}")
            }
            None => format!("unknown key `{name}`; expected one of {list}"),
        };
        key = None;
    } else if let Some(rest) = msg.strip_prefix("missing field `") {
        let name = rest.split('`').next().unwrap_or("");
        msg = format!("missing key `{name}`");
        key = None;
    }
    msg = msg
        .replace("expected i64", "expected a whole number")
        .replace("expected f64", "expected a number")
        .replace("expected a sequence", "expected a list")
        .replace("expected struct table ", "expected the table ")
        .replace(
            "expected struct experiment file",
            "expected a table of sections",
        );
    let section = section.map(|s| format!("[{s}] ")).unwrap_or_default();
    let key = key.map(|k| format!("{k}: ")).unwrap_or_default();
    match line {
        Some(l) => cli_err!("{file}:{l}: {section}{key}{msg}"),
        None => cli_err!("{file}: {section}{key}{msg}"),
    }
}

// ---------------------------------------------------------------------------------------------
// Validation helpers.

struct Ctx<'a> {
    file: &'a str,
    text: &'a str,
    dir: PathBuf,
    key_lines: Vec<(&'static str, &'static str, usize)>,
    section_lines: Vec<(&'static str, usize)>,
}

impl Ctx<'_> {
    fn err(
        &self,
        section: &str,
        key: &str,
        span: &Range<usize>,
        msg: impl std::fmt::Display,
    ) -> CliError {
        cli_err!(
            "{}:{}: [{section}] {key}: {msg}",
            self.file,
            line_of(self.text, span.start)
        )
    }

    fn header_line(&self, section: &str) -> Option<usize> {
        self.section_lines
            .iter()
            .find(|(s, _)| *s == section)
            .map(|x| x.1)
    }

    fn err_section(&self, section: &str, key: &str, msg: impl std::fmt::Display) -> CliError {
        match self.header_line(section) {
            Some(l) => cli_err!("{}:{l}: [{section}] {key}: {msg}", self.file),
            None => cli_err!("{}: [{section}] {key}: {msg}", self.file),
        }
    }

    fn record(&mut self, section: &'static str, present: Vec<(&'static str, Range<usize>)>) {
        for (k, span) in present {
            self.key_lines
                .push((section, k, line_of(self.text, span.start)));
        }
    }

    /// Rejects keys that exist in the section but do not apply to the chosen kind.
    fn only(
        &self,
        section: &str,
        present: &[(&'static str, Range<usize>)],
        selector: &str,
        allowed: &[&str],
        what: &str,
    ) -> CliResult<()> {
        for (k, span) in present {
            if !allowed.contains(k) {
                return Err(self.err(
                    section,
                    k,
                    span,
                    format!(
                        "not a key of {selector} = \"{what}\"; expected {}",
                        allowed.join(", ")
                    ),
                ));
            }
        }
        Ok(())
    }

    fn required<'v, T>(
        &self,
        section: &str,
        key: &str,
        v: &'v Option<Spanned<T>>,
        why: &str,
    ) -> CliResult<&'v Spanned<T>> {
        v.as_ref()
            .ok_or_else(|| self.err_section(section, key, format!("missing; {why}")))
    }

    fn finite(&self, section: &str, key: &str, v: &Spanned<f64>) -> CliResult<f64> {
        let x = *v.get_ref();
        if x.is_finite() {
            Ok(x)
        } else {
            Err(self.err(
                section,
                key,
                &v.span(),
                format!("expected a finite number, found {x}"),
            ))
        }
    }

    fn positive(&self, section: &str, key: &str, v: &Spanned<f64>) -> CliResult<f64> {
        let x = self.finite(section, key, v)?;
        if x > 0.0 {
            Ok(x)
        } else {
            Err(self.err(
                section,
                key,
                &v.span(),
                format!("expected a number > 0, found {x}"),
            ))
        }
    }

    fn opt_finite(
        &self,
        section: &str,
        key: &str,
        v: &Option<Spanned<f64>>,
        default: f64,
    ) -> CliResult<f64> {
        v.as_ref()
            .map_or(Ok(default), |v| self.finite(section, key, v))
    }

    fn finite_list(&self, section: &str, key: &str, v: &Spanned<Vec<f64>>) -> CliResult<Vec<f64>> {
        for (i, x) in v.get_ref().iter().enumerate() {
            if !x.is_finite() {
                return Err(self.err(
                    section,
                    key,
                    &v.span(),
                    format!("element {}: expected a finite number, found {x}", i + 1),
                ));
            }
        }
        Ok(v.get_ref().clone())
    }
}

fn number(v: &toml::Value) -> Option<f64> {
    match v {
        toml::Value::Float(x) => Some(*x),
        toml::Value::Integer(i) => Some(*i as f64),
        _ => None,
    }
}

fn describe(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => format!("the string {s:?}"),
        toml::Value::Integer(i) => format!("the integer {i}"),
        toml::Value::Float(x) => format!("the number {x}"),
        toml::Value::Boolean(b) => format!("the boolean {b}"),
        toml::Value::Datetime(d) => format!("the date {d}"),
        toml::Value::Array(a) => format!("an array of {} element(s)", a.len()),
        toml::Value::Table(_) => "a table".to_string(),
    }
}

// ---------------------------------------------------------------------------------------------

/// Reads and validates an experiment file.
pub fn read(path: &Path) -> CliResult<Experiment> {
    let file = path.display().to_string();
    csvio::check_regular_file(path, &file)?;
    let bytes = std::fs::read(path)
        .map_err(|e| cli_err!("{file}: cannot read: {}", csvio::io_reason(&e)))?;
    let text = String::from_utf8(bytes).map_err(|e| {
        cli_err!(
            "{file}: not UTF-8 text (invalid byte at offset {}); expected a TOML experiment file",
            e.utf8_error().valid_up_to()
        )
    })?;
    let dir = path
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."));
    parse(&file, &text, &dir)
}

/// Parses and validates experiment text; `file` names it in messages, `dir` resolves relative
/// paths.
pub fn parse(file: &str, text: &str, dir: &Path) -> CliResult<Experiment> {
    let raw: RawExperiment = toml::from_str(text).map_err(|e| toml_error(file, text, &e))?;
    let mut section_lines = Vec::new();
    for (i, l) in text.lines().enumerate() {
        let l = l.trim();
        if let Some(inner) = l.strip_prefix('[').and_then(|r| r.split(']').next()) {
            let inner = inner.trim();
            if let Some(s) = SECTIONS.iter().find(|s| **s == inner) {
                section_lines.push((*s, i + 1));
            }
        }
    }
    let mut cx = Ctx {
        file,
        text,
        dir: dir.to_path_buf(),
        key_lines: Vec::new(),
        section_lines,
    };
    let sampling = raw
        .sampling
        .as_ref()
        .ok_or_else(|| cli_err!("{file}: missing section [sampling]; expected keys interval, samples and optionally start"))?;
    let system = raw
        .system
        .as_ref()
        .ok_or_else(|| cli_err!("{file}: missing section [system]; expected kind = \"zpk\", \"tf\" or \"sinusoid\" and its keys"))?;
    cx.record("sampling", sampling.present());
    cx.record("system", system.present());
    if let Some(s) = &raw.input {
        cx.record("input", s.present());
    }
    if let Some(s) = &raw.jitter {
        cx.record("jitter", s.present());
    }
    if let Some(s) = &raw.noise {
        cx.record("noise", s.present());
    }
    if let Some(s) = &raw.estimate {
        cx.record("estimate", s.present());
    }

    let grid = parse_sampling(&cx, sampling)?;
    let system = parse_system(&cx, system)?;
    let input = match (&system.kind, &raw.input) {
        (SystemKind::Sinusoid(_), None) => InputSpec::None,
        (SystemKind::Sinusoid(_), Some(r)) => {
            let span = r.kind.as_ref().map(|k| k.span()).unwrap_or(0..0);
            return Err(match r.kind {
                Some(_) => cx.err("input", "kind", &span, "a sinusoid system has no input; remove the [input] section"),
                None => cx.err_section("input", "kind", "a sinusoid system has no input; remove the [input] section"),
            });
        }
        (_, None) => {
            return Err(cli_err!(
                "{file}: missing section [input]; a {} system needs an input (kind = \"random-binary\", \"sine\", \"multisine\", \"piecewise\" or \"csv\")",
                match system.kind { SystemKind::Zpk(_) => "zpk", _ => "tf" }
            ))
        }
        (_, Some(r)) => parse_input(&cx, r, &grid)?,
    };
    let jitter = match &raw.jitter {
        Some(r) => parse_jitter(&cx, r)?,
        None => JitterSpec {
            truth: AnyJitter::None(NoJitter),
            model: AnyJitter::None(NoJitter),
            estimate: false,
            n_range: None,
            family_differs: false,
        },
    };
    let noise = match &raw.noise {
        Some(r) => parse_noise(&cx, r)?,
        None => NoiseSpec {
            std: 0.0,
            shape: AnyNoise::White,
            estimate: false,
        },
    };
    let estimate = match &raw.estimate {
        Some(r) => parse_estimate(&cx, r, &grid)?,
        None => EstimateSpec {
            method: Method::Bcls,
            frequencies: Frequencies::Dft,
            solver: SolverKind::Lm,
            multistart: 0,
            multistart_radius: 0.5,
            perturb: 0.2,
            max_iterations: None,
            max_seconds: None,
        },
    };
    Ok(Experiment {
        file: file.to_string(),
        dir: cx.dir.clone(),
        title: raw.title.clone(),
        grid,
        input,
        system,
        jitter,
        noise,
        estimate,
        key_lines: cx.key_lines,
        section_lines: cx.section_lines,
    })
}

fn parse_sampling(cx: &Ctx, r: &RawSampling) -> CliResult<SampleGrid> {
    const S: &str = "sampling";
    let interval = cx.required(
        S,
        "interval",
        &r.interval,
        "expected the sampling interval T in seconds",
    )?;
    let interval = cx.positive(S, "interval", interval)?;
    let samples = cx.required(S, "samples", &r.samples, "expected the number of samples N")?;
    let n = *samples.get_ref();
    if !(1..=MAX_SAMPLES).contains(&n) {
        return Err(cx.err(
            S,
            "samples",
            &samples.span(),
            format!("expected a whole number in [1, {MAX_SAMPLES}], found {n}"),
        ));
    }
    let start = cx.opt_finite(S, "start", &r.start, 0.0)?;
    let end = start + n as f64 * interval;
    if !end.is_finite() || (end - start) <= 0.0 || interval <= end.abs().max(start.abs()) * 1e-12 {
        let span = r.interval.as_ref().map(|s| s.span()).unwrap_or(0..0);
        return Err(cx.err(
            S,
            "interval",
            &span,
            "too small for the record's times to be told apart in double precision",
        ));
    }
    SampleGrid::new(start, interval, n as usize).map_err(|e| cx.err_section(S, "interval", e))
}

fn parse_input(cx: &Ctx, r: &RawInput, grid: &SampleGrid) -> CliResult<InputSpec> {
    const S: &str = "input";
    let present = r.present();
    let kind = cx.required(
        S,
        "kind",
        &r.kind,
        "expected kind = \"random-binary\", \"sine\", \"multisine\", \"piecewise\" or \"csv\"",
    )?;
    let kspan = kind.span();
    let kind = kind.get_ref().as_str();
    match kind {
        "random-binary" => {
            cx.only(S, &present, "kind", &["kind", "mean_dwell", "low", "high"], kind)?;
            let dwell = cx.required(S, "mean_dwell", &r.mean_dwell, "expected the mean time between switches in seconds")?;
            let mean_dwell = cx.positive(S, "mean_dwell", dwell)?;
            let low = cx.opt_finite(S, "low", &r.low, 0.0)?;
            let high = cx.opt_finite(S, "high", &r.high, 1.0)?;
            let (a, b) = input_span(grid);
            if (b - a) / mean_dwell > MAX_SWITCHES || mean_dwell < 1e-9 * a.abs().max(b.abs()) {
                return Err(cx.err(S, "mean_dwell", &dwell.span(), format!("too short for a record of {} s (at most {MAX_SWITCHES:e} switches)", b - a)));
            }
            let rb = RandomBinary::new(mean_dwell, low, high).map_err(|e| cx.err(S, "mean_dwell", &dwell.span(), e))?;
            Ok(InputSpec::RandomBinary(rb))
        }
        "sine" => {
            cx.only(S, &present, "kind", &["kind", "frequency", "amplitude", "phase"], kind)?;
            let f = cx.required(S, "frequency", &r.frequency, "expected the frequency in Hz")?;
            let frequency = cx.finite(S, "frequency", f)?;
            if frequency < 0.0 {
                return Err(cx.err(S, "frequency", &f.span(), format!("expected a frequency >= 0 Hz, found {frequency}")));
            }
            let amplitude = cx.opt_finite(S, "amplitude", &r.amplitude, 1.0)?;
            let phase = cx.opt_finite(S, "phase", &r.phase, 0.0)?;
            let m = Multisine::sine(frequency, amplitude, phase).map_err(|e| cx.err(S, "frequency", &f.span(), e))?;
            Ok(InputSpec::Known(Input::Tones(m)))
        }
        "multisine" => {
            cx.only(S, &present, "kind", &["kind", "frequencies", "amplitudes", "phases"], kind)?;
            let fs = cx.required(S, "frequencies", &r.frequencies, "expected a list of frequencies in Hz")?;
            let freqs = cx.finite_list(S, "frequencies", fs)?;
            if freqs.is_empty() {
                return Err(cx.err(S, "frequencies", &fs.span(), "expected at least one frequency"));
            }
            if let Some(f) = freqs.iter().find(|f| **f < 0.0) {
                return Err(cx.err(S, "frequencies", &fs.span(), format!("expected frequencies >= 0 Hz, found {f}")));
            }
            let list = |key: &'static str, v: &Option<Spanned<Vec<f64>>>, default: f64| -> CliResult<Vec<f64>> {
                match v {
                    None => Ok(vec![default; freqs.len()]),
                    Some(v) => {
                        let l = cx.finite_list(S, key, v)?;
                        if l.len() != freqs.len() {
                            return Err(cx.err(S, key, &v.span(), format!("expected {} values (one per frequency), found {}", freqs.len(), l.len())));
                        }
                        Ok(l)
                    }
                }
            };
            let amps = list("amplitudes", &r.amplitudes, 1.0)?;
            let phases = list("phases", &r.phases, 0.0)?;
            let tones = freqs
                .iter()
                .zip(&amps)
                .zip(&phases)
                .map(|((&frequency, &amplitude), &phase)| Tone { frequency, amplitude, phase })
                .collect();
            let m = Multisine::new(tones).map_err(|e| cx.err(S, "frequencies", &fs.span(), e))?;
            Ok(InputSpec::Known(Input::Tones(m)))
        }
        "piecewise" => {
            cx.only(S, &present, "kind", &["kind", "times", "values"], kind)?;
            let ts = cx.required(S, "times", &r.times, "expected the switch times in seconds")?;
            let vs = cx.required(S, "values", &r.values, "expected the input level from each switch time on")?;
            let times = cx.finite_list(S, "times", ts)?;
            let values = cx.finite_list(S, "values", vs)?;
            let p = piecewise(&times, &values, grid).map_err(|m| cx.err(S, "times", &ts.span(), m))?;
            Ok(InputSpec::Known(Input::Piecewise(p)))
        }
        "csv" => {
            cx.only(S, &present, "kind", &["kind", "path", "time_column", "value_column"], kind)?;
            let p = cx.required(S, "path", &r.path, "expected the path of a CSV file (relative to the experiment file)")?;
            let tc = r.time_column.as_ref().map_or("t", |s| s.get_ref().as_str());
            let vc = r.value_column.as_ref().map_or("u", |s| s.get_ref().as_str());
            let path = cx.dir.join(p.get_ref());
            let table = csvio::read(&path)?;
            let p = piecewise_from_table(&table, tc, vc, grid)?;
            Ok(InputSpec::Known(Input::Piecewise(p)))
        }
        other => Err(cx.err(S, "kind", &kspan, format!("unknown input kind \"{other}\"; expected \"random-binary\", \"sine\", \"multisine\", \"piecewise\" or \"csv\""))),
    }
}

/// The span `[t0, t0 + (N+1)T)` on which a random binary input is drawn.
pub fn input_span(grid: &SampleGrid) -> (f64, f64) {
    let t0 = grid.start();
    (t0, t0 + (grid.len() as f64 + 1.0) * grid.interval())
}

/// A piecewise-constant input from switch times and levels: `u = values[j]` from `times[j]` to
/// the next time; with one more time than values the last time ends the input (zero after it),
/// otherwise the last level holds until `t0 + 2NT` (well after the record).
pub fn piecewise(
    times: &[f64],
    values: &[f64],
    grid: &SampleGrid,
) -> Result<PiecewiseConstant, String> {
    if values.is_empty() {
        return Err("expected at least one switch time and level".into());
    }
    let mut edges = times.to_vec();
    if times.len() == values.len() {
        let last = times[times.len() - 1];
        let hold =
            (grid.start() + 2.0 * grid.duration() + grid.interval()).max(last + grid.interval());
        edges.push(hold);
    } else if times.len() != values.len() + 1 {
        return Err(format!(
            "expected as many times as values ({}), or one more to end the input; found {} times",
            values.len(),
            times.len()
        ));
    }
    for (i, w) in edges.windows(2).enumerate() {
        if w[1] <= w[0] {
            return Err(format!(
                "times must increase strictly: element {} ({}) is not above the one before ({})",
                i + 2,
                w[1],
                w[0]
            ));
        }
    }
    PiecewiseConstant::new(edges, values.to_vec()).map_err(|e| e.to_string())
}

/// A piecewise-constant input from two columns of a CSV table (see [`piecewise`]); a last row
/// with level 0 ends the input at its time.
pub fn piecewise_from_table(
    table: &csvio::Table,
    time_column: &str,
    value_column: &str,
    grid: &SampleGrid,
) -> CliResult<PiecewiseConstant> {
    let t = table.column(time_column)?;
    let u = table.column(value_column)?;
    for i in 1..t.len() {
        if t[i] <= t[i - 1] {
            return Err(cli_err!(
                "{}:{}: column `{time_column}`: times must increase strictly; {} is not above {}",
                table.name,
                table.lines[i],
                t[i],
                t[i - 1]
            ));
        }
    }
    let (times, values) = if t.len() >= 2 && u[u.len() - 1] == 0.0 {
        (t.to_vec(), u[..u.len() - 1].to_vec())
    } else {
        (t.to_vec(), u.to_vec())
    };
    piecewise(&times, &values, grid)
        .map_err(|m| cli_err!("{}:{}: {m}", table.name, table.header_line))
}

fn parse_roots(cx: &Ctx, key: &str, v: &Spanned<Vec<toml::Value>>) -> CliResult<Vec<Root>> {
    let mut out = Vec::new();
    for (i, e) in v.get_ref().iter().enumerate() {
        let bad = |what: String| {
            cx.err("system", key, &v.span(), format!(
                "element {}: expected a number (a real root) or [re, im] with im > 0 (a complex pair), found {what}",
                i + 1
            ))
        };
        let root = match e {
            toml::Value::Array(a) if a.len() == 2 => match (number(&a[0]), number(&a[1])) {
                (Some(re), Some(im)) if re.is_finite() && im.is_finite() && im > 0.0 => {
                    Root::Pair { re, im }
                }
                (Some(re), Some(im)) => return Err(bad(format!("[{re}, {im}]"))),
                _ => return Err(bad(describe(e))),
            },
            other => match number(other) {
                Some(x) if x.is_finite() => Root::Real(x),
                Some(x) => return Err(bad(format!("{x}"))),
                None => return Err(bad(describe(other))),
            },
        };
        out.push(root);
    }
    Ok(out)
}

fn parse_system(cx: &Ctx, r: &RawSystem) -> CliResult<SystemSpec> {
    const S: &str = "system";
    let present = r.present();
    let kind = cx.required(
        S,
        "kind",
        &r.kind,
        "expected kind = \"zpk\", \"tf\" or \"sinusoid\"",
    )?;
    let kspan = kind.span();
    let estimate = r.estimate.as_ref().is_some_and(|e| *e.get_ref());
    let kind = match kind.get_ref().as_str() {
        "zpk" => {
            cx.only(
                S,
                &present,
                "kind",
                &["kind", "gain", "zeros", "poles", "estimate"],
                "zpk",
            )?;
            let g = cx.required(
                S,
                "gain",
                &r.gain,
                "kind = \"zpk\" needs gain, poles and optionally zeros",
            )?;
            let gain = cx.finite(S, "gain", g)?;
            let p = cx.required(
                S,
                "poles",
                &r.poles,
                "kind = \"zpk\" needs gain, poles and optionally zeros",
            )?;
            let poles = parse_roots(cx, "poles", p)?;
            let zeros = match &r.zeros {
                Some(z) => parse_roots(cx, "zeros", z)?,
                None => Vec::new(),
            };
            SystemKind::Zpk(
                Zpk::new(gain, zeros, poles).map_err(|e| cx.err(S, "poles", &p.span(), e))?,
            )
        }
        "tf" => {
            cx.only(
                S,
                &present,
                "kind",
                &["kind", "num", "den", "estimate"],
                "tf",
            )?;
            let n = cx.required(
                S,
                "num",
                &r.num,
                "kind = \"tf\" needs num and den (highest power first)",
            )?;
            let d = cx.required(
                S,
                "den",
                &r.den,
                "kind = \"tf\" needs num and den (highest power first)",
            )?;
            let num = cx.finite_list(S, "num", n)?;
            let den = cx.finite_list(S, "den", d)?;
            SystemKind::Tf(
                TransferFunction::new(&num, &den).map_err(|e| cx.err(S, "den", &d.span(), e))?,
            )
        }
        "sinusoid" => {
            cx.only(
                S,
                &present,
                "kind",
                &["kind", "amplitude", "frequency", "phase", "estimate"],
                "sinusoid",
            )?;
            let a = cx.required(
                S,
                "amplitude",
                &r.amplitude,
                "kind = \"sinusoid\" needs amplitude, frequency and optionally phase",
            )?;
            let f = cx.required(
                S,
                "frequency",
                &r.frequency,
                "kind = \"sinusoid\" needs amplitude, frequency and optionally phase",
            )?;
            let amplitude = cx.finite(S, "amplitude", a)?;
            let frequency = cx.finite(S, "frequency", f)?;
            let phase = cx.opt_finite(S, "phase", &r.phase, 0.0)?;
            SystemKind::Sinusoid(
                Sinusoid::new(amplitude, frequency, phase)
                    .map_err(|e| cx.err(S, "frequency", &f.span(), e))?,
            )
        }
        other => {
            return Err(cx.err(
                S,
                "kind",
                &kspan,
                format!(
                    "unknown system kind \"{other}\"; expected \"zpk\", \"tf\" or \"sinusoid\""
                ),
            ))
        }
    };
    Ok(SystemSpec { kind, estimate })
}

const FAMILIES: &str =
    "\"none\", \"uniform-sum\", \"gaussian\", \"laplace\", \"two-point\" or \"exponential\"";

/// The keys that carry a family's parameters.
fn family_keys(family: &str) -> Option<&'static [&'static str]> {
    Some(match family {
        "none" => &[],
        "uniform-sum" => &["n", "a"],
        "gaussian" => &["sigma"],
        "laplace" => &["scale"],
        "two-point" => &["d"],
        "exponential" => &["mean"],
        _ => return None,
    })
}

/// A family with the standard deviation `sigma` (for `fit_family`); `n` for the uniform sum.
fn family_with_std(family: &str, sigma: f64, n: u32) -> Result<AnyJitter, String> {
    if family == "none" {
        return Ok(AnyJitter::None(NoJitter));
    }
    if !(sigma.is_finite() && sigma > 0.0) {
        return Err(format!("a fitted family \"{family}\" needs a given jitter with a spread (standard deviation > 0) to start from"));
    }
    let e = |e: jitterid::jitter::JitterError| e.to_string();
    Ok(match family {
        "uniform-sum" => AnyJitter::UniformSum(
            UniformSum::new(n, sigma * (3.0 * (f64::from(n) + 1.0)).sqrt()).map_err(e)?,
        ),
        "gaussian" => AnyJitter::Gaussian(Gaussian::new(sigma).map_err(e)?),
        "laplace" => AnyJitter::Laplace(Laplace::new(sigma / 2f64.sqrt()).map_err(e)?),
        "two-point" => AnyJitter::TwoPoint(TwoPoint::new(sigma).map_err(e)?),
        "exponential" => AnyJitter::Exponential(ExponentialDelay::new(sigma).map_err(e)?),
        other => return Err(format!("unknown family \"{other}\"; expected {FAMILIES}")),
    })
}

fn parse_jitter(cx: &Ctx, r: &RawJitter) -> CliResult<JitterSpec> {
    const S: &str = "jitter";
    let present = r.present();
    let fam = cx.required(
        S,
        "family",
        &r.family,
        &format!("expected family = {FAMILIES}"),
    )?;
    let family = fam.get_ref().as_str();
    let Some(own) = family_keys(family) else {
        return Err(cx.err(
            S,
            "family",
            &fam.span(),
            format!("unknown jitter family \"{family}\"; expected {FAMILIES}"),
        ));
    };
    let mut allowed = vec!["family", "estimate", "offset", "fit_family", "n_range"];
    allowed.extend_from_slice(own);
    cx.only(S, &present, "family", &allowed, family)?;
    let why = format!("family = \"{family}\" needs {}", own.join(", "));
    let positive = |key: &str, v: &Option<Spanned<f64>>| -> CliResult<f64> {
        let v = cx.required(S, key, v, &why)?;
        cx.positive(S, key, v)
    };
    let n_of = |v: &Option<Spanned<i64>>| -> CliResult<u32> {
        match v {
            None => Ok(0),
            Some(v) => {
                let n = *v.get_ref();
                u32::try_from(n)
                    .ok()
                    .filter(|n| *n <= UniformSum::MAX_N)
                    .ok_or_else(|| {
                        cx.err(
                            S,
                            "n",
                            &v.span(),
                            format!(
                                "expected a whole number in [0, {}], found {n}",
                                UniformSum::MAX_N
                            ),
                        )
                    })
            }
        }
    };
    let jerr = |key: &str, e: jitterid::jitter::JitterError| cx.err_section(S, key, e);
    let base = match family {
        "none" => AnyJitter::None(NoJitter),
        "uniform-sum" => {
            let n = n_of(&r.n)?;
            let a = positive("a", &r.a)?;
            AnyJitter::UniformSum(UniformSum::new(n, a).map_err(|e| jerr("a", e))?)
        }
        "gaussian" => AnyJitter::Gaussian(
            Gaussian::new(positive("sigma", &r.sigma)?).map_err(|e| jerr("sigma", e))?,
        ),
        "laplace" => AnyJitter::Laplace(
            Laplace::new(positive("scale", &r.scale)?).map_err(|e| jerr("scale", e))?,
        ),
        "two-point" => {
            AnyJitter::TwoPoint(TwoPoint::new(positive("d", &r.d)?).map_err(|e| jerr("d", e))?)
        }
        "exponential" => AnyJitter::Exponential(
            ExponentialDelay::new(positive("mean", &r.mean)?).map_err(|e| jerr("mean", e))?,
        ),
        _ => unreachable_family(),
    };
    let offset = match &r.offset {
        Some(o) => Some(cx.finite(S, "offset", o)?),
        None => None,
    };
    let shift = |j: AnyJitter| -> CliResult<AnyJitter> {
        match offset {
            Some(c) => Ok(AnyJitter::Shifted(Box::new(
                Shifted::new(j, c).map_err(|e| jerr("offset", e))?,
            ))),
            None => Ok(j),
        }
    };
    let truth = shift(base.clone())?;
    let estimate = r.estimate.as_ref().is_some_and(|e| *e.get_ref());
    let (model, family_differs, model_family) = match &r.fit_family {
        Some(ff) if ff.get_ref() != family => {
            let name = ff.get_ref().as_str();
            if family_keys(name).is_none() {
                return Err(cx.err(
                    S,
                    "fit_family",
                    &ff.span(),
                    format!("unknown jitter family \"{name}\"; expected {FAMILIES}"),
                ));
            }
            let n = match &base {
                AnyJitter::UniformSum(u) => u.n(),
                _ => 0,
            };
            let j = family_with_std(name, base.std_dev(), n)
                .map_err(|m| cx.err(S, "fit_family", &ff.span(), m))?;
            (shift(j)?, true, name.to_string())
        }
        _ => (truth.clone(), false, family.to_string()),
    };
    if estimate && model.num_params() == 0 {
        let span = r.estimate.as_ref().map(|e| e.span()).unwrap_or(0..0);
        return Err(cx.err(
            S,
            "estimate",
            &span,
            format!("family \"{model_family}\" has no parameter to estimate; set estimate = false"),
        ));
    }
    let profiled = estimate && model_family == "uniform-sum" && offset.is_none();
    let n_range = match (&r.n_range, profiled) {
        (Some(v), true) => {
            let l = v.get_ref();
            let ok =
                l.len() == 2 && l[0] >= 0 && l[0] <= l[1] && l[1] <= i64::from(UniformSum::MAX_N);
            if !ok {
                return Err(cx.err(
                    S,
                    "n_range",
                    &v.span(),
                    format!(
                        "expected [min, max] with 0 <= min <= max <= {}, found {l:?}",
                        UniformSum::MAX_N
                    ),
                ));
            }
            Some((l[0] as u32, l[1] as u32))
        }
        (Some(v), false) => {
            return Err(cx.err(S, "n_range", &v.span(), "applies only when estimate = true and the fitted family is \"uniform-sum\" without an offset"));
        }
        (None, true) => Some((0, 9)),
        (None, false) => None,
    };
    Ok(JitterSpec {
        truth,
        model,
        estimate,
        n_range,
        family_differs,
    })
}

fn unreachable_family() -> AnyJitter {
    // `family_keys` accepted the name, and every accepted name has an arm above.
    AnyJitter::None(NoJitter)
}

fn parse_noise(cx: &Ctx, r: &RawNoise) -> CliResult<NoiseSpec> {
    const S: &str = "noise";
    let present = r.present();
    let std = match &r.std {
        Some(v) => {
            let x = cx.finite(S, "std", v)?;
            if x < 0.0 {
                return Err(cx.err(
                    S,
                    "std",
                    &v.span(),
                    format!("expected a standard deviation >= 0, found {x}"),
                ));
            }
            x
        }
        None => 0.0,
    };
    let estimate = r.estimate.as_ref().is_some_and(|e| *e.get_ref());
    let model = r.model.as_ref().map_or("white", |m| m.get_ref().as_str());
    let shape = match model {
        "white" => {
            cx.only(S, &present, "model", &["std", "model", "estimate"], "white")?;
            AnyNoise::White
        }
        "arma" => {
            let c = match &r.c {
                Some(v) => cx.finite_list(S, "c", v)?,
                None => Vec::new(),
            };
            let d = match &r.d {
                Some(v) => cx.finite_list(S, "d", v)?,
                None => Vec::new(),
            };
            AnyNoise::Arma(ArmaNoise::new(c, d).map_err(|e| {
                let span = r.model.as_ref().map(|m| m.span()).unwrap_or(0..0);
                cx.err(S, "model", &span, e)
            })?)
        }
        other => {
            let span = r.model.as_ref().map(|m| m.span()).unwrap_or(0..0);
            return Err(cx.err(
                S,
                "model",
                &span,
                format!("unknown noise model \"{other}\"; expected \"white\" or \"arma\""),
            ));
        }
    };
    Ok(NoiseSpec {
        std,
        shape,
        estimate,
    })
}

fn parse_estimate(cx: &Ctx, r: &RawEstimate, grid: &SampleGrid) -> CliResult<EstimateSpec> {
    const S: &str = "estimate";
    let method = match &r.method {
        None => Method::Bcls,
        Some(m) => Method::parse(m.get_ref()).ok_or_else(|| {
            cx.err(
                S,
                "method",
                &m.span(),
                format!(
                    "unknown method \"{}\"; expected \"ls\", \"bcls\", \"bj\" or \"ml\"",
                    m.get_ref()
                ),
            )
        })?,
    };
    let frequencies = match &r.frequencies {
        None => Frequencies::Dft,
        Some(v) => parse_frequencies(cx, v, grid)?,
    };
    let solver = match &r.solver {
        None => SolverKind::Lm,
        Some(s) => match s.get_ref().as_str() {
            "lm" | "levenberg-marquardt" => SolverKind::Lm,
            "gauss-newton" => SolverKind::GaussNewton,
            "nelder-mead" => SolverKind::NelderMead,
            other => return Err(cx.err(S, "solver", &s.span(), format!("unknown solver \"{other}\"; expected \"lm\", \"gauss-newton\" or \"nelder-mead\""))),
        },
    };
    let multistart = match &r.multistart {
        None => 0,
        Some(v) => {
            let n = *v.get_ref();
            if !(0..=1000).contains(&n) {
                return Err(cx.err(
                    S,
                    "multistart",
                    &v.span(),
                    format!("expected a whole number of extra starts in [0, 1000], found {n}"),
                ));
            }
            n as usize
        }
    };
    let bounded = |key: &str, v: &Option<Spanned<f64>>, default: f64| -> CliResult<f64> {
        match v {
            None => Ok(default),
            Some(v) => {
                let x = cx.finite(S, key, v)?;
                if (0.0..=10.0).contains(&x) {
                    Ok(x)
                } else {
                    Err(cx.err(
                        S,
                        key,
                        &v.span(),
                        format!("expected a relative size in [0, 10], found {x}"),
                    ))
                }
            }
        }
    };
    let multistart_radius = bounded("multistart_radius", &r.multistart_radius, 0.5)?;
    let perturb = bounded("perturb", &r.perturb, 0.2)?;
    let max_iterations = match &r.max_iterations {
        None => None,
        Some(v) => {
            let n = *v.get_ref();
            if !(1..=1_000_000).contains(&n) {
                return Err(cx.err(
                    S,
                    "max_iterations",
                    &v.span(),
                    format!("expected a whole number in [1, 1000000], found {n}"),
                ));
            }
            Some(n as u64)
        }
    };
    Ok(EstimateSpec {
        method,
        frequencies,
        solver,
        multistart,
        multistart_radius,
        perturb,
        max_iterations,
        max_seconds: None,
    })
}

fn parse_frequencies(
    cx: &Ctx,
    v: &Spanned<toml::Value>,
    grid: &SampleGrid,
) -> CliResult<Frequencies> {
    const S: &str = "estimate";
    const K: &str = "frequencies";
    let expected = "expected \"dft\", { min = …, max = … } (Hz) or a list of frequencies in Hz";
    let nyquist_period = 1.0 / grid.interval();
    let f = match v.get_ref() {
        toml::Value::String(s) if s == "dft" => Frequencies::Dft,
        toml::Value::Table(t) => {
            if let Some(k) = t.keys().find(|k| *k != "min" && *k != "max") {
                return Err(cx.err(
                    S,
                    K,
                    &v.span(),
                    format!("unknown key `{k}` in the band; expected min and max"),
                ));
            }
            let get = |k: &str| -> CliResult<f64> {
                let x = t.get(k).ok_or_else(|| {
                    cx.err(S, K, &v.span(), format!("the band needs `{k}`; {expected}"))
                })?;
                number(x).filter(|x| x.is_finite()).ok_or_else(|| {
                    cx.err(
                        S,
                        K,
                        &v.span(),
                        format!(
                            "band `{k}`: expected a finite number of Hz, found {}",
                            describe(x)
                        ),
                    )
                })
            };
            let (min, max) = (get("min")?, get("max")?);
            if !(min >= 0.0 && min <= max) {
                return Err(cx.err(
                    S,
                    K,
                    &v.span(),
                    format!("expected 0 <= min <= max, found min = {min}, max = {max}"),
                ));
            }
            jitterid::window::FrequencySet::band(grid, min, max)
                .map_err(|e| cx.err(S, K, &v.span(), e))?;
            Frequencies::Band { min, max }
        }
        toml::Value::Array(a) => {
            let mut out = Vec::with_capacity(a.len());
            for (i, x) in a.iter().enumerate() {
                match number(x).filter(|x| x.is_finite() && *x >= 0.0 && *x < nyquist_period) {
                    Some(f) => out.push(f),
                    None => {
                        return Err(cx.err(S, K, &v.span(), format!("element {}: expected a frequency in [0, 1/T) = [0, {nyquist_period}) Hz, found {}", i + 1, describe(x))));
                    }
                }
            }
            if out.is_empty() {
                return Err(cx.err(S, K, &v.span(), "expected at least one frequency"));
            }
            jitterid::window::FrequencySet::list(grid, out.clone())
                .map_err(|e| cx.err(S, K, &v.span(), e))?;
            Frequencies::List(out)
        }
        other => {
            return Err(cx.err(
                S,
                K,
                &v.span(),
                format!("{expected}, found {}", describe(other)),
            ))
        }
    };
    Ok(f)
}
