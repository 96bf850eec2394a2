//! [`FitTermination`]: why an estimate stopped, the solver's reason or the estimator's verdict.

use crate::solver::Termination;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::fmt;

/// Why an estimate stopped: the solver's [`Termination`], or a verdict of the estimator on a
/// point where the solver met a convergence test ([`FitTermination::ResidualNotFlat`]).
///
/// Displays and serialises exactly as the solver's reasons did when the verdict was one of
/// them: a solver's reason as itself, the verdict as the string `"ResidualNotFlat"`.
#[non_exhaustive]
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum FitTermination {
    /// The solver's reason.
    Solver(Termination),
    /// The solver met a convergence test, but the residual spectrum is far from flat
    /// ([`residual_flatness`](crate::residual_flatness) above
    /// [`FLATNESS_LIMIT`](crate::FLATNESS_LIMIT)): a local minimum, or a model that does not
    /// describe the data. Set by [`fit`](crate::fit), not by the solvers.
    ResidualNotFlat,
}

impl FitTermination {
    /// Whether this reason is a convergence test of the solver (small step, cost change or
    /// gradient), in the interior or at a bound ([`Termination::is_convergence`]); the
    /// estimator's verdicts are not.
    pub fn is_convergence(&self) -> bool {
        match self {
            FitTermination::Solver(t) => t.is_convergence(),
            FitTermination::ResidualNotFlat => false,
        }
    }

    /// The solver's reason, if this is one.
    pub fn solver(&self) -> Option<&Termination> {
        match self {
            FitTermination::Solver(t) => Some(t),
            FitTermination::ResidualNotFlat => None,
        }
    }
}

impl From<Termination> for FitTermination {
    fn from(t: Termination) -> Self {
        FitTermination::Solver(t)
    }
}

impl PartialEq<Termination> for FitTermination {
    fn eq(&self, other: &Termination) -> bool {
        self.solver() == Some(other)
    }
}

impl fmt::Display for FitTermination {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FitTermination::Solver(t) => t.fmt(f),
            FitTermination::ResidualNotFlat => f.write_str(
                "converged, but the residual spectrum is not flat (a local minimum, or a model \
                 that does not describe the data)",
            ),
        }
    }
}

/// The variant name and index `ResidualNotFlat` had in the solver's `Termination`.
const NOT_FLAT: &str = "ResidualNotFlat";
const NOT_FLAT_INDEX: u32 = 8;

impl Serialize for FitTermination {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match self {
            FitTermination::Solver(t) => t.serialize(serializer),
            FitTermination::ResidualNotFlat => {
                serializer.serialize_unit_variant("Termination", NOT_FLAT_INDEX, NOT_FLAT)
            }
        }
    }
}

impl<'de> Deserialize<'de> for FitTermination {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        enum Verdict {
            ResidualNotFlat,
        }
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Repr {
            Verdict(Verdict),
            Solver(Termination),
        }
        Ok(match Repr::deserialize(deserializer)? {
            Repr::Verdict(Verdict::ResidualNotFlat) => FitTermination::ResidualNotFlat,
            Repr::Solver(t) => FitTermination::Solver(t),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn displays_and_serialises_as_before() {
        let flat = FitTermination::ResidualNotFlat;
        assert_eq!(
            flat.to_string(),
            "converged, but the residual spectrum is not flat (a local minimum, or a model that \
             does not describe the data)"
        );
        assert_eq!(serde_json::to_string(&flat).unwrap(), "\"ResidualNotFlat\"");
        for t in [
            FitTermination::ResidualNotFlat,
            Termination::SmallStep.into(),
            Termination::AtBound { params: vec![1] }.into(),
            Termination::Other("why".into()).into(),
        ] {
            let json = serde_json::to_string(&t).unwrap();
            if let Some(s) = t.solver() {
                assert_eq!(json, serde_json::to_string(s).unwrap());
                assert_eq!(t.to_string(), s.to_string());
            }
            assert_eq!(serde_json::from_str::<FitTermination>(&json).unwrap(), t);
        }
    }
}
