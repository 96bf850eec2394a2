//! From an experiment to signals, model structures and estimates.

use crate::error::StudyResult;
use crate::experiment::{name_table, Experiment, Method};
use crate::export::{self, reported_covariance, CovarianceSource};
use crate::study_err;
use crate::Watch;
use jitterid::estimate::solver::{AnySolver, BrentOrBfgs};
use jitterid::estimate::{
    fit as fit_criterion, fit_profile, AnyCriterion, AnyNoise, EstimateError, Fit as Estimate,
    FitOptions, ModelStructure, NoiseModel, Record,
};
use jitterid::jitter::registry::JitterRegistry;
use jitterid::jitter::{AnyJitter, JitterError, JitterModel, UniformSum};
use jitterid::rand::rngs::StdRng;
use jitterid::rand::Rng;
use jitterid::signal::registry::KIND_KEY;
use jitterid::signal::{AnySignal, Input, SampleGrid, Signal};
use serde::Serialize;
use serde_json::Map;

/// The uniform-sum jitter with `n + 1` terms and standard deviation `sigma`, through the
/// registry: the start of every `n` of a profile.
fn uniform_sum_with_std(sigma: f64) -> impl Fn(i64) -> Result<AnyJitter, JitterError> + Sync {
    move |n| {
        let mut spec = Map::new();
        spec.insert("n".into(), n.into());
        JitterRegistry::builtin().from_std_dev("uniform-sum", sigma, &spec)
    }
}

/// The model structure of the command line.
pub type Structure = ModelStructure<AnySignal, AnyJitter, AnyNoise>;

/// The signal of the experiment's system driven by `input` (a kind that needs one, such as a
/// rational system, fails without it), built through the experiment's signal registry.
pub fn signal_of(exp: &Experiment, inputs: &[Input]) -> StudyResult<AnySignal> {
    let spec = &exp.system.kind;
    let needs_input = spec
        .get(KIND_KEY)
        .and_then(|k| k.as_str())
        .and_then(|name| exp.registries.signal.kind(name))
        .is_some_and(|k| k.needs_input());
    if needs_input && inputs.is_empty() {
        return Err(study_err!("a rational system needs an input"));
    }
    build_signal(exp, spec, inputs).map_err(|e| study_err!("[system]: {e}"))
}

/// The model of the spec table `spec` (the experiment's system's, or one derived from it)
/// driven by `inputs`: a multi-input system's `superposition` table builds each input's
/// response with the experiment's signal registry, any other kind is built by the registry
/// from the first input (none for a kind without one).
///
/// # Errors
///
/// The registry's build errors, and a kind driven by an input given none.
pub fn build_signal(
    exp: &Experiment,
    spec: &jitterid::signal::registry::SpecTable,
    inputs: &[Input],
) -> StudyResult<AnySignal> {
    let registry = &exp.registries.signal;
    let name = spec.get(KIND_KEY).and_then(|k| k.as_str()).unwrap_or("");
    if name == jitterid::signal::superposition::SUPERPOSITION_KIND {
        return jitterid::signal::superposition::build(registry, spec, inputs)
            .map_err(|e| study_err!("{e}"));
    }
    let needs_input = registry.kind(name).is_some_and(|k| k.needs_input());
    if needs_input && inputs.is_empty() {
        return Err(study_err!("a rational system needs an input"));
    }
    registry
        .build(spec, inputs.first())
        .map_err(|e| study_err!("{e}"))
}

/// `signal` with its estimated output offset started from `record`: `mean(y) − mean(m_k)` for
/// the response without the offset under the experiment's jitter model
/// ([`jitterid::estimate::offset_start`]), the start a data-driven fit (`--init auto`) gives
/// the offset beside the initializer's system. A signal without an estimated offset is
/// returned unchanged.
///
/// # Errors
///
/// The signal does not rebuild without its offset (it was built by the same registry, so
/// only a registry that lost its kind fails), or the start is not finite (non-finite data).
pub fn with_offset_start(
    exp: &Experiment,
    signal: &AnySignal,
    inputs: &[Input],
    y: &[f64],
) -> StudyResult<AnySignal> {
    let mut spec = signal.spec();
    if spec.get("estimate_offset") != Some(&serde_json::Value::Bool(true)) {
        return Ok(signal.clone());
    }
    let mut bare = spec.clone();
    bare.remove("offset");
    bare.remove("estimate_offset");
    let build = |spec: &jitterid::signal::registry::SpecTable| {
        build_signal(exp, spec, inputs)
            .map_err(|e| study_err!("[output] offset: the start's model: {e}"))
    };
    let response = build(&bare)?;
    let record = record(&exp.grid, y.to_vec()).map_err(|e| study_err!("[output] offset: {e}"))?;
    let y0 = jitterid::estimate::offset_start(&response, &record, &exp.jitter.model);
    if !y0.is_finite() {
        return Err(study_err!(
            "[output] offset: the record gives no finite start for the offset"
        ));
    }
    spec.insert("offset".into(), serde_json::json!(y0));
    build(&spec)
}

/// The data-driven start of `fit --init auto`: the initializer's system
/// ([`crate::select::auto_start`]), then its output offset ([`with_offset_start`]); `data`
/// names the record in messages.
///
/// # Errors
///
/// Those of the two steps.
pub fn data_start(
    exp: &Experiment,
    signal: &AnySignal,
    inputs: &[Input],
    y: &[f64],
    data: &str,
) -> StudyResult<AnySignal> {
    let signal = crate::select::auto_start(exp, signal, inputs, y, data)?;
    with_offset_start(exp, &signal, inputs, y)
}

/// The model structure for `signal` as the experiment says (free parts, noise, method).
pub fn structure(exp: &Experiment, signal: AnySignal, method: Method) -> StudyResult<Structure> {
    let shape_free = exp.noise.estimate
        && (method.as_str() == "bj" || method.is_likelihood_in(&exp.registries.criteria))
        && !exp.noise.shape.is_white();
    let s = ModelStructure::bj(signal, exp.jitter.model.clone(), exp.noise.shape.clone())
        .with_estimated(exp.system.estimate, exp.jitter.estimate, shape_free);
    if exp.noise.estimate {
        Ok(s)
    } else {
        s.with_noise_std(exp.noise.std)
            .map_err(|e| study_err!("{}: [noise] std: {e}", exp.file))
    }
}

/// The solver of the experiment, built through the solver registry; `seed` seeds multistart
/// perturbations. The command line's iteration and wall-clock budgets go to the entry's
/// `max_iters` and `max_seconds` keys where it takes them (a solver without a wall-clock
/// budget runs to its iteration limit), and the watcher of iterations, when there is one, to
/// the solver itself.
pub fn solver(exp: &Experiment, seed: u64, watch: &Watch) -> StudyResult<AnySolver> {
    let e = &exp.estimate;
    let registry = &exp.registries.solvers;
    let mut table = name_table(registry.key(), e.solver.as_str());
    let takes = |key: &str| {
        registry
            .entry(e.solver.as_str())
            .is_some_and(|entry| entry.params.iter().any(|p| p.key == key))
    };
    if let Some(n) = e.max_iterations.filter(|_| takes("max_iters")) {
        table.insert("max_iters".into(), n.into());
    }
    if let Some(t) = e.max_seconds.filter(|_| takes("max_seconds")) {
        table.insert("max_seconds".into(), t.into());
    }
    if e.multistart > 0 {
        table.insert("starts".into(), e.multistart.into());
        table.insert("radius".into(), e.multistart_radius.into());
        table.insert("seed".into(), seed.into());
    }
    let solver = registry.build(&table).map_err(|err| {
        study_err!(
            "{}: [estimate] solver \"{}\": {err}",
            exp.file,
            e.solver.as_str()
        )
    })?;
    Ok(watch.watched(solver))
}

/// One reported parameter of a fit.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Param {
    /// Its name.
    pub name: String,
    /// The estimate.
    pub estimate: f64,
    /// Its standard error, where defined.
    pub stderr: Option<f64>,
}

/// The outcome of one fit.
#[derive(Debug, Clone)]
pub struct Fit {
    /// Method used.
    pub method: Method,
    /// Whether the solver converged.
    pub converged: bool,
    /// Final cost.
    pub cost: f64,
    /// Iterations.
    pub iterations: u64,
    /// Why the solver stopped.
    pub termination: String,
    /// Noise standard deviation used for the covariance (known or estimated).
    pub noise_std: f64,
    /// Reported parameters, in the model's order.
    pub params: Vec<Param>,
    /// Covariance of the reported parameters, in their order, where computed (`None` entries
    /// for parameters without one, such as a profiled integer).
    pub covariance: Option<Vec<Vec<Option<f64>>>>,
    /// The fitted structure.
    pub fitted: Structure,
    /// Names of the estimated parameters, in the estimator's order (which [`params`](Self::params)
    /// may extend with derived values, such as a profiled `n` or `σ`).
    pub estimated: Vec<String>,
    /// Asymptotic covariance of the estimated parameters, in the order of
    /// [`estimated`](Self::estimated), when computed and defined.
    pub estimator_covariance: Option<Vec<Vec<f64>>>,
}

/// Names of the reported parameters, in order, for an experiment fitted with `method`.
pub fn param_names(
    exp: &Experiment,
    signal: &AnySignal,
    method: Method,
) -> StudyResult<Vec<String>> {
    let s = structure(exp, signal.clone(), method)?;
    Ok(report_names(exp, &s))
}

/// Whether the experiment profiles the uniform-sum order over `[jitter] n_range`.
pub(crate) fn profiled(exp: &Experiment) -> bool {
    exp.jitter.estimate && exp.jitter.n_range.is_some()
}

fn report_names(exp: &Experiment, s: &Structure) -> Vec<String> {
    let mut names = Vec::new();
    let (ns, _, _) = s.blocks();
    let all = s.param_names();
    names.extend(all[..ns].iter().cloned());
    if s.estimate_jitter {
        if profiled(exp) {
            names.extend(["jitter.n".into(), "jitter.a".into(), "jitter.sigma".into()]);
        } else {
            names.extend(s.jitter.param_names().iter().map(|n| format!("jitter.{n}")));
        }
    }
    if s.estimate_noise {
        names.extend(s.noise.param_names().iter().map(|n| format!("noise.{n}")));
    }
    if exp.noise.estimate {
        names.push("noise.std".into());
    }
    names
}

/// True values of the reported parameters (`None` where the fitted family differs from the
/// true one).
pub fn truth_values(
    exp: &Experiment,
    signal_truth: &AnySignal,
    method: Method,
) -> StudyResult<Vec<Option<f64>>> {
    let s = structure(exp, signal_truth.clone(), method)?;
    let names = report_names(exp, &s);
    let mut out = Vec::with_capacity(names.len());
    if s.estimate_signal {
        // After an input with a history the free response's coefficients are those of each
        // realisation's state at t0: no one truth.
        let names = signal_truth.param_names();
        out.extend(signal_truth.params().into_iter().zip(&names).map(|(p, n)| {
            let initial = n.starts_with(jitterid::signal::INITIAL_PREFIX)
                || n.contains(&format!(".{}", jitterid::signal::INITIAL_PREFIX));
            (!exp.has_history() || !initial).then_some(p)
        }));
    }
    if s.estimate_jitter {
        let t = &exp.jitter.truth;
        if profiled(exp) {
            match (t.downcast_ref::<UniformSum>(), exp.jitter.family_differs) {
                (Some(u), false) => {
                    out.extend([Some(f64::from(u.n())), Some(u.a())]);
                }
                _ => out.extend([None, None]),
            }
            out.push(Some(t.std_dev()));
        } else if exp.jitter.family_differs {
            out.extend(
                s.jitter
                    .param_names()
                    .iter()
                    .map(|n| (*n == "sigma").then(|| t.std_dev())),
            );
        } else {
            out.extend(t.params().into_iter().map(Some));
        }
    }
    if s.estimate_noise {
        out.extend(exp.noise.shape.params().into_iter().map(Some));
    }
    if exp.noise.estimate {
        out.push(Some(exp.noise.std));
    }
    debug_assert_eq!(out.len(), names.len());
    Ok(out)
}

/// The options of a fit of `criterion`. A first-moment criterion runs the experiment's
/// solver on its frequency set. A likelihood runs the likelihood's default solver (Brent's
/// method for one parameter, BFGS otherwise), with the wall-clock budget given to BFGS
/// (Brent's method is bounded by its iteration limit).
pub(crate) fn options(
    exp: &Experiment,
    criterion: &AnyCriterion,
    seed: u64,
    covariance: bool,
    watch: &Watch,
) -> StudyResult<FitOptions> {
    let solver = if criterion.is_likelihood() {
        let mut s = BrentOrBfgs::default();
        if let Some(max_seconds) = exp.estimate.max_seconds {
            s.bfgs.max_seconds = max_seconds;
        }
        watch.watched(AnySolver::new(s))
    } else {
        solver(exp, seed, watch)?
    };
    Ok(FitOptions {
        frequencies: exp.estimate.frequencies.clone(),
        solver: Some(solver),
        covariance,
        ..FitOptions::default()
    })
}

/// The criterion `method` names, as the experiment fits it: `"ml"`, the exact likelihood of
/// white noise, is the Gaussian (quasi) likelihood of the first two moments for an ARMA noise
/// model.
pub(crate) fn criterion_of(exp: &Experiment, s: &Structure, method: Method) -> AnyCriterion {
    let criterion = method.criterion_in(&exp.registries.criteria);
    if method.as_str() == "ml" && !s.noise.is_white() {
        AnyCriterion::quasi_ml()
    } else {
        criterion
    }
}

/// `j`, a uniform sum, with its whole number `n` replaced (rebuilt through the registry).
pub(crate) fn with_n(j: &AnyJitter, n: u32) -> Result<AnyJitter, JitterError> {
    let mut spec = j.spec();
    spec.insert("n".into(), n.into());
    JitterRegistry::builtin().build(&spec)
}

/// Runs `criterion` on `s` as the experiment asks: the uniform-sum order profiled when it is
/// estimated over a range, the jitter's white floor beside an ARMA shape for a criterion that
/// weights by the noise model. Returns the estimate, the fitted structure (with `σ_v` when the
/// criterion estimated it) and the profiled `n`.
fn run_criterion(
    exp: &Experiment,
    s: &Structure,
    record: &Record,
    criterion: &AnyCriterion,
    opts: &FitOptions,
) -> Result<(Estimate, Structure, Option<u32>), EstimateError> {
    if profiled(exp) {
        if let (Some(u), Some((lo, hi))) =
            (s.jitter.downcast_ref::<UniformSum>(), exp.jitter.n_range)
        {
            let values = i64::from(lo)..=i64::from(hi);
            let build = uniform_sum_with_std(u.std_dev());
            let p = fit_profile(s, record, criterion, opts, values, build)?;
            let n = p.value as u32;
            let mut base = s.clone();
            base.jitter = with_n(&s.jitter, n)?;
            let fitted = fitted_structure(&base, criterion, &p.estimate)?;
            return Ok((p.estimate, fitted, Some(n)));
        }
    }
    // A criterion that weights by the noise model (Box–Jenkins) sees the jitter's white floor
    // beside the ARMA shape; the likelihoods add it from the jitter's second moment themselves.
    let sees_noise = criterion
        .as_first_moment()
        .is_some_and(|c| c.uses_noise_model());
    if sees_noise {
        let guess = (exp.noise.std > 0.0).then_some(exp.noise.std);
        let (e, fitted) = s.fit_with_jitter_floor(record, guess, |floored| {
            fit_criterion(floored, record, criterion, opts)
        })?;
        return Ok((e, fitted, None));
    }
    let e = fit_criterion(s, record, criterion, opts)?;
    let fitted = fitted_structure(s, criterion, &e)?;
    Ok((e, fitted, None))
}

/// `base` at the estimate `e`: a likelihood's parameters are the structure's followed by the
/// `σ_v` it estimated, which becomes the structure's noise level.
fn fitted_structure(
    base: &Structure,
    criterion: &AnyCriterion,
    e: &Estimate,
) -> Result<Structure, EstimateError> {
    if !criterion.is_likelihood() {
        return base.with_params(&e.params);
    }
    let k = base.num_params();
    let mut fitted = base.with_params(e.params.get(..k).unwrap_or(&e.params))?;
    fitted.noise_std = Some(e.noise_std);
    Ok(fitted)
}

/// The raw outcome of one estimator, before the parameters are arranged for the report.
pub(crate) struct Raw {
    /// The structure's free parameters, then `σ_v` when a likelihood estimated it.
    params: Vec<f64>,
    std_errors: Option<Vec<f64>>,
    names: Vec<String>,
    covariance: Option<Vec<Vec<f64>>>,
    cost: f64,
    iterations: u64,
    termination: String,
    converged: bool,
    noise_std: f64,
    fitted: Structure,
    n: Option<u32>,
}

impl Raw {
    /// The outcome of an estimator with the structure it fitted and the profiled `n`, if any.
    pub(crate) fn of(e: Estimate, fitted: Structure, n: Option<u32>) -> Self {
        Raw {
            params: e.params,
            std_errors: e.std_errors,
            names: e.names,
            covariance: e.covariance,
            cost: e.cost,
            iterations: e.iterations,
            termination: e.termination.to_string(),
            converged: e.converged,
            noise_std: e.noise_std,
            fitted,
            n,
        }
    }
}

/// Fits structure `s` (started at its parameters) to `record` with `method`; the error is a
/// message.
///
/// A likelihood fit of an estimated system starts from the BCLS estimate (or, with
/// [`LikelihoodStart::Given`](crate::experiment::LikelihoodStart::Given), from `s` with the
/// BCLS route as a check) and is not reported as converged when it stopped at an optimum BCLS
/// could not have given on this record (see `likelihood_start`): the whole under one time
/// limit.
pub fn fit(
    exp: &Experiment,
    s: &Structure,
    record: &Record,
    method: Method,
    seed: u64,
    covariance: bool,
    watch: &Watch,
) -> Result<Fit, String> {
    let call = FitCall {
        exp,
        record,
        method,
        seed,
        covariance,
        watch,
    };
    if criterion_of(exp, s, method).is_likelihood() && s.estimate_signal && !profiled(exp) {
        let budget = crate::budget_of(exp, watch.cancel.clone());
        return budget.run(|| crate::likelihood_start::fit(&call, s));
    }
    call.once(s)
}

/// Everything of a fit but its start: what [`fit`] runs once or several times.
pub(crate) struct FitCall<'a> {
    pub(crate) exp: &'a Experiment,
    pub(crate) record: &'a Record,
    pub(crate) method: Method,
    pub(crate) seed: u64,
    pub(crate) covariance: bool,
    pub(crate) watch: &'a Watch,
}

impl FitCall<'_> {
    /// One fit from `s`'s parameters, under its own time limit.
    pub(crate) fn once(&self, s: &Structure) -> Result<Fit, String> {
        fit_once(self, s)
    }
}

/// One fit of `s` from its parameters, under its own time limit.
fn fit_once(call: &FitCall<'_>, s: &Structure) -> Result<Fit, String> {
    let (exp, record, method, seed) = (call.exp, call.record, call.method, call.seed);
    let (covariance, watch) = (call.covariance, call.watch);
    let criterion = criterion_of(exp, s, method);
    if criterion.is_likelihood() && !cfg!(feature = "ml") {
        return Err("maximum likelihood is not available in this build of jitterid".into());
    }
    let opts = options(exp, &criterion, seed, covariance, watch).map_err(|e| e.to_string())?;
    // The fit's whole work (search, covariance, flatness) under its time limit and the front
    // end's cancel flag: a spent budget ends the search as not converged with the reason, or,
    // when it ran out before the search began, as this error rather than the NaN it left.
    let budget = crate::budget_of(exp, watch.cancel.clone());
    let (e, fitted, n) = budget
        .run(|| run_criterion(exp, s, record, &criterion, &opts))
        .map_err(|e| match budget.stop() {
            Some(stop) => format!("stopped before the search could begin: {stop}"),
            None => e.to_string(),
        })?;
    reported(exp, s, method, Raw::of(e, fitted, n))
}

/// The fit of `s` with `method` as reported: the estimator's outcome `e` with the reported
/// parameters (a profiled order and its derived `σ`, a noise level estimated after the fit)
/// and their covariance.
pub(crate) fn reported(
    exp: &Experiment,
    s: &Structure,
    method: Method,
    e: Raw,
) -> Result<Fit, String> {
    let names = report_names(exp, s);
    let se = |i: usize| {
        e.std_errors
            .as_ref()
            .and_then(|v| v.get(i).copied())
            .filter(|x| x.is_finite())
    };
    let (ns, nj, nn) = s.blocks();
    let mut params = Vec::with_capacity(names.len());
    let mut sources: Vec<CovarianceSource> = Vec::with_capacity(names.len());
    let mut push = |estimate: f64, stderr: Option<f64>, source: CovarianceSource| {
        sources.push(source);
        let name = names.get(params.len()).cloned().unwrap_or_default();
        params.push(Param {
            name,
            estimate,
            stderr,
        });
    };
    let at = |i: usize| e.params.get(i).copied().unwrap_or(f64::NAN);
    for i in 0..ns {
        push(at(i), se(i), Some((i, 1.0)));
    }
    if let Some(n) = e.n {
        let a = at(ns);
        // σ = a/√(3(n+1)); the divisor is the half-width of the unit-σ member.
        let k = uniform_sum_with_std(1.0)(i64::from(n))
            .map_err(|e| e.to_string())?
            .params()[0];
        push(f64::from(n), None, None);
        push(a, se(ns), Some((ns, 1.0)));
        push(a / k, se(ns).map(|s| s / k), Some((ns, 1.0 / k)));
    } else {
        for i in ns..ns + nj {
            push(at(i), se(i), Some((i, 1.0)));
        }
    }
    for i in ns + nj..ns + nj + nn {
        push(at(i), se(i), Some((i, 1.0)));
    }
    if exp.noise.estimate {
        // A likelihood estimates σ_v jointly (the last parameter); the least-squares criteria
        // estimate it from the residuals afterwards (no standard error).
        let joint = e.params.len() > ns + nj + nn;
        let last = ns + nj + nn;
        push(
            e.noise_std,
            if joint { se(last) } else { None },
            joint.then_some((last, 1.0)),
        );
    }
    Ok(Fit {
        method,
        converged: e.converged,
        cost: e.cost,
        iterations: e.iterations,
        termination: e.termination,
        noise_std: e.noise_std,
        covariance: e
            .covariance
            .as_deref()
            .map(|c| reported_covariance(c, &sources)),
        params,
        fitted: e.fitted,
        estimated: e.names,
        estimator_covariance: e.covariance,
    })
}

/// `θ ∘ (1 + U(−r, r))`, componentwise, drawn from `rng`.
pub fn perturb(theta: &[f64], r: f64, rng: &mut StdRng) -> Vec<f64> {
    theta
        .iter()
        .map(|x| x * (1.0 + rng.random_range(-r..=r)))
        .collect()
}

/// A record from samples on the experiment's grid.
pub fn record(grid: &SampleGrid, y: Vec<f64>) -> Result<Record, EstimateError> {
    Record::new(*grid, y)
}

/// The JSON of `jitterid fit --json`, borrowed from a [`Fit`].
#[derive(Debug, Serialize)]
pub struct FitJson<'a> {
    method: &'a str,
    converged: bool,
    cost: f64,
    iterations: u64,
    termination: &'a str,
    noise_std: f64,
    parameters: &'a [Param],
    /// Covariance of `parameters`, in their order (`null` where undefined).
    covariance: Option<&'a [Vec<Option<f64>>]>,
    /// The fitted system in zpk, tf and state-space form (rational systems only).
    #[serde(skip_serializing_if = "Option::is_none")]
    model: Option<export::ExportedModel>,
    /// Why a rational system's export could not be made (absent when it was, or for a system
    /// that is not rational): an export never goes missing without a word.
    #[serde(skip_serializing_if = "Option::is_none")]
    model_error: Option<String>,
    /// What the record suggests the model misses ([`crate::notes`]); absent without a note.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    notes: Vec<String>,
}

/// Fits the experiment's model with its method to the samples `y` of a record whose input
/// `signal` holds; `data` names the record in messages.
///
/// `watch.iterations` follows the solver's iterations.
pub fn fit_values(
    exp: &Experiment,
    signal: AnySignal,
    y: Vec<f64>,
    data: &str,
    watch: &Watch,
) -> StudyResult<Fit> {
    let record = record(&exp.grid, y).map_err(|e| study_err!("{data}: {e}"))?;
    fit_record(exp, signal, &record, watch)
}

/// [`fit_values`] of a record already made: a caller that keeps the samples (for figures)
/// shares them with the fit instead of handing it a copy.
pub fn fit_record(
    exp: &Experiment,
    signal: AnySignal,
    record: &Record,
    watch: &Watch,
) -> StudyResult<Fit> {
    let method = exp.estimate.method;
    let s = structure(exp, signal, method)?;
    fit(exp, &s, record, method, 0, true, watch).map_err(|e| {
        study_err!(
            "{}: fit with method {} failed: {e}",
            exp.file,
            method.as_str()
        )
    })
}

/// The JSON of `jitterid fit --json`, with the notes of the fit's record.
pub fn fit_json_noted<'a>(f: &'a Fit, notes: &crate::notes::Notes) -> FitJson<'a> {
    FitJson {
        notes: notes.lines(),
        ..fit_json(f)
    }
}

/// The JSON of `jitterid fit --json`.
pub fn fit_json(f: &Fit) -> FitJson<'_> {
    let (model, model_error) = match export::exported_model(&f.fitted.signal) {
        Ok(m) => (m, None),
        Err(e) => (
            None,
            Some(format!("the fitted model could not be exported: {e}")),
        ),
    };
    FitJson {
        method: f.method.as_str(),
        converged: f.converged,
        cost: f.cost,
        iterations: f.iterations,
        termination: &f.termination,
        noise_std: f.noise_std,
        parameters: &f.params,
        covariance: f.covariance.as_deref(),
        model,
        model_error,
        notes: Vec::new(),
    }
}
