//! The documented limits on the size of the work a caller can ask for, in one place.
//!
//! Each limit is checked where the size enters the library: a grid's constructor checks the
//! number of samples, an input's the switches or tones, a rational model's the poles, the
//! jitter registry the terms of a sum, the likelihood its quadrature nodes, the study layer a
//! file's size and a study's realisations. A size beyond its limit is refused with a
//! [`LimitExceeded`] that names the limit, the size asked for and the bound, before anything
//! is allocated; the command line and Python print the same message.
//!
//! The bounds are set where the work stops being useful or stops being bounded: ten million
//! samples is about 80 MB per copy of a record; 30 poles is where repeated or clustered poles
//! lose every digit of their realisation in double precision; a sum of more than two terms
//! with a density costs a nested quadrature per density value (a third one multiplies a fit's
//! time by about a hundred).
//!
//! ```
//! use jitterid_numeric::limits::{check, Limit};
//! assert!(check(Limit::Poles, 30).is_ok());
//! let e = check(Limit::Poles, 31).unwrap_err();
//! assert_eq!(e.to_string(), "31 poles exceed the limit of 30 poles of a rational model");
//! ```

use std::fmt;
use thiserror::Error;

/// Largest number of samples of a record, a simulation or a batch of draws.
pub const MAX_SAMPLES: usize = 10_000_000;
/// Largest number of switches (edges) of a piecewise-constant input: as many as samples, so
/// that the zero-order hold of the longest record is an input.
pub const MAX_SWITCHES: usize = MAX_SAMPLES;
/// Largest number of tones of a multisine input.
pub const MAX_TONES: usize = 1_000;
/// Largest number of poles (the order) of a rational model; its zeros are fewer.
pub const MAX_POLES: usize = 30;
/// Largest magnitude of a tone's phase in radians: beyond it, `2πft + φ` has lost the digits
/// that make the tone a tone (at `1e308` it is one constant).
pub const MAX_PHASE: f64 = 1e6;
/// Largest number of terms of a sum of jitters (nested sums counted by their terms).
pub const MAX_SUM_TERMS: usize = 8;
/// Largest number of terms with a density (not only atoms) in a sum of jitters.
pub const MAX_DENSITY_TERMS: usize = 2;
/// Largest number of components of a mixture of jitters.
pub const MAX_MIXTURE_COMPONENTS: usize = 16;
/// Largest number of quadrature nodes per sample of the exact likelihood.
pub const MAX_QUADRATURE_NODES: usize = 1 << 18;
/// Largest size in bytes of a file the library reads (experiments, CSV, shards, fits).
pub const MAX_FILE_BYTES: u64 = 1 << 30;
/// Largest number of realisations of a Monte Carlo study.
pub const MAX_RUNS: u64 = 10_000_000;

/// One of the documented limits.
#[non_exhaustive]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Limit {
    /// [`MAX_SAMPLES`].
    Samples,
    /// [`MAX_SWITCHES`].
    Switches,
    /// [`MAX_TONES`].
    Tones,
    /// [`MAX_POLES`].
    Poles,
    /// [`MAX_SUM_TERMS`].
    SumTerms,
    /// [`MAX_DENSITY_TERMS`].
    DensityTerms,
    /// [`MAX_MIXTURE_COMPONENTS`].
    MixtureComponents,
    /// [`MAX_QUADRATURE_NODES`].
    QuadratureNodes,
    /// [`MAX_FILE_BYTES`].
    FileBytes,
    /// [`MAX_RUNS`].
    Runs,
}

impl Limit {
    /// Every limit, in the order the documentation lists them.
    pub const ALL: [Limit; 10] = [
        Limit::Samples,
        Limit::Switches,
        Limit::Tones,
        Limit::Poles,
        Limit::SumTerms,
        Limit::DensityTerms,
        Limit::MixtureComponents,
        Limit::QuadratureNodes,
        Limit::FileBytes,
        Limit::Runs,
    ];

    /// The bound: the largest size allowed.
    pub const fn max(self) -> u64 {
        match self {
            Limit::Samples => MAX_SAMPLES as u64,
            Limit::Switches => MAX_SWITCHES as u64,
            Limit::Tones => MAX_TONES as u64,
            Limit::Poles => MAX_POLES as u64,
            Limit::SumTerms => MAX_SUM_TERMS as u64,
            Limit::DensityTerms => MAX_DENSITY_TERMS as u64,
            Limit::MixtureComponents => MAX_MIXTURE_COMPONENTS as u64,
            Limit::QuadratureNodes => MAX_QUADRATURE_NODES as u64,
            Limit::FileBytes => MAX_FILE_BYTES,
            Limit::Runs => MAX_RUNS,
        }
    }

    /// What is counted, in the plural ("samples", "poles").
    pub const fn unit(self) -> &'static str {
        match self {
            Limit::Samples => "samples",
            Limit::Switches => "switches",
            Limit::Tones => "tones",
            Limit::Poles => "poles",
            Limit::SumTerms => "terms",
            Limit::DensityTerms => "terms with a density",
            Limit::MixtureComponents => "components",
            Limit::QuadratureNodes => "quadrature nodes",
            Limit::FileBytes => "bytes",
            Limit::Runs => "realisations",
        }
    }

    /// Of what the limit bounds the size.
    pub const fn of_what(self) -> &'static str {
        match self {
            Limit::Samples => "a record, a simulation or a batch of draws",
            Limit::Switches => "a piecewise-constant input",
            Limit::Tones => "a multisine",
            Limit::Poles => "a rational model",
            Limit::SumTerms | Limit::DensityTerms => "a sum of jitters",
            Limit::MixtureComponents => "a mixture of jitters",
            Limit::QuadratureNodes => "the exact likelihood's rule of a sample",
            Limit::FileBytes => "a file the library reads",
            Limit::Runs => "a Monte Carlo study",
        }
    }
}

impl fmt::Display for Limit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {} of {}", self.max(), self.unit(), self.of_what())
    }
}

/// A size beyond its documented [`Limit`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
#[error("{found} {} exceed the limit of {limit}", .limit.unit())]
pub struct LimitExceeded {
    /// The limit.
    pub limit: Limit,
    /// The size asked for.
    pub found: u64,
}

/// `found` checked against `limit`.
///
/// # Errors
///
/// [`LimitExceeded`] when `found > limit.max()`.
pub fn check(limit: Limit, found: usize) -> Result<(), LimitExceeded> {
    check_u64(limit, u64::try_from(found).unwrap_or(u64::MAX))
}

/// [`check`] of a size held as `u64` (file sizes, realisations).
///
/// # Errors
///
/// [`LimitExceeded`] when `found > limit.max()`.
pub fn check_u64(limit: Limit, found: u64) -> Result<(), LimitExceeded> {
    if found > limit.max() {
        Err(LimitExceeded { limit, found })
    } else {
        Ok(())
    }
}

/// A vector with room for `len` elements, `len` checked against `limit` first and the
/// allocation made fallibly, so that a size the machine cannot hold is an error and not an
/// abort.
///
/// # Errors
///
/// [`LimitExceeded`] when `len` is beyond `limit`, or when the memory cannot be had (then
/// `found` is `len` and `limit` the one asked about: the limit could not be honoured on this
/// machine).
pub fn vec_with_capacity<T>(limit: Limit, len: usize) -> Result<Vec<T>, LimitExceeded> {
    check(limit, len)?;
    let mut v = Vec::new();
    v.try_reserve_exact(len).map_err(|_| LimitExceeded {
        limit,
        found: len as u64,
    })?;
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bound_itself_passes_and_one_more_fails() {
        for l in Limit::ALL {
            let max = usize::try_from(l.max()).unwrap();
            assert!(check(l, max).is_ok(), "{l:?}");
            let e = check(l, max + 1).unwrap_err();
            assert_eq!(e.found, l.max() + 1);
            assert!(e.to_string().contains(&l.max().to_string()), "{e}");
        }
    }

    #[test]
    fn a_vector_beyond_the_limit_is_refused_before_allocating() {
        let e = vec_with_capacity::<f64>(Limit::Samples, 1 << 40).unwrap_err();
        assert_eq!(e.limit, Limit::Samples);
        let v = vec_with_capacity::<f64>(Limit::Samples, 1000).unwrap();
        assert!(v.capacity() >= 1000);
    }

    #[test]
    fn messages_name_the_size_the_unit_and_the_bound() {
        let e = check(Limit::SumTerms, 42).unwrap_err();
        assert_eq!(
            e.to_string(),
            "42 terms exceed the limit of 8 terms of a sum of jitters"
        );
    }
}
