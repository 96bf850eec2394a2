//! The run-time registries a study is read and run with.
//!
//! Every name an experiment file gives (a jitter family, a system kind, a noise model, a method,
//! a solver) is looked up in one [`Registries`] value, which the experiment keeps: what was
//! accepted at the door is built from the same registries when the study runs. The command
//! line and Python use [`Registries::builtin`]; a program that adds its own jitter family,
//! signal kind, noise model, criterion or solver registers one entry in a copy of the built-in
//! registries and reads its experiments with it
//! ([`experiment::parse_with`](crate::experiment::parse_with)), after which the new entry works
//! in experiment files, fits, Monte Carlo studies and selection like a built-in one.

use jitterid::estimate::solver::SolverRegistry;
use jitterid::estimate::{CriterionRegistry, NoiseRegistry};
use jitterid::jitter::registry::JitterRegistry;
use jitterid::signal::registry::SignalRegistry;
use std::fmt;
use std::sync::{Arc, OnceLock};

/// The registries of every run-time choice of a study.
#[derive(Clone)]
pub struct Registries {
    /// Jitter families (`[jitter] family`, `[select] families`).
    pub jitter: JitterRegistry,
    /// Signal kinds (`[system] kind`).
    pub signal: SignalRegistry,
    /// Noise models (`[noise] model`).
    pub noise: NoiseRegistry,
    /// Criteria (`[estimate] method`).
    pub criteria: CriterionRegistry,
    /// Solvers (`[estimate] solver`).
    pub solvers: SolverRegistry,
}

impl Registries {
    /// The library's built-in registries, shared.
    pub fn builtin() -> Arc<Registries> {
        static BUILTIN: OnceLock<Arc<Registries>> = OnceLock::new();
        Arc::clone(BUILTIN.get_or_init(|| {
            Arc::new(Registries {
                jitter: JitterRegistry::builtin().clone(),
                signal: SignalRegistry::builtin().clone(),
                noise: NoiseRegistry::builtin(),
                criteria: CriterionRegistry::builtin(),
                solvers: SolverRegistry::builtin(),
            })
        }))
    }
}

impl fmt::Debug for Registries {
    /// The names each registry holds.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names = |n: Vec<&str>| n.join(", ");
        f.debug_struct("Registries")
            .field("jitter", &self.jitter)
            .field("signal", &self.signal)
            .field(
                "noise",
                &names(self.noise.entries().iter().map(|e| e.name).collect()),
            )
            .field(
                "criteria",
                &names(self.criteria.entries().iter().map(|e| e.name).collect()),
            )
            .field(
                "solvers",
                &names(self.solvers.entries().iter().map(|e| e.name).collect()),
            )
            .finish()
    }
}
