//! The registry of solvers by name, built from spec tables.

use super::{
    AnySolver, Bfgs, Brent, BrentOrBfgs, GaussNewtonLineSearch, LevenbergMarquardt, LmOptions,
    MultiStart, NelderMead, SolverError,
};
use jitterid_registry::keys::{count, number, real, whole};
use jitterid_registry::{Builtin, Entry, ParamSpec, Registry, RegistryError, SpecTable};

/// The key of a spec table that names the solver.
pub const SOLVER_KEY: &str = "solver";

/// Keys that wrap any solver in a [`MultiStart`]: `starts`, `radius`, `seed`.
fn multistart_keys() -> [ParamSpec; 3] {
    [
        whole(
            "starts",
            "perturbed starts in addition to the given one (0: a single run)",
            ">= 0",
            Some(0.0),
        ),
        real(
            "radius",
            "relative radius of the perturbed starts",
            "",
            ">= 0, finite",
            Some(0.5),
        ),
        whole("seed", "seed of the perturbed starts", ">= 0", Some(0.0)),
    ]
}

/// A registered solver.
pub type SolverEntry = Entry<AnySolver>;

/// Solvers by name: `"lm"`, `"gauss-newton"`, `"nelder-mead"` for the first-moment criteria
/// (Nelder–Mead also for likelihoods), `"bfgs"`, `"brent"` and `"brent-or-bfgs"` for the
/// likelihood criteria. Every solver also takes the multi-start keys `starts`, `radius` and
/// `seed` ([`Registry::common_keys`]): `starts > 0` wraps it in a [`MultiStart`].
pub type SolverRegistry = Registry<AnySolver>;

const MAX_ITERS: &str = "max_iters";
const MAX_SECONDS: &str = "max_seconds";

fn max_iters(default: f64) -> ParamSpec {
    whole(MAX_ITERS, "iteration limit", ">= 1", Some(default))
}

/// The wall-clock budget of a solver that checks one between iterations.
fn max_seconds(default: f64) -> ParamSpec {
    real(
        MAX_SECONDS,
        "wall-clock budget, checked between iterations",
        "s",
        ">= 0, finite",
        Some(default),
    )
}

fn positive(key: &'static str, meaning: &'static str, default: f64) -> ParamSpec {
    real(key, meaning, "", "> 0, finite", Some(default))
}

/// Wraps a built solver in a [`MultiStart`] when the table asks for perturbed starts.
fn multistart(table: &SpecTable, solver: AnySolver) -> Result<AnySolver, RegistryError> {
    let [starts, radius, seed] = multistart_keys();
    let starts = count(table, &starts, solver.name())?;
    if starts == 0 {
        return Ok(solver);
    }
    let radius = number(table, &radius, solver.name())?;
    if !(radius.is_finite() && radius >= 0.0) {
        return Err(RegistryError::bad(
            "radius",
            format!("must be finite and >= 0, got {radius}"),
        ));
    }
    // A seed above 2^53 has no exact `f64`: read it as the whole number it is.
    let seed = match table.get(&seed.key).and_then(serde_json::Value::as_u64) {
        Some(s) => s,
        None => count(table, &seed, solver.name())?,
    };
    Ok(AnySolver::new(MultiStart::new(
        solver,
        starts as usize,
        radius,
        seed,
    )))
}

/// Reads the entry's keys in order as numbers; an iteration limit must be at least 1, a
/// wall-clock budget finite and at least 0 (no time: stop after the start), other reals
/// finite and positive.
fn read(table: &SpecTable, entry: &str, specs: &[ParamSpec]) -> Result<Vec<f64>, RegistryError> {
    specs
        .iter()
        .map(|s| {
            let v = number(table, s, entry)?;
            if s.key == MAX_ITERS && !(v >= 1.0) {
                return Err(RegistryError::bad(MAX_ITERS, "must be at least 1"));
            }
            if s.key == MAX_SECONDS {
                return if v.is_finite() && v >= 0.0 {
                    Ok(v)
                } else {
                    Err(RegistryError::bad(
                        MAX_SECONDS,
                        format!("must be finite and >= 0, got {v}"),
                    ))
                };
            }
            let positive = v.is_finite() && v > 0.0;
            if !s.integer && !positive {
                return Err(RegistryError::bad(
                    &s.key,
                    format!("must be finite and > 0, got {v}"),
                ));
            }
            Ok(v)
        })
        .collect()
}

impl Builtin for AnySolver {
    /// The solvers of this crate.
    ///
    /// ```
    /// use jitterid_optim::SolverRegistry;
    ///
    /// let registry = SolverRegistry::builtin();
    /// let table = serde_json::json!({ "solver": "lm", "max_iters": 50, "starts": 4, "seed": 7 });
    /// let solver = registry.build(table.as_object().unwrap())?;
    /// assert_eq!(solver.name(), "multistart");
    /// let bad = serde_json::json!({ "solver": "lm", "max_iter": 50 });
    /// let err = registry.build(bad.as_object().unwrap()).unwrap_err();
    /// assert_eq!(err.key(), Some("max_iter"));
    /// # Ok::<(), jitterid_registry::RegistryError>(())
    /// ```
    fn builtin() -> Registry<Self> {
        let mut r = Registry::empty(
            SOLVER_KEY,
            "solver",
            multistart_keys().to_vec(),
            Some(multistart),
        );
        let lm = LmOptions::default();
        let lm_keys = vec![
            max_iters(lm.max_iters as f64),
            positive("xtol", "relative step tolerance", lm.xtol),
            positive("ftol", "relative cost-reduction tolerance", lm.ftol),
            positive("gtol", "gradient tolerance", lm.gtol),
            max_seconds(lm.max_seconds),
        ];
        let keys = lm_keys.clone();
        r.insert(Entry::new(
            "lm",
            "Levenberg–Marquardt; needs a least-squares criterion",
            lm_keys,
            move |t| {
                let v = read(t, "lm", &keys)?;
                let lm = LevenbergMarquardt::default()
                    .with_max_iters(v[0] as u64)
                    .with_xtol(v[1])
                    .with_ftol(v[2])
                    .with_gtol(v[3])
                    .with_max_seconds(v[4]);
                lm.options().validate().map_err(|e| match e {
                    SolverError::InvalidOption { option, .. } => RegistryError::bad(option, &e),
                    other => RegistryError::bad(SOLVER_KEY, other),
                })?;
                Ok(AnySolver::new(lm))
            },
        ));
        let gn = GaussNewtonLineSearch::default();
        let gn_keys = vec![
            max_iters(gn.max_iters as f64),
            positive("tol", "tolerance on the relative change of ‖r‖", gn.tol),
        ];
        let keys = gn_keys.clone();
        r.insert(Entry::new(
            "gauss-newton",
            "Gauss–Newton with an Armijo line search; needs a least-squares criterion",
            gn_keys,
            move |t| {
                let v = read(t, "gauss-newton", &keys)?;
                Ok(AnySolver::new(GaussNewtonLineSearch {
                    max_iters: v[0] as u64,
                    tol: v[1],
                    ..GaussNewtonLineSearch::default()
                }))
            },
        ));
        let nm = NelderMead::default();
        let nm_keys = vec![
            max_iters(nm.max_iters as f64),
            positive(
                "initial_step",
                "relative size of the initial simplex",
                nm.initial_step,
            ),
        ];
        let keys = nm_keys.clone();
        r.insert(Entry::new(
            "nelder-mead",
            "Nelder–Mead simplex on the cost; any criterion, no gradient",
            nm_keys,
            move |t| {
                let v = read(t, "nelder-mead", &keys)?;
                Ok(AnySolver::new(NelderMead {
                    max_iters: v[0] as u64,
                    initial_step: v[1],
                    ..NelderMead::default()
                }))
            },
        ));
        let bfgs = Bfgs::default();
        let bfgs_keys = vec![
            max_iters(bfgs.max_iters as f64),
            max_seconds(bfgs.max_seconds),
        ];
        let keys = bfgs_keys.clone();
        r.insert(Entry::new(
            "bfgs",
            "dense BFGS with Armijo backtracking; any criterion with a gradient",
            bfgs_keys,
            move |t| {
                let v = read(t, "bfgs", &keys)?;
                Ok(AnySolver::new(Bfgs {
                    max_iters: v[0] as u64,
                    max_seconds: v[1],
                    ..Bfgs::default()
                }))
            },
        ));
        let brent = Brent::default();
        let brent_keys = vec![
            max_iters(brent.max_iters as f64),
            positive(
                "tolerance",
                "absolute tolerance on the parameter",
                brent.tolerance,
            ),
        ];
        let keys = brent_keys.clone();
        r.insert(Entry::new(
            "brent",
            "Brent's method; criteria of exactly one free parameter",
            brent_keys,
            move |t| {
                let v = read(t, "brent", &keys)?;
                Ok(AnySolver::new(Brent {
                    max_iters: v[0] as u64,
                    tolerance: v[1],
                    ..Brent::default()
                }))
            },
        ));
        r.insert(Entry::new(
            "brent-or-bfgs",
            "Brent's method for one parameter, BFGS otherwise (the likelihoods' default)",
            Vec::new(),
            |_| Ok(AnySolver::new(BrentOrBfgs::default())),
        ));
        r
    }
}
