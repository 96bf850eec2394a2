//! Fuzzing the library's estimation entry points: random model structures,
//! parameters, inputs, jitter laws, criteria, frequency sets, solver options and data —
//! including NaN, infinite, huge and tiny values — through [`estimate`] and the initializer
//! ([`initialize`], then [`estimate`] from its start with [`MultiStart`]).
//!
//! Every run-time choice is drawn as a front end holds it, a spec table (key/value pairs),
//! and built through its registry: the signal kind ([`SignalRegistry`]), the jitter family
//! ([`JitterRegistry`]), the criterion ([`CriterionRegistry`]), the noise model
//! ([`NoiseRegistry`]) and the solver ([`SolverRegistry`]). The entry is picked by index into
//! the registry's list and each of its keys drawn by its description, so an entry added to a
//! registry is fuzzed with no edit here (and the run checks that every entry was drawn).
//! JSON holds no NaN or ±∞: in a spec table they are null, as in a table read from a file;
//! the record's data, the input (built by its constructors: there is no registry of inputs)
//! and the frequency set still carry them.
//!
//! The properties: no panic; no hang (every solver runs with a small iteration budget, and the
//! whole run is timed); an `Ok` estimate is internally consistent (finite non-negative cost,
//! parameters of the right length and valid for the structure, finite parameters when
//! converged, finite covariance when present); everything else is a typed error.
//!
//! CI runs 256 cases from a fixed seed (about two seconds). A longer run:
//!
//! ```text
//! PROPTEST_CASES=10000 cargo test --release -p jitterid-tests --test fuzz -- --nocapture
//! ```
//!
//! (`PROPTEST_RNG_SEED=<u64>` picks another seed; the summary of what the cases reached is
//! printed with `--nocapture`.)

use jitterid::estimate::solver::{
    AnySolver, LevenbergMarquardt, MultiStart, NelderMead, SolverRegistry,
};
use jitterid::estimate::{
    fit, initialize, Bcls, Criterion, CriterionRegistry, EstimateError, Fit, FitOptions,
    Frequencies, InitOptions, InitialModel, Ls, ModelStructure, NoiseModel, NoiseRegistry, Record,
    Registry,
};
use jitterid::jitter::registry::{JitterRegistry, SpecTable};
use jitterid::jitter::{AnyJitter, JitterError, JitterModel};
use jitterid::prelude::*;
use jitterid::signal::registry::{KindReader, SignalRegistry, KIND_KEY};
use jitterid::signal::{AnySignal, SignalError, Tone};
use jitterid::window::HannWindow;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed, TestRunner};
use serde_json::Value;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

/// Cases in CI (`PROPTEST_CASES` overrides): about as many initializer runs on `zpk`/`tf` tables
/// as before the harness drew every registered signal kind.
const CI_CASES: u32 = 384;
/// Seed in CI (`PROPTEST_RNG_SEED` overrides).
const CI_SEED: u64 = 0x6a69_7474_6572;

// ---------------------------------------------------------------------------------------------
// Strategies.

/// The awkward values: zero, huge, tiny, subnormal, infinite, NaN.
fn awkward() -> impl Strategy<Value = f64> {
    prop::sample::select(vec![
        0.0,
        1e300,
        -1e300,
        f64::MAX,
        -1e-300,
        1e-300,
        5e-324,
        1e-12,
        -1e12,
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ])
}

/// Ordinary values most of the time, an awkward one now and then.
fn any_value(scale: f64) -> impl Strategy<Value = f64> {
    prop_oneof![
        8 => (-1.0f64..1.0).prop_map(move |x| x * scale),
        1 => awkward(),
    ]
}

/// `len` ordinary values in `[-scale, scale)`, with one to three awkward values planted in a
/// quarter of the vectors.
fn values(len: usize, scale: f64) -> impl Strategy<Value = Vec<f64>> {
    (
        prop::collection::vec(-scale..scale, len),
        prop::option::weighted(0.25, prop::collection::vec((0..len, awkward()), 1..4)),
    )
        .prop_map(|(mut v, planted)| {
            for (i, x) in planted.unwrap_or_default() {
                v[i] = x;
            }
            v
        })
}

/// A magnitude spread over many decades, with a random sign when `signed`.
fn log_value(lo: f64, hi: f64, signed: bool) -> impl Strategy<Value = f64> {
    (lo..hi, any::<bool>()).prop_map(move |(e, neg)| {
        let v = 10f64.powf(e);
        if signed && neg {
            -v
        } else {
            v
        }
    })
}

/// A parameter: mostly plausible (a negative real part for poles when `stable`), sometimes
/// extreme or invalid.
fn param(stable: bool) -> impl Strategy<Value = f64> {
    prop_oneof![
        12 => log_value(-3.0, 2.0, !stable).prop_map(move |v| if stable { -v } else { v }),
        1 => log_value(-12.0, 12.0, true),
        1 => awkward(),
    ]
}

/// A spec-table value: a JSON number, or null for what JSON cannot hold (NaN, ±∞), as a
/// table read from an experiment file holds it.
fn number(x: f64) -> Value {
    Value::from(x)
}

fn numbers(v: Vec<f64>) -> Value {
    Value::Array(v.into_iter().map(number).collect())
}

/// A list of roots as a spec table writes them: a number (a real root) or `[re, im]` (a pair);
/// mostly stable and non-empty, sometimes of either sign and empty.
fn roots_value() -> impl Strategy<Value = Value> {
    let root = |stable: bool| {
        prop_oneof![
            param(stable).prop_map(number),
            (param(stable), param(false))
                .prop_map(|(re, im)| Value::Array(vec![number(re), number(im.abs())])),
        ]
    };
    prop_oneof![
        3 => prop::collection::vec(root(true), 1..3),
        1 => prop::collection::vec(root(false), 0..3),
    ]
    .prop_map(Value::Array)
}

/// A list of numbers within the documented `constraint`: small coefficients (an ARMA
/// polynomial with its roots inside the unit circle) where it mentions the unit circle;
/// weights (non-negative, now and then non-finite, of any length) where it asks for `>= 0`;
/// else a monic polynomial with positive coefficients (a stable-looking denominator) or
/// coefficients of any sign and size.
fn list_value(constraint: &str) -> BoxedStrategy<Value> {
    let small = || prop::collection::vec(-0.9f64..0.9, 0..3);
    let weights = || {
        (1usize..40, values(40, 3.0), any::<bool>()).prop_map(|(n, w, plain)| {
            w[..n]
                .iter()
                .map(|x| match (x.is_finite(), plain) {
                    (true, _) => x.abs(),
                    (false, true) => 1.0,
                    (false, false) => *x,
                })
                .collect::<Vec<f64>>()
        })
    };
    let lists = if constraint.contains("unit circle") {
        small().boxed()
    } else if constraint.contains(">= 0") || constraint.contains("≥ 0") {
        weights().boxed()
    } else {
        prop_oneof![
            3 => prop::collection::vec(log_value(-2.0, 2.0, false), 1..4).prop_map(|mut v| {
                v.insert(0, 1.0);
                v
            }),
            2 => prop::collection::vec(param(false), 1..3),
        ]
        .boxed()
    };
    lists.prop_map(numbers).boxed()
}

/// A number for the key `p` within its documented constraint: whole-number keys small (an
/// iteration limit at most 24, so that every solver runs on a small budget; a count or seed
/// whose default is small, such as the number of perturbed starts, at most 3), real keys
/// their default or a magnitude over several decades, positive where the constraint asks
/// for `>` or `≥`, of either sign otherwise. Values outside the constraint come from
/// [`entry_table`]'s corruption.
fn number_value(p: &ParamSpec) -> BoxedStrategy<Value> {
    if p.boolean {
        return any::<bool>().prop_map(|b| Value::from(u8::from(b))).boxed();
    }
    if p.integer {
        return match p.default {
            Some(d) if d <= 3.0 => (0u64..4).prop_map(Value::from).boxed(),
            _ => (1u64..25).prop_map(Value::from).boxed(),
        };
    }
    let positive = p.constraint.contains('>') || p.constraint.contains('≥');
    let typical = match p.default {
        Some(d) => Just(d).boxed(),
        None => log_value(-3.0, 2.0, false).boxed(),
    };
    prop_oneof![
        2 => typical,
        3 => log_value(-3.0, 2.0, !positive),
        1 => log_value(-12.0, 12.0, !positive),
    ]
    .prop_map(number)
    .boxed()
}

/// A value of any shape (an awkward number, a list, a list of roots, a boolean, a string):
/// what a spec table holds when its author writes the wrong kind of value.
fn any_shape() -> impl Strategy<Value = Value> {
    prop_oneof![
        3 => awkward().prop_map(number),
        1 => list_value(""),
        1 => list_value("unit circle"),
        1 => roots_value(),
        1 => Just(Value::Bool(true)),
        1 => Just(Value::from("x")),
    ]
}

/// A value for the key `p`, of the shape its description documents: a list of roots where
/// it mentions `[re, im]`, a list of numbers where it mentions a list, coefficients or `…`,
/// else a number. A key added to a registry is drawn with no edit here.
fn key_value(p: &ParamSpec) -> BoxedStrategy<Value> {
    let text = format!("{} {}", p.meaning, p.constraint);
    if text.contains("[re, im]") {
        roots_value().boxed()
    } else if text.contains("list") || text.contains("coefficients") || text.contains('…') {
        list_value(&p.constraint)
    } else {
        number_value(p)
    }
}

/// The keys of one entry: whole-number keys always (budgets: their defaults are sized for
/// real fits, not for hundreds of fuzz cases), required keys always (a missing one comes from
/// [`entry_table`]'s corruption), optional ones and those with a default now and then.
fn keys_of(params: &[ParamSpec]) -> Vec<BoxedStrategy<Option<(String, Value)>>> {
    params
        .iter()
        .map(|p| {
            let required = p.default.is_none() && !p.constraint.starts_with("optional");
            let key = p.key.clone();
            let value = key_value(p).prop_map(move |v| (key.clone(), v));
            if p.integer || required {
                value.prop_map(Some).boxed()
            } else {
                prop::option::weighted(0.2, value).boxed()
            }
        })
        .collect()
}

/// How a drawn table is spoiled, now and then: one key's value replaced by one of any shape,
/// one key removed, or a key the entry does not take added (a typed error naming the key is
/// then expected).
#[derive(Debug, Clone)]
struct Corruption {
    /// Which key (an index taken modulo the table's keys).
    key: usize,
    /// `Some`: the new value; `None`: the key is removed.
    value: Option<Value>,
    /// Whether an unknown key is added instead.
    unknown: bool,
}

fn corruption() -> impl Strategy<Value = Option<Corruption>> {
    prop::option::weighted(
        0.04,
        (
            any::<usize>(),
            prop::option::weighted(0.8, any_shape()),
            prop::bool::weighted(0.15),
        )
            .prop_map(|(key, value, unknown)| Corruption {
                key,
                value,
                unknown,
            }),
    )
}

/// A spec table naming, under `name_key`, one of `entries` (name and keys) picked by index,
/// with values for its keys and for `common` (keys every entry takes), spoiled now and then
/// (see [`Corruption`]). Everything a registry lists is drawn, so an entry added to it is
/// fuzzed with no edit here.
fn entry_table(
    name_key: &'static str,
    entries: Vec<(String, Vec<ParamSpec>)>,
    common: Vec<ParamSpec>,
) -> BoxedStrategy<SpecTable> {
    let count = entries.len();
    (0..count)
        .prop_flat_map(move |i| {
            let (name, params) = entries[i].clone();
            let mut keys = keys_of(&params);
            keys.extend(keys_of(&common));
            (keys, corruption()).prop_map(move |(pairs, corruption)| {
                let mut table = SpecTable::new();
                table.insert(name_key.into(), name.clone().into());
                table.extend(pairs.into_iter().flatten());
                if let Some(c) = corruption {
                    let keys: Vec<String> =
                        table.keys().filter(|k| *k != name_key).cloned().collect();
                    match (c.unknown || keys.is_empty(), c.value) {
                        (true, v) => {
                            table.insert("unknown".into(), v.unwrap_or(Value::from(1.0)));
                        }
                        (false, Some(v)) => {
                            table.insert(keys[c.key % keys.len()].clone(), v);
                        }
                        (false, None) => {
                            table.remove(&keys[c.key % keys.len()]);
                        }
                    }
                }
                table
            })
        })
        .boxed()
}

/// The entries of an estimation-crate registry, by name and keys.
fn entries<T>(registry: &Registry<T>) -> Vec<(String, Vec<ParamSpec>)> {
    registry
        .entries()
        .iter()
        .map(|e| (e.name.to_string(), e.params.clone()))
        .collect()
}

/// A signal as a spec table of the signal registry: any kind it lists (`zpk`, `tf`,
/// `sinusoid`, `pulse-response`, and whatever is added), with its keys.
fn signal() -> BoxedStrategy<SpecTable> {
    entry_table(KIND_KEY, signal_kinds(), Vec::new())
}

/// The signal registry's kinds, by name and keys.
fn signal_kinds() -> Vec<(String, Vec<ParamSpec>)> {
    SignalRegistry::builtin()
        .kinds()
        .map(|k| (k.name().to_string(), k.params().to_vec()))
        .collect()
}

/// The known input, built by its validating constructors (there is no registry of inputs;
/// JSON could not hold the NaN and ±∞ planted in the levels): steps, or a few tones. An
/// invalid one is kept as its typed error's text.
fn input() -> impl Strategy<Value = Result<Input, String>> {
    prop_oneof![
        4 => (
            -50.0f64..10.0,
            prop::collection::vec(log_value(-3.0, 2.5, false), 1..12),
            values(12, 2.0)
        )
            .prop_map(|(start, widths, levels)| {
                let mut edges = vec![start];
                for w in &widths {
                    edges.push(edges[edges.len() - 1] + w);
                }
                PiecewiseConstant::new(edges, levels[..widths.len()].to_vec())
                    .map(Input::from)
                    .map_err(|e| e.to_string())
            }),
        1 => prop::collection::vec((log_value(-3.0, 1.0, false), any_value(3.0), -3.0f64..3.0), 1..3)
            .prop_map(|tones| {
                let tones = tones
                    .into_iter()
                    .map(|(frequency, amplitude, phase)| Tone { frequency, amplitude, phase })
                    .collect();
                Multisine::new(tones).map(Input::from).map_err(|e| e.to_string())
            }),
    ]
}

/// A spec table for the library's jitter registry: a family (any registered one that takes no
/// terms), a value for each of its keys, and sometimes an offset. A family added to the
/// registry is fuzzed with no edit here.
#[derive(Debug, Clone)]
struct JitterSpec {
    family: String,
    /// Each key's value; a real JSON cannot hold (NaN, ±∞) is null.
    values: Vec<(String, serde_json::Value)>,
    offset: Option<f64>,
}

fn jitter() -> impl Strategy<Value = JitterSpec> {
    let width = || {
        prop_oneof![
            6 => log_value(-4.0, 0.5, false),
            1 => log_value(-9.0, 1.5, false),
            1 => any_value(1.0),
        ]
    };
    // (name, [(key, whole number?)]) of every family without terms.
    let families: Vec<(String, Vec<(String, bool)>)> = JitterRegistry::builtin()
        .families()
        .filter(|f| !f.takes_terms())
        .map(|f| {
            let keys = f.params().iter().map(|p| (p.key.clone(), p.integer));
            (f.name().to_string(), keys.collect())
        })
        .collect();
    let count = families.len();
    // n ≤ 12 for whole-number keys keeps the CI budget: the uniform sum's density costs O(n²)
    // per node, and the second moment's rules are rebuilt for every sample with input steps in
    // reach (n up to 50 is a corner test of its own).
    (
        0..count,
        prop::collection::vec((0u32..13, width()), 8),
        prop::option::weighted(0.15, any_value(1.0)),
    )
        .prop_map(move |(i, draws, offset)| {
            let (family, keys) = &families[i];
            let values = keys
                .iter()
                .zip(draws)
                .map(|((k, whole), (n, w))| {
                    let v = if *whole {
                        serde_json::Value::from(n)
                    } else {
                        serde_json::Value::from(w)
                    };
                    (k.clone(), v)
                })
                .collect();
            JitterSpec {
                family: family.clone(),
                values,
                offset,
            }
        })
}

/// The criterion registry's entries except those that build, with their defaults, into a
/// likelihood (this harness runs the first-moment estimator); an entry that needs keys to
/// build is kept.
fn first_moment_criteria() -> Vec<(String, Vec<ParamSpec>)> {
    let registry = CriterionRegistry::builtin();
    entries(&registry)
        .into_iter()
        .filter(|(name, _)| {
            let mut t = SpecTable::new();
            t.insert(registry.key().into(), name.as_str().into());
            registry
                .build(&t)
                .map_or(true, |c| c.as_first_moment().is_some())
        })
        .collect()
}

/// A first-moment criterion as a spec table of the criterion registry.
fn criterion() -> BoxedStrategy<SpecTable> {
    let key = CriterionRegistry::builtin().key();
    entry_table(key, first_moment_criteria(), Vec::new())
}

/// A noise model as a spec table of the noise registry (used by the BJ and JBJ structures).
fn noise() -> BoxedStrategy<SpecTable> {
    let registry = NoiseRegistry::builtin();
    entry_table(registry.key(), entries(&registry), Vec::new())
}

/// A solver as a spec table of the solver registry: any entry, with its keys and the
/// multi-start keys every solver takes.
fn solver() -> BoxedStrategy<SpecTable> {
    let registry = SolverRegistry::builtin();
    let common = registry.common_keys().to_vec();
    entry_table(registry.key(), entries(&registry), common)
}

/// A frequency set in units of `1/T` (converted by [`in_hertz`] for the case's `T`),
/// occasionally invalid. A frequency set is an option of the estimator, not a run-time family:
/// its variants are the library's own [`Frequencies`].
fn frequencies() -> impl Strategy<Value = Frequencies> {
    prop_oneof![
        3 => Just(Frequencies::Dft),
        1 => (prop_oneof![6 => 0.0f64..0.5, 1 => awkward()], prop_oneof![6 => 0.0f64..0.5, 1 => awkward()])
            .prop_map(|(min, width)| Frequencies::Band { min, max: min + width }),
        1 => (0usize..12, values(12, 1.0))
            .prop_map(|(n, v)| Frequencies::List(v[..n].iter().map(|x| if x.is_finite() { x.abs() } else { *x }).collect())),
    ]
}

/// `f`, given in units of `1/T`, in hertz for the sampling interval `interval`.
fn in_hertz(f: &Frequencies, interval: f64) -> Frequencies {
    match f {
        Frequencies::Dft => Frequencies::Dft,
        Frequencies::Band { min, max } => Frequencies::Band {
            min: min / interval,
            max: max / interval,
        },
        Frequencies::List(v) => Frequencies::List(v.iter().map(|f| f / interval).collect()),
    }
}

/// One case: the record, and spec tables for everything a front end chooses at run time.
#[derive(Debug, Clone)]
struct Case {
    n: usize,
    interval: f64,
    start: f64,
    data: Vec<f64>,
    signal: SpecTable,
    input: Result<Input, String>,
    jitter: JitterSpec,
    /// 0 OE, 1 JOE, 2 BJ, 3 JBJ; then what is estimated (when not the structure's default), the
    /// noise model (BJ and JBJ), a known noise level.
    structure: u8,
    estimated: Option<(bool, bool, bool)>,
    noise: SpecTable,
    noise_std: Option<f64>,
    criterion: SpecTable,
    frequencies: Frequencies,
    hann: bool,
    solver: SpecTable,
    covariance: bool,
}

fn case() -> impl Strategy<Value = Case> {
    let grid = (1usize..65, log_value(-2.0, 1.0, false), -20.0f64..20.0);
    let data = values(64, 1.0);
    (
        (grid, data, signal(), input(), jitter()),
        (
            0u8..4,
            prop::option::weighted(0.25, (any::<bool>(), any::<bool>(), any::<bool>())),
            noise(),
            prop::option::of(any_value(0.1).prop_map(|x| if x.is_finite() { x.abs() } else { x })),
            criterion(),
            frequencies(),
            any::<bool>(),
            solver(),
            any::<bool>(),
        ),
    )
        .prop_map(
            |(
                ((n, interval, start), data, signal, input, jitter),
                (
                    structure,
                    estimated,
                    noise,
                    noise_std,
                    criterion,
                    frequencies,
                    hann,
                    solver,
                    covariance,
                ),
            )| Case {
                n,
                interval,
                start,
                data,
                signal,
                input,
                jitter,
                structure,
                estimated,
                noise,
                noise_std,
                criterion,
                frequencies,
                hann,
                solver,
                covariance,
            },
        )
}

// ---------------------------------------------------------------------------------------------
// Running a case.

/// What the cases reached, for the summary.
#[derive(Default)]
struct Tally {
    cases: AtomicUsize,
    rejected_setup: AtomicUsize,
    estimate_err: AtomicUsize,
    estimate_ok: AtomicUsize,
    converged: AtomicUsize,
    init_ok: AtomicUsize,
    init_err: AtomicUsize,
}

static TALLY: Tally = Tally {
    cases: AtomicUsize::new(0),
    rejected_setup: AtomicUsize::new(0),
    estimate_err: AtomicUsize::new(0),
    estimate_ok: AtomicUsize::new(0),
    converged: AtomicUsize::new(0),
    init_ok: AtomicUsize::new(0),
    init_err: AtomicUsize::new(0),
};

static ERRORS: Mutex<Vec<(String, usize)>> = Mutex::new(Vec::new());

/// The registry entries the cases drew (`"solver lm"`, …), with how often.
static DRAWN: Mutex<Vec<(String, usize)>> = Mutex::new(Vec::new());

fn count(list: &Mutex<Vec<(String, usize)>>, key: String) {
    let mut v = list.lock().unwrap();
    match v.iter_mut().find(|(k, _)| *k == key) {
        Some((_, n)) => *n += 1,
        None => v.push((key, 1)),
    }
}

/// Notes which entry each of the case's spec tables names.
fn note_drawn(case: &Case) {
    let tables = [
        (KIND_KEY, &case.signal),
        (CriterionRegistry::builtin().key(), &case.criterion),
        (NoiseRegistry::builtin().key(), &case.noise),
        (SolverRegistry::builtin().key(), &case.solver),
    ];
    for (key, table) in tables {
        if let Some(name) = table.get(key).and_then(Value::as_str) {
            count(&DRAWN, format!("{key} {name}"));
        }
    }
}

fn bump(c: &AtomicUsize) {
    c.fetch_add(1, Ordering::Relaxed);
}

/// Counts typed errors by the start of their message (numbers stripped).
fn note_error(e: &dyn std::fmt::Display) {
    let key: String = e
        .to_string()
        .chars()
        .filter(|c| !c.is_ascii_digit() && !matches!(c, '.' | '-' | '+'))
        .take(60)
        .collect();
    count(&ERRORS, key);
}

fn build_jitter(spec: &JitterSpec) -> Result<AnyJitter, JitterError> {
    let mut table = SpecTable::new();
    table.insert("family".into(), spec.family.clone().into());
    for (key, v) in &spec.values {
        table.insert(key.clone(), v.clone());
    }
    if let Some(c) = spec.offset {
        table.insert("offset".into(), c.into());
    }
    JitterRegistry::builtin().build(&table)
}

/// The invariants of an `Ok` estimate.
fn check_estimate<S, J, N>(
    e: &Fit,
    structure: &ModelStructure<S, J, N>,
) -> Result<(), TestCaseError>
where
    S: Signal + Clone,
    J: JitterModel + Clone,
    N: NoiseModel,
{
    let p = structure.num_params();
    prop_assert_eq!(e.params.len(), p);
    prop_assert_eq!(e.names.len(), p);
    prop_assert!(e.cost.is_finite() && e.cost >= 0.0, "cost {}", e.cost);
    if e.converged {
        prop_assert!(e.termination.is_convergence(), "{}", e.termination);
        prop_assert!(e.params.iter().all(|v| v.is_finite()), "{:?}", e.params);
    }
    prop_assert!(
        structure.with_params(&e.params).is_ok(),
        "estimate {:?} outside the model's domain",
        e.params
    );
    if let Some(c) = &e.covariance {
        prop_assert!(c.iter().flatten().all(|v| v.is_finite()));
    }
    if let Some(s) = &e.std_errors {
        prop_assert!(s.iter().all(|v| v.is_finite() && *v >= 0.0), "{s:?}");
    }
    Ok(())
}

/// The structure `st` with its signal replaced by `model` driven by `input`.
fn typed<M, N>(
    st: &ModelStructure<AnySignal, AnyJitter, N>,
    model: M,
    input: &Input,
) -> ModelStructure<LtiResponse<M>, AnyJitter, N>
where
    M: InitialModel,
    N: NoiseModel + Clone,
{
    ModelStructure {
        signal: LtiResponse::new(model, input.clone()),
        jitter: st.jitter.clone(),
        noise: st.noise.clone(),
        estimate_signal: st.estimate_signal,
        estimate_jitter: st.estimate_jitter,
        estimate_noise: st.estimate_noise,
        noise_std: st.noise_std,
    }
}

/// The default robust path from `structure`'s model: the initializer, then multi-start LM
/// (small budgets).
fn run_initializer<M, N>(
    structure: &ModelStructure<LtiResponse<M>, AnyJitter, N>,
    record: &Record,
) -> Result<(), TestCaseError>
where
    M: InitialModel,
    N: NoiseModel + Clone,
{
    match initialize(structure, record, &InitOptions::default()) {
        Ok(start) => {
            bump(&TALLY.init_ok);
            let options = FitOptions::default()
                .with_solver(MultiStart::new(
                    AnySolver::new(LevenbergMarquardt::default().with_max_iters(15)),
                    2,
                    0.5,
                    1,
                ))
                .with_covariance(false);
            match fit(&start, record, &Bcls, &options) {
                Ok(e) => check_estimate(&e, &start)?,
                Err(e) => note_error(&e),
            }
        }
        Err(e) => {
            bump(&TALLY.init_err);
            note_error(&e);
        }
    }
    Ok(())
}

/// Runs the initializer on `structure`'s model when the initializer has a type for its kind.
/// The initializer is typed: it fits the rational models that implement [`InitialModel`]
/// (`Zpk`, `TransferFunction`), so the registry's `zpk` and `tf` tables are read back into
/// those types with the registry's own reader (`SignalKind::reader`). Every other kind,
/// including one added to the registry, is fuzzed through [`estimate`] only.
fn run_initializer_for<N: NoiseModel + Clone>(
    structure: &ModelStructure<AnySignal, AnyJitter, N>,
    input: &Input,
    record: &Record,
) -> Result<(), TestCaseError> {
    let spec = structure.signal.spec();
    let Some(kind) = SignalRegistry::builtin().kind(structure.signal.kind()) else {
        return Ok(());
    };
    let reader = match kind.reader(&spec) {
        Ok(r) => r,
        Err(e) => {
            return Err(TestCaseError::fail(format!(
                "{spec:?} does not read back: {e}"
            )))
        }
    };
    let read = |e: SignalError| TestCaseError::fail(format!("{spec:?} does not read back: {e}"));
    match kind.name() {
        "zpk" => {
            let (k, z, p) = (
                reader.f64("gain").map_err(read)?,
                reader.roots("zeros").map_err(read)?,
                reader.roots("poles").map_err(read)?,
            );
            let model = Zpk::new(k, z, p).map_err(read)?;
            run_initializer(&typed(structure, model, input), record)
        }
        "tf" => {
            let (num, den) = (
                reader.f64_list("num").map_err(read)?,
                reader.f64_list("den").map_err(read)?,
            );
            let model = TransferFunction::new(&num, &den).map_err(read)?;
            run_initializer(&typed(structure, model, input), record)
        }
        _ => Ok(()),
    }
}

/// Estimates with `structure`, then runs the initializer from its model.
fn run_structure<N: NoiseModel + Clone>(
    case: &Case,
    structure: ModelStructure<AnySignal, AnyJitter, N>,
    input: &Input,
    record: &Record,
    criterion: &dyn Criterion,
    solver: &AnySolver,
) -> Result<(), TestCaseError> {
    let frequencies = in_hertz(&case.frequencies, case.interval);
    let solver = solver.clone();
    let options = FitOptions {
        frequencies,
        solver: Some(solver),
        covariance: case.covariance,
        ..FitOptions::default()
    };
    let options = if case.hann {
        options.with_window(HannWindow)
    } else {
        options
    };
    let result = fit(&structure, record, &criterion, &options);
    match result {
        Ok(e) => {
            bump(&TALLY.estimate_ok);
            if e.converged {
                bump(&TALLY.converged);
            }
            check_estimate(&e, &structure)?;
        }
        Err(e) => {
            bump(&TALLY.estimate_err);
            note_error(&e);
        }
    }
    run_initializer_for(&structure, input, record)
}

/// The case being run and when it started, for the watchdog.
static CURRENT: Mutex<Option<(Instant, String)>> = Mutex::new(None);

fn run_case(case: &Case) -> Result<(), TestCaseError> {
    *CURRENT.lock().unwrap() = Some((Instant::now(), format!("{case:?}")));
    let out = run_case_inner(case);
    *CURRENT.lock().unwrap() = None;
    out
}

/// Builds a case's record and, through the registries, its model, criterion and solver; a
/// setup refused with a typed error is counted, and the case ends there.
fn run_case_inner(case: &Case) -> Result<(), TestCaseError> {
    bump(&TALLY.cases);
    note_drawn(case);
    let reject = |e: &dyn std::fmt::Display| {
        note_error(e);
        bump(&TALLY.rejected_setup);
        Ok(())
    };
    let grid = match SampleGrid::new(case.start, case.interval, case.n) {
        Ok(g) => g,
        Err(e) => return reject(&e),
    };
    let record = match Record::new(grid, case.data[..case.n].to_vec()) {
        Ok(r) => r,
        Err(e) => return reject(&e),
    };
    let input = match &case.input {
        Ok(u) => u,
        Err(e) => return reject(e),
    };
    let jitter = match build_jitter(&case.jitter) {
        Ok(j) => j,
        Err(e) => return reject(&e),
    };
    let any_criterion = match CriterionRegistry::builtin().build(&case.criterion) {
        Ok(c) => c,
        Err(e) => return reject(&e),
    };
    let Some(criterion) = any_criterion.as_first_moment() else {
        return Err(TestCaseError::fail(format!(
            "{:?} is a likelihood; the strategy draws first-moment criteria only",
            case.criterion
        )));
    };
    let solver = match SolverRegistry::builtin().build(&case.solver) {
        Ok(s) => s,
        Err(e) => return reject(&e),
    };
    // The registry hands the input to the kinds driven by one.
    let signal = match SignalRegistry::builtin().build(&case.signal, Some(input)) {
        Ok(s) => s,
        Err(e) => return reject(&e),
    };
    if case.structure < 2 {
        let mut st = if case.structure == 0 {
            ModelStructure::oe(signal, jitter)
        } else {
            ModelStructure::joe(signal, jitter)
        };
        if let Some((s, j, n)) = case.estimated {
            st = st.with_estimated(s, j, n);
        }
        if let Some(sd) = case.noise_std {
            st = match st.with_noise_std(sd) {
                Ok(st) => st,
                Err(e) => return reject(&e),
            };
        }
        run_structure(case, st, input, &record, criterion, &solver)
    } else {
        let noise = match NoiseRegistry::builtin().build(&case.noise) {
            Ok(x) => x,
            Err(e) => return reject(&e),
        };
        let mut st = if case.structure == 2 {
            ModelStructure::bj(signal, jitter, noise)
        } else {
            ModelStructure::jbj(signal, jitter, noise)
        };
        if let Some((s, j, n)) = case.estimated {
            st = st.with_estimated(s, j, n);
        }
        run_structure(case, st, input, &record, criterion, &solver)
    }
}

#[test]
fn estimate_entry_points_never_panic_or_hang() {
    let mut config = Config::default();
    if std::env::var_os("PROPTEST_CASES").is_none() {
        config.cases = CI_CASES;
    }
    if std::env::var_os("PROPTEST_RNG_SEED").is_none() {
        config.rng_seed = RngSeed::Fixed(CI_SEED);
    }
    config.failure_persistence = None;
    let cases = config.cases;
    let clock = Instant::now();
    // Watchdog: names a case that runs for more than 5 s (once per case).
    std::thread::spawn(|| {
        let mut reported = String::new();
        loop {
            std::thread::sleep(std::time::Duration::from_secs(1));
            if let Some((t, c)) = CURRENT.lock().unwrap().as_ref() {
                if t.elapsed().as_secs() >= 5 && *c != reported {
                    eprintln!("slow case (over 5 s): {c}");
                    reported = c.clone();
                }
            }
        }
    });
    let mut runner = TestRunner::new(config);
    let result = runner.run(&case(), |c| run_case(&c));
    let secs = clock.elapsed().as_secs_f64();
    let get = |c: &AtomicUsize| c.load(Ordering::Relaxed);
    eprintln!(
        "fuzz: {} cases run ({cases} requested) in {secs:.1} s: {} rejected while building the \
         model/data (typed errors), {} estimates Ok ({} converged), {} estimate errors; \
         initializer {} Ok, {} typed errors",
        get(&TALLY.cases),
        get(&TALLY.rejected_setup),
        get(&TALLY.estimate_ok),
        get(&TALLY.converged),
        get(&TALLY.estimate_err),
        get(&TALLY.init_ok),
        get(&TALLY.init_err),
    );
    let mut errors = ERRORS.lock().unwrap().clone();
    errors.sort_by_key(|e| std::cmp::Reverse(e.1));
    for (e, n) in &errors {
        eprintln!("  {n:5} × {e}");
    }
    let drawn = DRAWN.lock().unwrap().clone();
    eprintln!("  drawn: {drawn:?}");
    result.unwrap();
    // Every case ran at least once (shrinking only adds cases on failure).
    assert!(get(&TALLY.cases) >= cases as usize);
    // With the CI's number of cases, every entry of every registry was drawn (the first-moment
    // criteria only): an entry added to a registry is fuzzed.
    if cases >= CI_CASES {
        let named = |key: &str, names: Vec<String>| {
            names
                .into_iter()
                .map(move |n| format!("{key} {n}"))
                .collect::<Vec<_>>()
        };
        let (noise, solvers) = (NoiseRegistry::builtin(), SolverRegistry::builtin());
        let expected = [
            named(KIND_KEY, signal_kinds().into_iter().map(|k| k.0).collect()),
            named(
                CriterionRegistry::builtin().key(),
                first_moment_criteria().into_iter().map(|k| k.0).collect(),
            ),
            named(
                noise.key(),
                entries(&noise).into_iter().map(|k| k.0).collect(),
            ),
            named(
                solvers.key(),
                entries(&solvers).into_iter().map(|k| k.0).collect(),
            ),
        ]
        .concat();
        for entry in expected {
            assert!(
                drawn.iter().any(|(k, _)| *k == entry),
                "{entry} was never drawn in {cases} cases"
            );
        }
    }
}

/// Regression test: the exact first moment of an LTI response once cost `O(reach · rate)`
/// quadrature nodes per input step inside the jitter's reach (a rule refined over the whole
/// reach, capped at `4096·16` nodes per piece), although only `O(|p|/|Re p|)` of them matter
/// (`e^{p x}` is negligible beyond `x ≈ 50/|Re p|`, and the constant part needs only the mass);
/// the second moment's rules likewise. With a Gaussian jitter of σ = 10⁶ s, 49 samples and six
/// steps it took about 15 s in the dev profile; a pole at −10⁸ rad/s with a 55-term uniform-sum
/// jitter did the same. This test asserts results, not durations (a slow path shows as a slow
/// test; the timing itself is the benchmark `cargo bench -p jitterid --bench wide_jitter`):
/// the first moment, its gradient and the second moment are finite, and the first moment
/// equals what each case reduces to in closed form.
#[test]
fn wide_jitter_moments_are_finite_and_match_closed_forms() {
    let edges = vec![-31.66, -29.66, -29.657, -29.653, -5.58, 19.0, 19.06];
    let levels = vec![1.66, 1.16, -1.46, 0.86, 1.05, 0.5];
    // ∫u dt: the input is zero outside [edges[0], edges[6]).
    let input_area: f64 = levels
        .iter()
        .zip(edges.windows(2))
        .map(|(l, e)| l * (e[1] - e[0]))
        .sum();
    let u = PiecewiseConstant::new(edges, levels).unwrap();
    let (k, p1, p2) = (-2.5, 0.222, 0.396);
    let g = Zpk::new(k, vec![], vec![Root::Real(-p1), Root::Real(-p2)]).unwrap();
    let s = LtiResponse::new(g, u);
    let grid = SampleGrid::new(-1.875, 1.664, 49).unwrap();
    // m_k, after checking that m_k, ∂m_k/∂θ and E[s²] are all finite.
    let first_moment = |s: &LtiResponse<Zpk>, j: &dyn JitterModel| {
        let m = s.expected_values(&grid, j);
        let d = s.expected_values_gradient(&grid, j);
        let q = s.expected_squares(&grid, j);
        assert!(m
            .iter()
            .chain(d.iter().flatten())
            .chain(&q)
            .all(|v| v.is_finite()));
        m
    };
    first_moment(&s, &Gaussian::new(0.03).unwrap());
    first_moment(&s, &Gaussian::new(1e2).unwrap());
    // A Gaussian much wider than the response (which lives within about L = 100 s of t = 0)
    // is flat over it: m_k = ∫ s(t) φ_σ(t − t_k) dt = G(0) ∫u dt · φ_σ(t_k) (1 + O((L/σ)²)),
    // since ∫ s dt = G(0) ∫ u dt for a stable G and an input of finite support.
    let dc_gain = k / (p1 * p2);
    for sigma in [1e4, 1e6] {
        let m = first_moment(&s, &Gaussian::new(sigma).unwrap());
        let tolerance = 10.0 * (100.0 / sigma).powi(2);
        for (k, (&mk, t)) in m.iter().zip(grid.times()).enumerate() {
            let flat = dc_gain * input_area * (-0.5 * (t / sigma).powi(2)).exp()
                / (sigma * (2.0 * std::f64::consts::PI).sqrt());
            assert!(
                (mk - flat).abs() <= tolerance * flat.abs(),
                "σ = {sigma:e}, k = {k}: m_k = {mk:e}, flat-density value {flat:e}"
            );
        }
    }
    // Fast poles: e^{p x} vanishes after 50/|p| = 0.5 µs, so only that stretch after each step
    // needs refined quadrature; and a lightly damped one (found by the fuzzer: |p| = 10¹²,
    // Re p = −0.79) that would need |p|/|Re p| sub-intervals even there.
    //
    // 10⁸/((s + 10⁸)(s + 0.5)) is 1/(s + 0.5) up to a fast mode of area 10⁻⁸ and a gain
    // change of 5·10⁻⁹: per unit step the responses differ by at most 2·10⁻⁸, and the steps
    // sum to 8.3 in size, so s(t) and every m_k differ by less than 2·10⁻⁷.
    let slow = LtiResponse::new(
        Zpk::new(1.0, vec![], vec![Root::Real(-0.5)]).unwrap(),
        s.input().clone(),
    );
    let sum54 = UniformSum::new(54, 0.5).unwrap();
    let reference = first_moment(&slow, &sum54);
    let fast = LtiResponse::new(
        Zpk::new(1e8, vec![], vec![Root::Real(-1e8), Root::Real(-0.5)]).unwrap(),
        s.input().clone(),
    );
    for (k, (a, b)) in first_moment(&fast, &sum54)
        .iter()
        .zip(&reference)
        .enumerate()
    {
        assert!(
            (a - b).abs() <= 1e-6,
            "k = {k}: fast pole {a}, slow pole alone {b}"
        );
    }
    // 10⁸/(((s + 0.79)² + 10²⁴)(s + 25)): every residue is below 10⁻¹⁵ and the input below 2,
    // so |s(t)| and |m_k| stay below about 10⁻¹⁴.
    let ringing = LtiResponse::new(
        Zpk::new(
            1e8,
            vec![],
            vec![
                Root::Pair {
                    re: -0.79,
                    im: 1e12,
                },
                Root::Real(-25.0),
            ],
        )
        .unwrap(),
        s.input().clone(),
    );
    let m = first_moment(&ringing, &ExponentialDelay::new(0.15).unwrap());
    assert!(m.iter().all(|v| v.abs() <= 1e-12), "{m:?}");
}

/// Regression test: a start where `½ Σ r²` overflows (residuals of
/// 1e300) must be a typed error, as it is for Levenberg–Marquardt, not a report with an
/// infinite cost (which `SolverReport::cost` promises never to be).
#[test]
fn nelder_mead_rejects_an_overflowing_start() {
    let grid = SampleGrid::new(0.0, 1.0, 27).unwrap();
    let mut y = vec![0.0; 27];
    y[0] = 1e300;
    let record = Record::new(grid, y).unwrap();
    let zero = PiecewiseConstant::new(vec![0.0, 1.0], vec![0.0]).unwrap();
    let model = Zpk::new(1.0, vec![], vec![Root::Real(-1.0)]).unwrap();
    let structure = ModelStructure::oe(LtiResponse::new(model, zero), NoJitter);
    let lm = fit(&structure, &record, &Ls, &FitOptions::default());
    assert!(matches!(lm, Err(EstimateError::Solver(_))), "{lm:?}");
    let options = FitOptions::default()
        .with_solver(NelderMead::default())
        .with_covariance(false);
    // A typed error is right; so would be a report with a finite cost.
    if let Ok(e) = fit(&structure, &record, &Ls, &options) {
        assert!(e.cost.is_finite(), "Ok with cost {}", e.cost);
    }
}
