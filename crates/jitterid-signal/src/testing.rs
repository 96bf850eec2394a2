//! Contract checks that every [`Signal`] must pass, and the fixtures the test crates share.
//!
//! Run [`check_contract`] in a test of any new signal:
//!
//! ```
//! use jitterid_jitter::UniformSum;
//! use jitterid_signal::testing::{binary, check_contract, eq17};
//! use jitterid_signal::{LtiResponse, SampleGrid};
//!
//! let g = eq17(0.2, 0.5, -0.25, 0.3).unwrap();
//! let signal = LtiResponse::new(g, binary(1, 8.0, -5.0, 45.0).unwrap());
//! let grid = SampleGrid::new(0.0, 1.0, 40).unwrap();
//! let jitter = UniformSum::new(2, 0.2887).unwrap();
//! check_contract(&signal, &jitter, &grid, 7).unwrap();
//! ```
//!
//! The reference for the jitter expectations is an adaptive Gauss–Legendre integration over the
//! jitter's own pieces and atoms that bisects wherever a rule and its two halves disagree. It
//! never asks the signal for its [`breakpoints`](Signal::breakpoints) or its
//! [`rate`](Signal::rate): it finds jumps and fast transients itself. Both the signal's own
//! `m_k` and the trait's provided quadrature route (through [`Plain`], which sees only
//! `breakpoints` and `rate`) are held against it, so a forgotten breakpoint or a rate that is
//! too low is caught even for a signal that overrides `expected_values` with a closed form.

use crate::{
    Jacobian, PiecewiseConstant, RandomBinary, Root, SampleGrid, Signal, SignalError, Zpk,
};
use jitterid_jitter::JitterModel;
use jitterid_numeric::clenshaw_curtis::cc17;
use jitterid_numeric::gauss::gl16;
use rand::rngs::StdRng;
use rand::SeedableRng;
use std::fmt::Write as _;

/// Relative finite-difference step for parameter derivatives, scaled by `max(|θ_j|, 1)`.
const FD_STEP: f64 = 1e-6;

/// Tolerance of an analytic derivative against central differences, relative to its natural
/// size `|∂x/∂θ| + max|x| / max(|θ|, 1)`. With step `δ = 1e-6 max(|θ|, 1)` the rounding error of
/// the difference is `≈ ε max|x| / δ ≈ 2e-10` of that size and the truncation error
/// `δ² |x'''| / 6` is far smaller for the smooth parameter dependence of signal models; `1e-6`
/// sits far above both and far below any error a wrong formula makes.
const FD_TOL: f64 = 1e-6;

/// Accepted difference between a signal's own `m_k` (or `E[s²]`) and the reference, relative
/// to the scale of `s` over the record. The reference integrates to about `1e-13` of that
/// scale; exact routes round at `1e-14`; `1e-9` leaves room for either and catches any
/// missing step, misplaced atom or wrong closed form (which are off by `1e-4` or more).
const EXPECT_TOL: f64 = 1e-9;

/// Accepted difference of the provided quadrature route (the jitter's rule at the signal's
/// breakpoints and rate) against the reference. A forgotten breakpoint costs `≈ 1e-3` of the
/// scale (a jump inside a 16-node panel), a rate ten times too low about as much; a correct
/// signal lands below `1e-11`.
const RULE_TOL: f64 = 1e-8;

/// Acceptance of the reference bisection, relative to the scale: a panel whose rule and two
/// halves agree to this is accepted.
const REFERENCE_TOL: f64 = 1e-14;

/// Deepest bisection of a jitter piece: `2^-60` of its width is below the resolution of `f64`.
const REFERENCE_DEPTH: u32 = 60;

/// Instants checked by Monte Carlo: the first ones of the grid.
pub const MC_INSTANTS: usize = 8;
/// Draws per instant of the Monte Carlo check.
pub const MC_DRAWS: usize = 4_000;
/// Width of the Monte Carlo acceptance band, in standard errors: a correct signal lands outside
/// with probability about `6e-7` per comparison (normal two-sided tail at 5).
pub const MC_SIGMAS: f64 = 5.0;

/// Instants (within the grid's span) where values and gradients are probed.
const PROBES: usize = 9;

/// Runs every check on `signal` sampled on `grid` under `jitter`, with the Monte Carlo part
/// seeded by `seed`, and reports every failure, one per line:
///
/// * parameters: names, values and count agree; names are distinct and non-empty;
///   `with_params(params())` rebuilds the signal (same parameters, same values); a parameter
///   vector of the wrong length is rejected with [`SignalError::WrongParamCount`]; a NaN
///   parameter is rejected;
/// * structure: breakpoints finite and increasing, rate finite and `≥ 0`, values finite;
/// * `value_gradient` against central differences through `with_params`;
/// * `expected_values` and `expected_squares` against the reference integration (see the
///   module docs), and the provided quadrature route (with the signal's `breakpoints` and
///   `rate`) against it too: this is the check that `breakpoints` and `rate` are sufficient;
/// * `expected_values_gradient` against central differences of `expected_values`;
/// * `expected_values` against the Monte Carlo mean of `s(t_k + τ)` over [`MC_DRAWS`] draws at
///   the first [`MC_INSTANTS`] instants, within [`MC_SIGMAS`] standard errors.
pub fn check_contract<S: Signal + Clone>(
    signal: &S,
    jitter: &dyn JitterModel,
    grid: &SampleGrid,
    seed: u64,
) -> Result<(), String> {
    let mut fails = Vec::new();
    let probes = probe_times(signal, grid);
    let scale = value_scale(signal, jitter, grid);
    check_params(signal, &probes, scale, &mut fails);
    check_structure(signal, &probes, &mut fails);
    if fails.is_empty() {
        check_value_gradient(signal, &probes, scale, &mut fails);
        check_expectations(signal, jitter, grid, scale, &mut fails);
        check_expectation_gradient(signal, jitter, grid, scale, &mut fails);
        check_monte_carlo(signal, jitter, grid, scale, seed, &mut fails);
    }
    if fails.is_empty() {
        return Ok(());
    }
    let mut msg = format!(
        "signal {} breaks {} contract check(s):",
        std::any::type_name::<S>(),
        fails.len()
    );
    for f in fails {
        let _ = write!(msg, "\n  - {f}");
    }
    Err(msg)
}

/// `E[h(τ)]` over `jitter` by adaptive Gauss–Legendre bisection on each of its pieces (plus its
/// atoms), independent of any breakpoint list: panels are halved until a 16-point rule and its
/// two halves agree within `tol` (absolute), down to `2^-60` of a piece.
pub fn reference_expectation(jitter: &dyn JitterModel, h: &dyn Fn(f64) -> f64, tol: f64) -> f64 {
    let g = |tau: f64| h(tau) * jitter.pdf(tau);
    let mut total = 0.0;
    for (a, b) in jitter.pieces() {
        if b > a {
            let whole = panel(&g, a, b).0;
            total += bisect(&g, a, b, whole, tol, REFERENCE_DEPTH);
        }
    }
    for atom in jitter.atoms() {
        total += atom.mass * h(atom.position);
    }
    total
}

/// Estimates of `∫_a^b g` by 16-point Gauss–Legendre (open) and 17-point Clenshaw–Curtis
/// (closed: it evaluates both ends).
fn panel(g: &dyn Fn(f64) -> f64, a: f64, b: f64) -> (f64, f64) {
    let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
    let rule = |(x, w): &(Vec<f64>, Vec<f64>)| {
        x.iter()
            .zip(w)
            .map(|(x, w)| w * g(mid + half * x))
            .sum::<f64>()
            * half
    };
    (rule(gl16()), rule(cc17()))
}

/// Halves `[a, b]` until the Gauss rule on the panel agrees with the sum over its halves and,
/// on the halves, with the Clenshaw–Curtis rule. Gauss nodes stay `≈ 0.01` of a panel away
/// from its ends, so a jump closer to a bisection point than that is invisible to Gauss rules
/// at every level (seen at `1e-9`); the closed rule sees the other side of it there.
fn bisect(g: &dyn Fn(f64) -> f64, a: f64, b: f64, whole: f64, tol: f64, depth: u32) -> f64 {
    let m = 0.5 * (a + b);
    let ((left, left_cc), (right, right_cc)) = (panel(g, a, m), panel(g, m, b));
    let halves = left + right;
    // A NaN difference also stops: it is reported by the comparison, not hidden by recursion.
    let agree = !((halves - whole).abs() > tol) && !((halves - left_cc - right_cc).abs() > tol);
    if depth == 0 || agree {
        halves
    } else {
        bisect(g, a, m, left, tol, depth - 1) + bisect(g, m, b, right, tol, depth - 1)
    }
}

/// A signal that forwards only the required methods, [`breakpoints`](Signal::breakpoints) and
/// [`rate`](Signal::rate), so that its jitter expectations are the trait's provided quadrature
/// route: the reference against which fast exact routes are tested.
#[derive(Debug, Clone, PartialEq)]
pub struct Plain<S>(pub S);

impl<S: Signal> Signal for Plain<S> {
    fn param_names(&self) -> Vec<String> {
        self.0.param_names()
    }
    fn params(&self) -> Vec<f64> {
        self.0.params()
    }
    fn with_params(&self, params: &[f64]) -> Result<Self, SignalError> {
        self.0.with_params(params).map(Plain)
    }
    fn value(&self, t: f64) -> f64 {
        self.0.value(t)
    }
    fn value_gradient(&self, t: f64, grad: &mut [f64]) {
        self.0.value_gradient(t, grad)
    }
    fn breakpoints(&self) -> Vec<f64> {
        self.0.breakpoints()
    }
    fn rate(&self) -> f64 {
        self.0.rate()
    }
}

/// The paper's eq. (17) system `k0 (s + z) / ((s − pr)² + pi²)`; Table 2's truth is
/// `eq17(0.2, 0.5, -0.25, 0.3)`.
pub fn eq17(k0: f64, z: f64, pr: f64, pi: f64) -> Result<Zpk, SignalError> {
    Zpk::new(
        k0,
        vec![Root::Real(-z)],
        vec![Root::Pair { re: pr, im: pi }],
    )
}

/// A random binary input between 0 and 1 with mean dwell `dwell` on `[start, end)`, drawn from
/// `StdRng::seed_from_u64(seed)` (the paper's input has `dwell = 8`).
pub fn binary(
    seed: u64,
    dwell: f64,
    start: f64,
    end: f64,
) -> Result<PiecewiseConstant, SignalError> {
    let mut rng = StdRng::seed_from_u64(seed);
    RandomBinary::new(dwell, 0.0, 1.0)?.generate(start, end, &mut rng)
}

/// Instants spread over the grid's span, moved off the breakpoints (where a value may jump and a
/// difference quotient in a parameter that moves it is meaningless).
fn probe_times<S: Signal>(signal: &S, grid: &SampleGrid) -> Vec<f64> {
    let span = grid.duration().max(grid.interval());
    let breaks = signal.breakpoints();
    (0..PROBES)
        .map(|i| {
            let t = grid.start() + span * (i as f64 + 0.37) / PROBES as f64;
            let near = breaks.iter().any(|b| (b - t).abs() < 1e-6 * span);
            if near {
                t + 1e-3 * span
            } else {
                t
            }
        })
        .collect()
}

/// `max |s|` over a fine scan of the record widened by the jitter's reach (at least `1e-300`):
/// the scale of every tolerance.
fn value_scale<S: Signal>(signal: &S, jitter: &dyn JitterModel, grid: &SampleGrid) -> f64 {
    let (lo, hi) = jitter.reach();
    let (a, b) = (
        grid.start() + lo.max(-1e3),
        grid.time(grid.len() - 1) + hi.min(1e3),
    );
    let n = 4096;
    (0..=n)
        .map(|i| signal.value(a + (b - a) * i as f64 / n as f64).abs())
        .filter(|v| v.is_finite())
        .fold(1e-300, f64::max)
}

fn check_params<S: Signal + Clone>(
    signal: &S,
    probes: &[f64],
    scale: f64,
    fails: &mut Vec<String>,
) {
    let names = signal.param_names();
    let params = signal.params();
    if names.len() != params.len() || signal.num_params() != params.len() {
        fails.push(format!(
            "{} names, {} parameters, num_params() = {}",
            names.len(),
            params.len(),
            signal.num_params()
        ));
        return;
    }
    for (i, n) in names.iter().enumerate() {
        if n.is_empty() || names[..i].contains(n) {
            fails.push(format!("parameter name {i} ({n:?}) is empty or repeated"));
        }
    }
    match signal.with_params(&params) {
        Ok(again) => {
            if again.params() != params {
                fails.push(format!(
                    "with_params(params()) has parameters {:?}, not {params:?}",
                    again.params()
                ));
            }
            for &t in probes {
                let (a, b) = (signal.value(t), again.value(t));
                if !((a - b).abs() <= 1e-12 * scale) {
                    fails.push(format!(
                        "with_params(params()) changes s({t}) from {a} to {b}"
                    ));
                    break;
                }
            }
        }
        Err(e) => fails.push(format!("with_params(params()) fails: {e}")),
    }
    let mut longer = params.clone();
    longer.push(0.0);
    let mut wrong = vec![longer];
    if !params.is_empty() {
        wrong.push(params[..params.len() - 1].to_vec());
    }
    for p in wrong {
        if !matches!(
            signal.with_params(&p),
            Err(SignalError::WrongParamCount { .. })
        ) {
            fails.push(format!(
                "with_params of {} values (takes {}) is not WrongParamCount",
                p.len(),
                params.len()
            ));
        }
    }
    for j in 0..params.len() {
        let mut p = params.clone();
        p[j] = f64::NAN;
        if signal.with_params(&p).is_ok() {
            fails.push(format!("a NaN parameter {} is accepted", names[j]));
        }
    }
}

fn check_structure<S: Signal>(signal: &S, probes: &[f64], fails: &mut Vec<String>) {
    let breaks = signal.breakpoints();
    if breaks.iter().any(|b| !b.is_finite()) || breaks.windows(2).any(|w| !(w[1] > w[0])) {
        fails.push("breakpoints are not finite and strictly increasing".to_string());
    }
    let rate = signal.rate();
    if !(rate.is_finite() && rate >= 0.0) {
        fails.push(format!("rate {rate} is not finite and >= 0"));
    }
    for &t in probes {
        if !signal.value(t).is_finite() {
            fails.push(format!("s({t}) = {} is not finite", signal.value(t)));
        }
    }
}

/// Central difference of `f` over parameter `j` through `with_params`; `None` where a shifted
/// parameter vector is rejected (at a constraint's edge).
fn central<S: Signal, T>(
    signal: &S,
    j: usize,
    f: impl Fn(&S) -> T,
    diff: impl Fn(T, T, f64) -> T,
) -> Option<T> {
    let p = signal.params();
    let h = FD_STEP * p[j].abs().max(1.0);
    let (mut up, mut dn) = (p.clone(), p);
    up[j] += h;
    dn[j] -= h;
    let (su, sd) = (signal.with_params(&up).ok()?, signal.with_params(&dn).ok()?);
    Some(diff(f(&su), f(&sd), 2.0 * h))
}

fn check_value_gradient<S: Signal>(
    signal: &S,
    probes: &[f64],
    scale: f64,
    fails: &mut Vec<String>,
) {
    let params = signal.params();
    let names = signal.param_names();
    let mut grad = vec![0.0; params.len()];
    for &t in probes {
        signal.value_gradient(t, &mut grad);
        for j in 0..params.len() {
            let Some(fd) = central(signal, j, |s| s.value(t), |a, b, h| (a - b) / h) else {
                continue;
            };
            let size = grad[j].abs() + scale / params[j].abs().max(1.0);
            if !((grad[j] - fd).abs() <= FD_TOL * size) {
                fails.push(format!(
                    "value_gradient: ∂s({t})/∂{} = {} but central differences give {fd}",
                    names[j], grad[j]
                ));
            }
        }
    }
}

fn check_expectations<S: Signal + Clone>(
    signal: &S,
    jitter: &dyn JitterModel,
    grid: &SampleGrid,
    scale: f64,
    fails: &mut Vec<String>,
) {
    let tol = REFERENCE_TOL * scale;
    let plain = Plain(signal.clone());
    let first: Vec<f64> = grid
        .times()
        .map(|t| reference_expectation(jitter, &|tau| signal.value(t + tau), tol))
        .collect();
    let second: Vec<f64> = grid
        .times()
        .map(|t| reference_expectation(jitter, &|tau| signal.value(t + tau).powi(2), tol * scale))
        .collect();
    let sufficient = "by the provided quadrature (are breakpoints() and rate() sufficient?)";
    let own = signal.expected_values(grid, jitter);
    compare("expected_values", &own, &first, EXPECT_TOL * scale, fails);
    let rule = plain.expected_values(grid, jitter);
    let what = format!("expected_values {sufficient}");
    compare(&what, &rule, &first, RULE_TOL * scale, fails);
    let own = signal.expected_squares(grid, jitter);
    let tol = EXPECT_TOL * scale * scale;
    compare("expected_squares", &own, &second, tol, fails);
    let rule = plain.expected_squares(grid, jitter);
    let what = format!("expected_squares {sufficient}");
    compare(&what, &rule, &second, RULE_TOL * scale * scale, fails);
}

fn compare(what: &str, got: &[f64], want: &[f64], tol: f64, fails: &mut Vec<String>) {
    if got.len() != want.len() {
        fails.push(format!(
            "{what}: {} values for {} instants",
            got.len(),
            want.len()
        ));
        return;
    }
    let worst = got
        .iter()
        .zip(want)
        .enumerate()
        .map(|(k, (g, w))| (k, (g - w).abs(), *g, *w))
        .max_by(|a, b| a.1.total_cmp(&b.1).then(std::cmp::Ordering::Greater));
    if let Some((k, d, g, w)) = worst {
        if !(d <= tol) {
            fails.push(format!(
                "{what}: at instant {k} {g} against the reference {w} (|diff| {d:e} > {tol:e})"
            ));
        }
    }
}

fn check_expectation_gradient<S: Signal>(
    signal: &S,
    jitter: &dyn JitterModel,
    grid: &SampleGrid,
    scale: f64,
    fails: &mut Vec<String>,
) {
    let params = signal.params();
    let names = signal.param_names();
    let cols: Jacobian = signal.expected_values_gradient(grid, jitter);
    if cols.len() != params.len() || cols.iter().any(|c| c.len() != grid.len()) {
        fails.push(format!(
            "expected_values_gradient has {} columns (of lengths {:?}) for {} parameters and {} instants",
            cols.len(),
            cols.iter().map(Vec::len).collect::<Vec<_>>(),
            params.len(),
            grid.len()
        ));
        return;
    }
    for (j, col) in cols.iter().enumerate() {
        let diff = |a: Vec<f64>, b: Vec<f64>, h: f64| -> Vec<f64> {
            a.iter().zip(&b).map(|(a, b)| (a - b) / h).collect()
        };
        let Some(fd) = central(signal, j, |s| s.expected_values(grid, jitter), diff) else {
            continue;
        };
        let size =
            col.iter().fold(0.0f64, |m, v| m.max(v.abs())) + scale / params[j].abs().max(1.0);
        compare(
            &format!("expected_values_gradient column {}", names[j]),
            col,
            &fd,
            FD_TOL * size,
            fails,
        );
    }
}

fn check_monte_carlo<S: Signal>(
    signal: &S,
    jitter: &dyn JitterModel,
    grid: &SampleGrid,
    scale: f64,
    seed: u64,
    fails: &mut Vec<String>,
) {
    let m = signal.expected_values(grid, jitter);
    let mut rng = StdRng::seed_from_u64(seed);
    for (k, t) in grid.times().enumerate().take(MC_INSTANTS) {
        let draws: Vec<f64> = (0..MC_DRAWS)
            .map(|_| signal.value(t + jitter.sample(&mut rng)))
            .collect();
        let n = draws.len() as f64;
        let mean = draws.iter().sum::<f64>() / n;
        let var = draws.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
        let se = (var / n).sqrt();
        let Some(&mk) = m.get(k) else {
            return;
        };
        if !((mean - mk).abs() <= MC_SIGMAS * se + 1e-12 * scale) {
            fails.push(format!(
                "Monte Carlo mean of s(t_{k} + τ) is {mean} ± {se:e} but expected_values gives {mk}"
            ));
        }
    }
}

/// A mass–spring–damper as a grey-box model written with expressions: force in, position out,
/// `ẋ = [[0, 1], [−k/m, −damp/m]] x + [0, 1/m] u`, `y = x₁`, parameters `m, damp, k` (in this
/// order) with `m` bounded to `[0, 10³]`: `1/(m s² + damp s + k)`.
pub fn mass_spring_damper() -> crate::greybox::ExprModel {
    use crate::greybox::{ExprModel, WrittenMatrices};
    let written = WrittenMatrices {
        a: vec![
            vec!["0".into(), "1".into()],
            vec!["-k/m".into(), "-damp/m".into()],
        ],
        b: vec![vec![0.0.into()], vec!["1/m".into()]],
        c: vec![vec![1.0.into(), 0.0.into()]],
        d: None,
    };
    let names = ["m", "damp", "k"].map(String::from);
    // The matrices above parse against these names: a failure is a bug of this function.
    ExprModel::new(&names, &[], &[("m".into(), (0.0, 1e3))], &written)
        .expect("the mass–spring–damper's expressions parse")
}
