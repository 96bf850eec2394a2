//! Fuzzing the library's estimation entry points: random model structures,
//! parameters, inputs, jitter laws, criteria, frequency sets, solver options and data —
//! including NaN, infinite, huge and tiny values — through [`estimate`] and the initializer
//! ([`initialize`], then [`estimate`] from its start with [`MultiStart`]).
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
    AnySolver, LevenbergMarquardt, LmOptions, MultiStart, NelderMead, Scaling,
};
use jitterid::estimate::{
    estimate, initialize, AnyCriterion, ArmaNoise, Bcls, Criterion, CriterionRegistry,
    EstimateError, EstimateOptions, Fit, Frequencies, InitOptions, InitialModel, Ls,
    ModelStructure, NoiseModel, Record,
};
use jitterid::jitter::registry::{JitterRegistry, Spec};
use jitterid::jitter::{AnyJitter, JitterError, JitterModel};
use jitterid::prelude::*;
use jitterid::signal::Tone;
use jitterid::window::{DirichletWindow, HannWindow};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed, TestRunner};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

/// Cases in CI (`PROPTEST_CASES` overrides).
const CI_CASES: u32 = 256;
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

#[derive(Debug, Clone)]
enum RootSpec {
    Real(f64),
    Pair(f64, f64),
}

fn root(stable: bool) -> impl Strategy<Value = RootSpec> {
    prop_oneof![
        param(stable).prop_map(RootSpec::Real),
        (param(stable), param(false)).prop_map(|(re, im)| RootSpec::Pair(re, im.abs())),
    ]
}

impl RootSpec {
    fn root(&self) -> Root {
        match *self {
            RootSpec::Real(x) => Root::Real(x),
            RootSpec::Pair(re, im) => Root::Pair { re, im },
        }
    }
}

#[derive(Debug, Clone)]
enum ModelSpec {
    Zpk(f64, Vec<RootSpec>, Vec<RootSpec>),
    Tf(Vec<f64>, Vec<f64>),
}

fn model() -> impl Strategy<Value = ModelSpec> {
    prop_oneof![
        (
            param(false),
            prop::collection::vec(root(false), 0..2),
            prop::collection::vec(root(true), 1..3)
        )
            .prop_map(|(k, z, p)| ModelSpec::Zpk(k, z, p)),
        (
            prop::collection::vec(param(false), 1..3),
            prop::collection::vec(log_value(-2.0, 2.0, false), 1..4)
        )
            .prop_map(|(num, mut den)| {
                den.insert(0, 1.0);
                ModelSpec::Tf(num, den)
            }),
    ]
}

#[derive(Debug, Clone)]
enum InputSpec {
    Steps {
        start: f64,
        widths: Vec<f64>,
        levels: Vec<f64>,
    },
    Tones(Vec<(f64, f64, f64)>),
}

fn input() -> impl Strategy<Value = InputSpec> {
    prop_oneof![
        4 => (
            -50.0f64..10.0,
            prop::collection::vec(log_value(-3.0, 2.5, false), 1..12),
            values(12, 2.0)
        )
            .prop_map(|(start, widths, levels)| InputSpec::Steps { start, widths, levels }),
        1 => prop::collection::vec((log_value(-3.0, 1.0, false), any_value(3.0), -3.0f64..3.0), 1..3)
            .prop_map(InputSpec::Tones),
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

/// The spec table naming one criterion of the registry.
fn named_criterion(name: &str) -> Spec {
    let mut t = Spec::new();
    t.insert("criterion".into(), name.into());
    t
}

/// A first-moment criterion as a registry spec table; weighted BCLS gets weights that are
/// occasionally invalid (negative, or non-finite, which JSON holds as null).
fn criterion() -> impl Strategy<Value = Spec> {
    prop_oneof![
        Just(named_criterion("ls")),
        Just(named_criterion("bcls")),
        (1usize..40, values(40, 3.0), any::<bool>()).prop_map(|(n, w, plain)| {
            let weights: Vec<f64> = if plain {
                w[..n]
                    .iter()
                    .map(|x| if x.is_finite() { x.abs() } else { 1.0 })
                    .collect()
            } else {
                w[..n]
                    .iter()
                    .map(|x| if x.is_finite() { x.abs() } else { *x })
                    .collect()
            };
            let mut t = named_criterion("weighted-bcls");
            t.insert("weights".into(), serde_json::json!(weights));
            t
        }),
        Just(named_criterion("bj")),
    ]
}

/// A frequency set, in units of `1/T` (converted for the case's `T`), occasionally invalid.
#[derive(Debug, Clone)]
enum FreqSpec {
    Dft,
    Band(f64, f64),
    List(Vec<f64>),
}

fn frequencies() -> impl Strategy<Value = FreqSpec> {
    prop_oneof![
        3 => Just(FreqSpec::Dft),
        1 => (prop_oneof![6 => 0.0f64..0.5, 1 => awkward()], prop_oneof![6 => 0.0f64..0.5, 1 => awkward()])
            .prop_map(|(min, width)| FreqSpec::Band(min, width)),
        1 => (0usize..12, values(12, 1.0))
            .prop_map(|(n, v)| FreqSpec::List(v[..n].iter().map(|x| if x.is_finite() { x.abs() } else { *x }).collect())),
    ]
}

impl FreqSpec {
    fn resolve(&self, interval: f64) -> Frequencies {
        match self {
            FreqSpec::Dft => Frequencies::Dft,
            FreqSpec::Band(min, width) => Frequencies::Band {
                min: min / interval,
                max: (min + width) / interval,
            },
            FreqSpec::List(v) => Frequencies::List(v.iter().map(|f| f / interval).collect()),
        }
    }
}

#[derive(Debug, Clone)]
struct SolverSpec {
    kind: u8,
    max_iters: u64,
    tol: f64,
    scaling: bool,
    starts: usize,
    radius: f64,
}

fn solver() -> impl Strategy<Value = SolverSpec> {
    (
        0u8..3,
        0u64..25,
        prop_oneof![4 => Just(1e-10), 1 => any_value(1.0)],
        any::<bool>(),
        0usize..3,
        prop_oneof![4 => 0.0f64..1.0, 1 => any_value(1.0)],
    )
        .prop_map(
            |(kind, max_iters, tol, scaling, starts, radius)| SolverSpec {
                kind,
                max_iters,
                tol,
                scaling,
                starts,
                radius,
            },
        )
}

#[derive(Debug, Clone)]
struct Case {
    n: usize,
    interval: f64,
    start: f64,
    data: Vec<f64>,
    model: ModelSpec,
    input: InputSpec,
    jitter: JitterSpec,
    /// 0 OE, 1 JOE, 2 BJ, 3 JBJ; then what is estimated (when not the structure's default), the
    /// noise filter, a known noise level.
    structure: u8,
    estimated: Option<(bool, bool, bool)>,
    arma: (Vec<f64>, Vec<f64>),
    noise_std: Option<f64>,
    criterion: Spec,
    frequencies: FreqSpec,
    hann: bool,
    solver: SolverSpec,
    covariance: bool,
}

fn case() -> impl Strategy<Value = Case> {
    let grid = (1usize..65, log_value(-2.0, 1.0, false), -20.0f64..20.0);
    let data = values(64, 1.0);
    let noise = (
        prop::collection::vec(-0.9f64..0.9, 0..2),
        prop::collection::vec(-0.9f64..0.9, 0..2),
    );
    (
        (grid, data, model(), input(), jitter()),
        (
            0u8..4,
            prop::option::weighted(0.25, (any::<bool>(), any::<bool>(), any::<bool>())),
            noise,
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
                ((n, interval, start), data, model, input, jitter),
                (
                    structure,
                    estimated,
                    arma,
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
                model,
                input,
                jitter,
                structure,
                estimated,
                arma,
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
    let mut v = ERRORS.lock().unwrap();
    match v.iter_mut().find(|(k, _)| *k == key) {
        Some((_, n)) => *n += 1,
        None => v.push((key, 1)),
    }
}

fn build_jitter(spec: &JitterSpec) -> Result<AnyJitter, JitterError> {
    let mut table = Spec::new();
    table.insert("family".into(), spec.family.clone().into());
    for (key, v) in &spec.values {
        table.insert(key.clone(), v.clone());
    }
    if let Some(c) = spec.offset {
        table.insert("offset".into(), c.into());
    }
    JitterRegistry::builtin().build(&table)
}

fn build_input(spec: &InputSpec) -> Option<Input> {
    match spec {
        InputSpec::Steps {
            start,
            widths,
            levels,
        } => {
            let mut edges = vec![*start];
            for w in widths {
                edges.push(edges[edges.len() - 1] + w);
            }
            PiecewiseConstant::new(edges, levels[..widths.len()].to_vec())
                .ok()
                .map(Input::from)
        }
        InputSpec::Tones(tones) => Multisine::new(
            tones
                .iter()
                .map(|&(frequency, amplitude, phase)| Tone {
                    frequency,
                    amplitude,
                    phase,
                })
                .collect(),
        )
        .ok()
        .map(Input::from),
    }
}

fn build_criterion(spec: &Spec) -> Option<AnyCriterion> {
    CriterionRegistry::builtin()
        .build(spec)
        .map_err(|e| note_error(&e))
        .ok()
}

fn build_solver(spec: &SolverSpec) -> AnySolver {
    let lm = LevenbergMarquardt::new(LmOptions {
        max_iters: spec.max_iters,
        xtol: spec.tol,
        ftol: spec.tol,
        gtol: spec.tol,
        scaling: if spec.scaling {
            Scaling::Marquardt
        } else {
            Scaling::Identity
        },
        ..LmOptions::default()
    });
    match spec.kind {
        0 => AnySolver::new(lm),
        1 => AnySolver::new(MultiStart::new(
            AnySolver::new(lm),
            spec.starts,
            spec.radius,
            7,
        )),
        _ => AnySolver::new(NelderMead {
            max_iters: 20 * spec.max_iters,
            ..NelderMead::default()
        }),
    }
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

/// Estimates with `structure`, then (for an LTI signal) initializes and estimates again.
fn run_structure<M, N>(
    case: &Case,
    structure: ModelStructure<LtiResponse<M>, AnyJitter, N>,
    record: &Record,
    criterion: &dyn Criterion,
) -> Result<(), TestCaseError>
where
    M: InitialModel,
    N: NoiseModel,
{
    let solver = build_solver(&case.solver);
    let result = if case.hann {
        let options = EstimateOptions {
            frequencies: case.frequencies.resolve(case.interval),
            window: HannWindow,
            solver,
            covariance: case.covariance,
        };
        estimate(&structure, record, criterion, &options)
    } else {
        let options = EstimateOptions {
            frequencies: case.frequencies.resolve(case.interval),
            window: DirichletWindow,
            solver,
            covariance: case.covariance,
        };
        estimate(&structure, record, criterion, &options)
    };
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
    // The default robust path: initializer, then multi-start LM (small budgets).
    match initialize(&structure, record, &InitOptions::default()) {
        Ok(start) => {
            bump(&TALLY.init_ok);
            let options = EstimateOptions {
                frequencies: Frequencies::Dft,
                window: DirichletWindow,
                solver: MultiStart::new(
                    LevenbergMarquardt::default().with_max_iters(15),
                    2,
                    0.5,
                    1,
                ),
                covariance: false,
            };
            match estimate(&start, record, &Bcls, &options) {
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

fn run_model<M: InitialModel>(
    case: &Case,
    model: M,
    input: Input,
    jitter: AnyJitter,
    record: &Record,
    criterion: &dyn Criterion,
) -> Result<(), TestCaseError> {
    let signal = LtiResponse::new(model, input);
    let with_std = |x: Result<_, EstimateError>| match x {
        Ok(x) => Some(x),
        Err(e) => {
            note_error(&e);
            None
        }
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
            let Some(x) = with_std(st.clone().with_noise_std(sd)) else {
                bump(&TALLY.rejected_setup);
                return Ok(());
            };
            st = x;
        }
        run_structure(case, st, record, criterion)
    } else {
        let noise = match ArmaNoise::new(case.arma.0.clone(), case.arma.1.clone()) {
            Ok(x) => x,
            Err(e) => {
                note_error(&e);
                bump(&TALLY.rejected_setup);
                return Ok(());
            }
        };
        let mut st = if case.structure == 2 {
            ModelStructure::bj(signal, jitter, noise)
        } else {
            ModelStructure::jbj(signal, jitter, noise)
        };
        if let Some((s, j, n)) = case.estimated {
            st = st.with_estimated(s, j, n);
        }
        run_structure(case, st, record, criterion)
    }
}

/// The case being run and when it started, for the watchdog.
static CURRENT: Mutex<Option<(Instant, String)>> = Mutex::new(None);

fn run_case(case: &Case) -> Result<(), TestCaseError> {
    *CURRENT.lock().unwrap() = Some((Instant::now(), format!("{case:?}")));
    let out = run_case_inner(case);
    *CURRENT.lock().unwrap() = None;
    out
}

fn run_case_inner(case: &Case) -> Result<(), TestCaseError> {
    bump(&TALLY.cases);
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
    let Some(input) = build_input(&case.input) else {
        bump(&TALLY.rejected_setup);
        return Ok(());
    };
    let jitter = match build_jitter(&case.jitter) {
        Ok(j) => j,
        Err(e) => return reject(&e),
    };
    let Some(any_criterion) = build_criterion(&case.criterion) else {
        bump(&TALLY.rejected_setup);
        return Ok(());
    };
    let Some(criterion) = any_criterion.as_first_moment() else {
        bump(&TALLY.rejected_setup);
        return Ok(());
    };
    match &case.model {
        ModelSpec::Zpk(k, z, p) => {
            match Zpk::new(
                *k,
                z.iter().map(RootSpec::root).collect(),
                p.iter().map(RootSpec::root).collect(),
            ) {
                Ok(m) => run_model(case, m, input, jitter, &record, criterion),
                Err(e) => reject(&e),
            }
        }
        ModelSpec::Tf(num, den) => match TransferFunction::new(num, den) {
            Ok(m) => run_model(case, m, input, jitter, &record, criterion),
            Err(e) => reject(&e),
        },
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
    result.unwrap();
    // Every case ran at least once (shrinking only adds cases on failure).
    assert!(get(&TALLY.cases) >= cases as usize);
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
    let lm = estimate(&structure, &record, &Ls, &EstimateOptions::default());
    assert!(matches!(lm, Err(EstimateError::Solver(_))), "{lm:?}");
    let options = EstimateOptions {
        frequencies: Frequencies::Dft,
        window: DirichletWindow,
        solver: NelderMead::default(),
        covariance: false,
    };
    // A typed error is right; so would be a report with a finite cost.
    if let Ok(e) = estimate(&structure, &record, &Ls, &options) {
        assert!(e.cost.is_finite(), "Ok with cost {}", e.cost);
    }
}
