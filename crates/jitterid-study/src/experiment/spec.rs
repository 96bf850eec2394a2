//! The validated experiment: what every command reads, with nothing left to check.

use crate::Registries;
use jitterid::estimate::solver::SolverRegistry;
use jitterid::estimate::{
    AnyCriterion, AnyNoise, CriterionRegistry, Frequencies, NoiseModel, SpecTable,
};
use jitterid::jitter::AnyJitter;
use jitterid::signal::{Input, RandomBinary, SampleGrid};
use std::fmt;
use std::path::PathBuf;
use std::sync::Arc;

/// How an input is obtained.
#[derive(Debug, Clone, PartialEq)]
pub enum InputSpec {
    /// A random binary input, drawn per realisation from the seed.
    RandomBinary(RandomBinary),
    /// A known input.
    Known(Input),
}

/// One input of the experiment (`[input]`, or one table of `[[input]]`).
#[derive(Debug, Clone, PartialEq)]
pub struct InputChannel {
    /// Its name (`name`; `u` for a single input, `u1`, `u2`, … for several): the prefix of its
    /// channel's parameters and its column in a record's input file.
    pub name: String,
    /// How it is obtained.
    pub spec: InputSpec,
    /// How long (s) the true input ran before the record's first instant `t0`: a random
    /// binary input is drawn from `t0 − history`, and a fit sees it from `t0` on only.
    pub history: f64,
}

/// The `[system]` section, or the `[[system]]` tables of a multi-input system.
#[derive(Debug, Clone, PartialEq)]
pub struct SystemSpec {
    /// The signal registry's spec table (`kind` and that kind's keys, checked at the door): the
    /// truth in `simulate`/`montecarlo`, the start in `fit`. Built with
    /// [`crate::fit::signal_of`]. A multi-input system's is a `superposition` table
    /// ([`jitterid::signal::superposition`]): the input names, one spec table per input and
    /// which of them are estimated.
    pub kind: SpecTable,
    /// Whether any of its parameters are estimated.
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
#[derive(Clone)]
pub struct NoiseSpec {
    /// Standard deviation of the white noise `e_k` (of `v_k` itself for white noise).
    pub std: f64,
    /// The registry name of the noise model (`"white"`, `"arma"`).
    pub model: String,
    /// The noise shape `H`.
    pub shape: AnyNoise,
    /// Whether the noise level (and, with method `bj`, the shape) is estimated.
    pub estimate: bool,
}

impl NoiseSpec {
    /// The shape by name and parameters, which is what identifies it (`White`,
    /// `Arma(["c1", "d1"], [0.5, -0.3])`).
    fn shape_text(&self) -> String {
        let name = upper_camel(&self.model);
        let names = self.shape.param_names();
        if names.is_empty() {
            name
        } else {
            format!("{name}({names:?}, {:?})", self.shape.params())
        }
    }
}

impl fmt::Debug for NoiseSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("NoiseSpec")
            .field("std", &self.std)
            .field("shape", &format_args!("{}", self.shape_text()))
            .field("estimate", &self.estimate)
            .finish()
    }
}

impl PartialEq for Registries {
    /// Registries are the same when they are one value (an experiment read with the built-in
    /// registries equals another read with them): entries hold functions, which do not
    /// compare.
    fn eq(&self, other: &Self) -> bool {
        std::ptr::eq(self, other)
    }
}

impl PartialEq for NoiseSpec {
    fn eq(&self, other: &Self) -> bool {
        self.std == other.std
            && self.estimate == other.estimate
            && self.model == other.model
            && self.shape.params() == other.shape.params()
    }
}

/// An estimation method: the name of a [`CriterionRegistry`] entry that the command line can
/// build from its name alone (`"ls"`, `"bcls"`, `"bj"`, `"ml"`, `"quasi-ml"`), validated where
/// it enters. `"ml"` is the exact likelihood for white noise and the quasi-likelihood for a
/// shaped noise model.
#[derive(Clone, Copy, PartialEq, Eq)]
pub struct Method(&'static str);

impl Method {
    /// Naive least squares (jitter ignored): the comparison fit of `fit --plot`.
    pub const LS: Method = Method("ls");
    /// Bias-compensated least squares: the default.
    pub const BCLS: Method = Method("bcls");

    /// The name used in files and on the command line.
    pub fn as_str(self) -> &'static str {
        self.0
    }

    /// The built-in registry's method of this name, if the command line can run it.
    pub fn parse(s: &str) -> Option<Self> {
        Self::parse_in(&Registries::builtin().criteria, s)
    }

    /// The method of this name in `registry`, if it builds from its name alone.
    pub fn parse_in(registry: &CriterionRegistry, s: &str) -> Option<Self> {
        let entry = registry.entry(s)?;
        registry
            .build(&name_table(registry.key(), entry.name))
            .ok()
            .map(|_| Method(entry.name))
    }

    /// The names [`parse`](Self::parse) accepts, quoted, for messages.
    pub fn names() -> String {
        Self::names_in(&Registries::builtin().criteria)
    }

    /// The names [`parse_in`](Self::parse_in) accepts in `registry`, quoted, for messages.
    pub fn names_in(registry: &CriterionRegistry) -> String {
        let names: Vec<&str> = registry
            .entries()
            .iter()
            .map(|e| e.name)
            .filter(|n| Method::parse_in(registry, n).is_some())
            .collect();
        quoted_list(&names)
    }

    /// The criterion, built through `registry` (the one the method was accepted from).
    pub fn criterion_in(self, registry: &CriterionRegistry) -> AnyCriterion {
        // Only names that built at the door are held.
        registry
            .build(&name_table(registry.key(), self.0))
            .unwrap_or_else(|_| AnyCriterion::first_moment(jitterid::estimate::Bcls))
    }

    /// Whether the method is a likelihood in `registry` (its cost is `−log L`).
    pub fn is_likelihood_in(self, registry: &CriterionRegistry) -> bool {
        self.criterion_in(registry).is_likelihood()
    }
}

impl fmt::Debug for Method {
    /// The name in upper camel case (`bcls` → `Bcls`), the spelling the fingerprint has always
    /// hashed.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&upper_camel(self.0))
    }
}

/// A solver: the name of a [`SolverRegistry`] entry the command line offers (`"lm"`, also
/// spelled `"levenberg-marquardt"`; `"gauss-newton"`; `"nelder-mead"`), validated where it
/// enters.
#[derive(Clone, Copy, PartialEq, Eq)]
pub struct SolverName(&'static str);

impl SolverName {
    /// Levenberg–Marquardt: the default.
    pub const LM: SolverName = SolverName("lm");
    /// The solvers that take the command line's iteration budget and progress bar.
    const OFFERED: [&'static str; 3] = ["lm", "gauss-newton", "nelder-mead"];

    /// The registry name.
    pub fn as_str(self) -> &'static str {
        self.0
    }

    /// The solver of this name (or alias) in `registry`, if the command line offers it.
    pub fn parse_in(registry: &SolverRegistry, s: &str) -> Option<Self> {
        let s = if s == "levenberg-marquardt" { "lm" } else { s };
        let entry = registry.entry(s)?;
        Self::OFFERED
            .contains(&entry.name)
            .then_some(SolverName(entry.name))
    }

    /// The names [`parse_in`](Self::parse_in) accepts, quoted, for messages.
    pub fn names() -> String {
        quoted_list(&Self::OFFERED)
    }
}

impl fmt::Debug for SolverName {
    /// The name in upper camel case (`gauss-newton` → `GaussNewton`), the spelling the
    /// fingerprint has always hashed.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&upper_camel(self.0))
    }
}

/// `{key: name}`: the spec table that names a registry entry without keys.
pub fn name_table(key: &str, name: &str) -> SpecTable {
    let mut t = SpecTable::new();
    t.insert(key.into(), name.into());
    t
}

/// `"a", "b" or "c"`.
pub(crate) fn quoted_list(names: &[&str]) -> String {
    let quoted: Vec<String> = names.iter().map(|n| format!("\"{n}\"")).collect();
    match quoted.split_last() {
        Some((last, [])) => last.clone(),
        Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
        None => String::new(),
    }
}

/// `gauss-newton` → `GaussNewton`.
pub(crate) fn upper_camel(name: &str) -> String {
    name.split('-')
        .map(|w| {
            let mut c = w.chars();
            c.next()
                .map(|h| h.to_uppercase().chain(c).collect::<String>())
                .unwrap_or_default()
        })
        .collect()
}

/// The `[estimate]` section.
#[derive(Debug, Clone, PartialEq)]
pub struct EstimateSpec {
    /// The method.
    pub method: Method,
    /// The frequency set.
    pub frequencies: Frequencies,
    /// The solver.
    pub solver: SolverName,
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
    /// Where a likelihood fit of an estimated system starts; set from the command line
    /// (`fit --init experiment-only`).
    pub likelihood_start: LikelihoodStart,
}

/// Where a likelihood fit (exact or quasi ML) of an estimated system starts.
///
/// The likelihood of a record has local optima that the first moment's least-squares cost
/// does not: from a start 20 % off the truth, exact ML once stopped at lightly damped poles with
/// a likelihood some 1 300 log units below the optimum, and reported it as converged. The BCLS
/// estimate is consistent whatever its start's basin, so a likelihood fit starts there.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LikelihoodStart {
    /// BCLS is fitted first from the given start, and the likelihood from its estimate (from the
    /// given start when BCLS does not converge).
    #[default]
    Bcls,
    /// The likelihood starts from the given values only; BCLS and a likelihood fit from its
    /// estimate still run, to check that this fit did not stop at a worse optimum.
    Given,
}

/// A validated experiment: every value is within the representable range, every model is
/// built, and (when read for estimation) `estimate.method` can fit what is marked as
/// estimated. Commands use it as it is; nothing in it is checked again.
#[derive(Debug, Clone, PartialEq)]
pub struct Experiment {
    /// The file's name, for messages.
    pub file: String,
    /// The directory relative paths are resolved from.
    pub dir: PathBuf,
    /// An optional title.
    pub title: Option<String>,
    /// The registries the experiment was read with, which build its models when it runs.
    pub registries: Arc<Registries>,
    /// The sampling grid.
    pub grid: SampleGrid,
    /// The inputs, in order (none for a system without one, a sinusoid).
    pub inputs: Vec<InputChannel>,
    /// The system.
    pub system: SystemSpec,
    /// The jitter.
    pub jitter: JitterSpec,
    /// The measurement noise.
    pub noise: NoiseSpec,
    /// How to estimate.
    pub estimate: EstimateSpec,
    /// The `[select]` grid of model orders and jitter families, when the file has one.
    pub select: Option<jitterid::estimate::selection::SelectionGrid>,
    /// For a system with several inputs, each input's candidate orders of `[select]` (its
    /// `orders`, or the grid's `poles` × `zeros`); empty for one input or without `[select]`.
    pub select_orders: Vec<jitterid::estimate::selection::ChannelOrders>,
    /// The `[design]` section's free design variables, when the file has one.
    pub design: Option<super::DesignSpec>,
}

impl Experiment {
    /// Whether the system has several inputs (a `superposition` of one response per input).
    pub fn multi_input(&self) -> bool {
        self.system.kind.get(jitterid::signal::registry::KIND_KEY)
            == Some(&jitterid::signal::superposition::SUPERPOSITION_KIND.into())
    }

    /// Whether any input ran before the record's first instant (`history > 0`).
    pub fn has_history(&self) -> bool {
        self.inputs.iter().any(|c| c.history > 0.0)
    }

    /// Whether any input is random binary (drawn per realisation; a record keeps its
    /// realisation in a side file).
    pub fn random_input(&self) -> bool {
        self.inputs
            .iter()
            .any(|c| matches!(c.spec, InputSpec::RandomBinary(_)))
    }

    /// The output offset of `[output]`: `(y₀, estimated)`, `None` without one (the system's
    /// spec table holds it as the keys `offset` and `estimate_offset`).
    pub fn output_offset(&self) -> Option<(f64, bool)> {
        let y0 = self.system.kind.get("offset")?.as_f64()?;
        let estimated = self.system.kind.get("estimate_offset") == Some(&true.into());
        Some((y0, estimated))
    }

    /// The input's level of `[input]` for a single-input system: `(u₀, estimated)`, `None`
    /// without one (the system's spec table holds it as the keys `level` and
    /// `estimate_level`; a multi-input system's are in its channels' tables).
    pub fn input_level(&self) -> Option<(f64, bool)> {
        let u0 = self.system.kind.get("level")?.as_f64()?;
        let estimated = self.system.kind.get("estimate_level") == Some(&true.into());
        Some((u0, estimated))
    }

    /// Whether `select` can run this experiment: its candidates are built from the `[select]`
    /// orders with the system's delay, free response and output offset; a multi-input system's
    /// from one transfer function per input, each estimated, without a delay or free response.
    ///
    /// # Errors
    ///
    /// One line naming the `[[system]]` key a multi-input candidate cannot carry.
    pub fn selectable(&self) -> crate::error::StudyResult<()> {
        if self.multi_input() {
            return super::select::channels_selectable(self);
        }
        Ok(())
    }
}
