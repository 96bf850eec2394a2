//! The subcommands, one module each: each reads its inputs through the study layer
//! ([`jitterid_study`]), which decides everything about the model, and prints or writes what it
//! returns.

mod design;
mod fit;
mod merge;
mod montecarlo;
mod select;
mod simulate;
mod validate;

pub use design::{design, DesignOptions};
pub use fit::{fit, FitRequest};
pub use merge::merge;
pub use montecarlo::{emit, montecarlo, MonteCarloOptions};
pub use select::{select, SelectOptions};
pub use simulate::{simulate, SimulateOptions};
pub use validate::{validate, ValidateOptions};

use jitterid_study::StudyError;

/// The width of a report table's parameter column: the longest name, at least as wide as its
/// heading `parameter`.
pub(crate) fn name_width<'a>(names: impl Iterator<Item = &'a str>) -> usize {
    names.map(str::len).max().unwrap_or(9).max(9)
}

/// A number as the reports print it: six decimals, or four significant digits in scientific
/// notation outside `[1e-3, 1e5)`, and `–` for a value that is not finite.
pub(crate) fn fmt_num(x: f64) -> String {
    if !x.is_finite() {
        return "–".into();
    }
    let a = x.abs();
    if a != 0.0 && !(1e-3..1e5).contains(&a) {
        format!("{x:.4e}")
    } else {
        format!("{x:.6}")
    }
}

/// Converts a [`StudyError`] from a command into the reported line.
pub fn report(e: &StudyError) -> String {
    format!("error: {e}")
}
