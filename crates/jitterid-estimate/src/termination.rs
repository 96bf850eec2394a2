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
    /// Converged on the boundary of the stable models: the search reached the imaginary axis
    /// (a pole at the origin, or an undamped pair) and stopped there, so the system
    /// parameters `params` (indices into the free parameters, named `names`) are held at 0 and
    /// the others fitted with them held. Set by [`fit`](crate::fit) for a model that refuses
    /// unstable poles; the parameters held get no standard error, as at any bound.
    AtStabilityBoundary {
        /// Indices of the parameters held at 0.
        params: Vec<usize>,
        /// Their names.
        names: Vec<String>,
    },
}

impl FitTermination {
    /// Whether this reason is a convergence test of the solver (small step, cost change or
    /// gradient), in the interior or at a bound ([`Termination::is_convergence`]); the
    /// estimator's verdicts are not.
    pub fn is_convergence(&self) -> bool {
        match self {
            FitTermination::Solver(t) => t.is_convergence(),
            FitTermination::ResidualNotFlat => false,
            FitTermination::AtStabilityBoundary { .. } => true,
        }
    }

    /// The solver's reason, if this is one.
    pub fn solver(&self) -> Option<&Termination> {
        match self {
            FitTermination::Solver(t) => Some(t),
            FitTermination::ResidualNotFlat | FitTermination::AtStabilityBoundary { .. } => None,
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
            FitTermination::AtStabilityBoundary { names, .. } => write!(
                f,
                "converged at the stability boundary with {} held at 0 (a pole on the imaginary \
                 axis: the model refuses poles right of it; `unstable = true` lets the search \
                 cross, `integrators = n` holds known integrators at the origin)",
                names.join(", ")
            ),
        }
    }
}

/// The variant name and index `ResidualNotFlat` had in the solver's `Termination`.
const NOT_FLAT: &str = "ResidualNotFlat";
const NOT_FLAT_INDEX: u32 = 8;
/// The variant name and index of [`FitTermination::AtStabilityBoundary`] in the same enum.
const AT_AXIS: &str = "AtStabilityBoundary";
const AT_AXIS_INDEX: u32 = 9;

impl Serialize for FitTermination {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match self {
            FitTermination::Solver(t) => t.serialize(serializer),
            FitTermination::ResidualNotFlat => {
                serializer.serialize_unit_variant("Termination", NOT_FLAT_INDEX, NOT_FLAT)
            }
            FitTermination::AtStabilityBoundary { params, names } => {
                use serde::ser::SerializeStructVariant;
                let mut v = serializer.serialize_struct_variant(
                    "Termination",
                    AT_AXIS_INDEX,
                    AT_AXIS,
                    2,
                )?;
                v.serialize_field("params", params)?;
                v.serialize_field("names", names)?;
                v.end()
            }
        }
    }
}

impl<'de> Deserialize<'de> for FitTermination {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        enum Verdict {
            ResidualNotFlat,
            AtStabilityBoundary {
                params: Vec<usize>,
                names: Vec<String>,
            },
        }
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Repr {
            Verdict(Verdict),
            Solver(Termination),
        }
        Ok(match Repr::deserialize(deserializer)? {
            Repr::Verdict(Verdict::ResidualNotFlat) => FitTermination::ResidualNotFlat,
            Repr::Verdict(Verdict::AtStabilityBoundary { params, names }) => {
                FitTermination::AtStabilityBoundary { params, names }
            }
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
            FitTermination::AtStabilityBoundary {
                params: vec![2],
                names: vec!["a0".into()],
            },
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
