//! Experiment files (TOML): read once, validated once, into an [`Experiment`].
//!
//! The way in runs one direction: `raw` holds the file as written (serde types),
//! the section parsers judge each value and build the library's models, `method` checks
//! that the method can fit what is marked as estimated, and the result is an [`Experiment`]
//! that no command has to question again. Every error is one line that names the file, the
//! line and the key, and says what was expected (`diagnostics`). The key names are
//! documented in `docs/experiments.md`.

mod channels;
mod checks;
mod design;
mod diagnostics;
mod estimate;
mod input;
mod jitter;
mod level;
mod method;
mod noise;
mod overrides;
mod paths;
pub mod range;
mod raw;
mod sampling;
mod select;
mod spec;
mod system;
mod tone_design;

pub use design::{
    budget_edit, dac_rate_edit, derived_edit, Budget, DesignCriterion, DesignEstimator, DesignSpec,
    Hold, PriorSpread, MAX_DRAWS, MAX_GRID, MAX_PRIOR_DRAWS,
};
pub use input::MAX_SWITCHES;
pub use overrides::Override;
pub use paths::Paths;
pub use sampling::MAX_SAMPLES;
pub use spec::{
    name_table, EstimateSpec, Experiment, InputChannel, InputSpec, JitterSpec, LikelihoodStart,
    Method, NoiseSpec, SolverName, SystemSpec,
};
pub use tone_design::{
    harmonics_in, PhaseChoice, ToneDesignSpec, DEFAULT_TONES, MAX_DAC_SAMPLES, MAX_DESIGN_TONES,
};

use crate::csvio;
use crate::error::StudyResult;
use crate::study_err;
use crate::Registries;
use diagnostics::{shape_error, toml_error, Source};
use jitterid::estimate::{AnyNoise, Frequencies};
use jitterid::signal::Input;
use raw::{OneOrMany, RawExperiment};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// What the experiment is read for: what it must be fit for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Purpose {
    /// Simulation only: the `[estimate]` section is read but not held against the rest.
    Simulate,
    /// Estimation with the file's method, or with this one (from the command line).
    Estimate(Option<Method>),
}

/// Reads and validates an experiment file for `purpose`; the files it names must be inside its
/// directory ([`Paths::Inside`]).
pub fn read(path: &Path, purpose: Purpose) -> StudyResult<Experiment> {
    read_with(path, purpose, Paths::Inside)
}

/// Reads and validates an experiment file for `purpose`; `paths` says where the files it names
/// may be (see [`Paths`]).
pub fn read_with(path: &Path, purpose: Purpose, paths: Paths) -> StudyResult<Experiment> {
    read_edited(
        path,
        purpose,
        &ReadOptions {
            paths,
            ..ReadOptions::default()
        },
    )
}

/// How an experiment file is read: where the files it names may be, the edits of its document
/// (the command line's `--set key=value`), and the data file whose `t` column and row count
/// give the `[sampling]` keys the document lacks.
#[derive(Debug, Clone, Default)]
pub struct ReadOptions {
    /// Where the files the experiment names may be.
    pub paths: Paths,
    /// Edits of the document, applied in order before it is read.
    pub overrides: Vec<Override>,
    /// The record the experiment is read for: `[sampling] samples`, `start` and `interval`,
    /// when the document does not give them, are its row count, its first instant and the
    /// step of its uniform `t` column.
    pub data: Option<PathBuf>,
}

/// Reads and validates the experiment file at `path` for `purpose`, edited as `options` says
/// before it is read (see [`parse_edited`]).
pub fn read_edited(
    path: &Path,
    purpose: Purpose,
    options: &ReadOptions,
) -> StudyResult<Experiment> {
    let file = path.display().to_string();
    let text = read_text(path)?;
    parse_edited(
        &Registries::builtin(),
        &file,
        &text,
        &directory_of(path),
        purpose,
        options,
    )
}

/// [`parse_with`] of `text` after the edits of `options`: the edited document is validated as a
/// file would be, and messages locate a key in the file as written, or name the edit that
/// wrote it (`exp.toml (--set jitter.sigma=-1): [jitter] sigma: …`).
pub fn parse_edited(
    registries: &Arc<Registries>,
    file: &str,
    text: &str,
    dir: &Path,
    purpose: Purpose,
    options: &ReadOptions,
) -> StudyResult<Experiment> {
    let read = |text: &str| parse_with(registries, file, text, dir, purpose, options.paths);
    if options.overrides.is_empty() && options.data.is_none() {
        return read(text);
    }
    match overrides::apply(text, &options.overrides, options.data.as_deref())? {
        Some(edited) => read(&edited.text).map_err(|e| edited.relocate(file, e)),
        // Not a TOML document: read unedited, it is reported as any such file is.
        None => read(text).and_then(|_| {
            Err(study_err!(
                "{file}: the document cannot be edited (it is read as TOML, but not by the editor)"
            ))
        }),
    }
}

/// The text of `text` after `edits`, as [`parse_edited`] would read it (the document's own
/// spacing and comments kept).
///
/// # Errors
///
/// An edit's path leads through a value or names a table; `file` is not a TOML document.
pub(crate) fn edited_text(file: &str, text: &str, edits: &[Override]) -> StudyResult<String> {
    match overrides::apply(text, edits, None)? {
        Some(edited) => Ok(edited.text),
        None => Err(study_err!("{file}: the document cannot be edited")),
    }
}

/// An estimated output offset `y₀` must be seen by a frequency-domain criterion. Its first
/// moment is `y₀ Γ_N(f)`: `N y₀` at `f = 0` and exactly zero at every other point of the DFT
/// grid `j/(NT)`, so a frequency set without `f = 0` whose points all lie on that grid (a band
/// above 0, a list of nonzero grid points) leaves the offset without information and its
/// estimate arbitrary. Such a set is refused, naming `[output] estimate_offset` (the choice
/// that needs `f = 0`), rather than fitting the offset to nothing or estimating it outside the
/// criterion. A list with a point off the grid sees the offset through the window's leakage.
fn offset_seen(
    cx: &diagnostics::Source,
    raw: &RawExperiment,
    system: &SystemSpec,
    frequencies: &Frequencies,
    grid: &jitterid::signal::SampleGrid,
) -> StudyResult<()> {
    if system.kind.get("estimate_offset") != Some(&serde_json::Value::Bool(true)) {
        return Ok(());
    }
    let n = grid.len() as f64;
    let nonzero_bin = |f: &f64| {
        let j = f * n * grid.interval();
        (j - j.round()).abs() <= 1e-9 * n && j.round().rem_euclid(n) != 0.0
    };
    let blind = match frequencies {
        Frequencies::Dft => false,
        Frequencies::Band { min, .. } => *min > 0.0,
        Frequencies::List(f) => f.iter().all(nonzero_bin),
    };
    if !blind {
        return Ok(());
    }
    let key = raw.output.as_ref().and_then(|o| o.estimate_offset.as_ref());
    Err(cx.err_at(
        "output",
        "estimate_offset",
        key,
        "an estimated offset is seen only at f = 0 by the frequency-domain criterion, and [estimate] frequencies leaves f = 0 out; include it (frequencies = \"dft\", or a band from 0) or use method = \"ml\"",
    ))
}

/// The text of the experiment file at `path`, read as every front end reads it: only a regular
/// file of at most [`csvio::MAX_FILE_BYTES`] (a device such as `/dev/zero` or a pipe is refused
/// before it is read), and only UTF-8 text.
///
/// # Errors
///
/// One line naming the file: it does not exist, cannot be read, is not a regular file, is too
/// large or is not UTF-8.
pub fn read_text(path: &Path) -> StudyResult<String> {
    let file = path.display().to_string();
    Ok(csvio::read_text(path, &file, "a TOML experiment file")?)
}

/// The directory the paths in the experiment file at `path` are resolved against: the file's
/// own (the empty path, that is the current directory, for a bare file name).
pub fn directory_of(path: &Path) -> PathBuf {
    path.parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."))
}

/// Parses and validates experiment text for `purpose` with the built-in registries; `file`
/// names it in messages, `dir` resolves relative paths, and the files it names must be inside
/// `dir` ([`Paths::Inside`]).
pub fn parse(file: &str, text: &str, dir: &Path, purpose: Purpose) -> StudyResult<Experiment> {
    parse_with(
        &Registries::builtin(),
        file,
        text,
        dir,
        purpose,
        Paths::Inside,
    )
}

/// Parses and validates experiment text for `purpose`, looking every name up in `registries`
/// (which the experiment keeps to build its models); `file` names it in messages, `dir`
/// resolves relative paths, `paths` says where the files it names may be (see [`Paths`]).
pub fn parse_with(
    registries: &Arc<Registries>,
    file: &str,
    text: &str,
    dir: &Path,
    purpose: Purpose,
    paths: Paths,
) -> StudyResult<Experiment> {
    // TOML knows LF and CRLF only; a lone CR would be reported as a stray character on line 1.
    let bytes = text.as_bytes();
    if (0..bytes.len()).any(|i| bytes[i] == b'\r' && bytes.get(i + 1) != Some(&b'\n')) {
        return Err(study_err!(
            "{file}: line endings are CR only; expected LF or CRLF line endings (a TOML file)"
        ));
    }
    if let Some(e) = shape_error(file, text) {
        return Err(e);
    }
    let raw: RawExperiment = toml::from_str(text).map_err(|e| toml_error(file, text, &e))?;
    let cx = Source::new(file, text, dir.to_path_buf(), paths, registries);
    let r_sampling = raw.sampling.as_ref().ok_or_else(|| {
        study_err!("{file}: missing section [sampling]; expected keys interval, samples and optionally start")
    })?;
    let r_systems = raw.system.as_ref().map(OneOrMany::items).ok_or_else(|| {
        study_err!(
            "{file}: missing section [system]; expected kind = {} and its keys",
            system::kinds(&registries.signal)
        )
    })?;
    let r_inputs = raw.input.as_ref().map(OneOrMany::items).unwrap_or_default();
    let grid = sampling::parse_sampling(&cx, r_sampling)?;
    let (mut system, inputs) = if r_systems.len() == 1 && r_inputs.len() <= 1 {
        let r_system = r_systems[0];
        let system = system::parse_system(&cx, r_system, &grid)?;
        let inputs = input::parse_input_section(&cx, r_inputs.first().copied(), &system, &grid)?;
        if let (Some(d), Some(InputSpec::Known(Input::Tones(_)))) =
            (&r_system.delay, inputs.first().map(|c| &c.spec))
        {
            // A tone's delay is a phase: the delayed response needs an input made of steps.
            return Err(cx.err(
                "system",
                "delay",
                &d.span(),
                "needs an input made of steps (random-binary, piecewise or csv); a sine or multisine input's delay is a phase",
            ));
        }
        (system, inputs)
    } else {
        channels::parse_channels(&cx, &r_systems, &r_inputs, &grid)?
    };
    system::output_keys(&cx, raw.output.as_ref(), &mut system)?;
    level::level_keys(&cx, &r_inputs, &inputs, &mut system)?;
    let jitter = match &raw.jitter {
        Some(r) => jitter::parse_jitter(&cx, r, &grid)?,
        None => jitter::no_jitter(),
    };
    let noise = match &raw.noise {
        Some(r) => noise::parse_noise(&cx, r)?,
        None => NoiseSpec {
            std: 0.0,
            model: "white".into(),
            shape: AnyNoise::default(),
            estimate: false,
        },
    };
    let mut estimate = match &raw.estimate {
        Some(r) => estimate::parse_estimate(&cx, r, &grid)?,
        None => EstimateSpec {
            method: Method::BCLS,
            frequencies: Frequencies::Dft,
            solver: SolverName::LM,
            multistart: 0,
            multistart_radius: 0.5,
            perturb: 0.2,
            max_iterations: None,
            max_seconds: None,
            likelihood_start: LikelihoodStart::default(),
        },
    };
    if let Purpose::Estimate(chosen) = purpose {
        estimate.method = chosen.unwrap_or(estimate.method);
        let parts = method::Estimated {
            system: &system,
            jitter: &jitter,
            noise: &noise,
        };
        method::check_method(&cx, &raw, &parts, estimate.method, chosen.is_some())?;
        if !estimate.method.is_likelihood_in(&registries.criteria) {
            offset_seen(&cx, &raw, &system, &estimate.frequencies, &grid)?;
        }
    }
    let (select, select_orders) = match &raw.select {
        Some(r) => {
            // The inputs whose orders a multi-input grid lists; none for one input.
            let multi = system.kind.get(jitterid::signal::registry::KIND_KEY)
                == Some(&jitterid::signal::superposition::SUPERPOSITION_KIND.into());
            let names: Vec<&str> = match multi {
                true => inputs.iter().map(|c| c.name.as_str()).collect(),
                false => Vec::new(),
            };
            let (grid, orders) = select::parse_select(&cx, r, grid.len(), &names)?;
            (Some(grid), orders)
        }
        None => (None, Vec::new()),
    };
    let design = match &raw.design {
        Some(r) => {
            // A design varies the one input of a single-input experiment.
            let one = match (&raw.input, inputs.as_slice()) {
                (Some(OneOrMany::One(i)), [c]) => Some((i, c.history)),
                _ => None,
            };
            let kind = one.and_then(|(i, _)| i.kind.as_ref().map(|k| k.get_ref().as_str()));
            let history = one.map_or(0.0, |(_, h)| h);
            // A multisine design starts from the file's own tones.
            let tones = match inputs.as_slice() {
                [c] if one.is_some() => match &c.spec {
                    InputSpec::Known(jitterid::signal::Input::Tones(m)) => Some(m.tones()),
                    _ => None,
                },
                _ => None,
            };
            Some(design::parse_design(&cx, r, kind, tones, &grid, history)?)
        }
        None => None,
    };
    Ok(Experiment {
        file: file.to_string(),
        dir: cx.dir.clone(),
        title: raw.title.clone(),
        registries: Arc::clone(registries),
        grid,
        inputs,
        system,
        jitter,
        noise,
        estimate,
        select,
        select_orders,
        design,
    })
}
