//! Reproducible Monte Carlo studies: per-realisation seeds derived from a master seed, parallel
//! execution with rayon whose results do not depend on the thread count, and streaming
//! summaries (Welford) so a study need not keep every estimate.

use rand::rngs::StdRng;
use rand::SeedableRng;
use rayon::prelude::*;

/// The seed of realisation `r` of a study with master seed `master` (SplitMix64 of the pair):
/// independent of how realisations are scheduled, so results are identical for any thread
/// count and for any split of the runs into shards.
pub fn realization_seed(master: u64, r: u64) -> u64 {
    let mut z = master
        .wrapping_add(0x9E37_79B9_7F4A_7C15)
        .wrapping_add(r.wrapping_mul(0xD1B5_4A32_D192_ED03));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The generator of realisation `r`.
pub fn realization_rng(master: u64, r: u64) -> StdRng {
    StdRng::seed_from_u64(realization_seed(master, r))
}

/// Runs `f(r, rng)` for every realisation `r` in `runs` in parallel on the current rayon pool
/// and returns the results in the order of `runs`.
pub fn run<T, F>(master: u64, runs: std::ops::Range<u64>, f: F) -> Vec<T>
where
    T: Send,
    F: Fn(u64, &mut StdRng) -> T + Sync + Send,
{
    runs.into_par_iter()
        .map(|r| f(r, &mut realization_rng(master, r)))
        .collect()
}

/// Streaming mean and variance (Welford), mergeable across shards (Chan et al.).
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Summary {
    /// Number of values.
    pub count: u64,
    /// Their mean.
    pub mean: f64,
    /// Sum of squared deviations from the mean.
    pub m2: f64,
}

impl Summary {
    /// Adds one value.
    pub fn push(&mut self, x: f64) {
        self.count += 1;
        let d = x - self.mean;
        self.mean += d / self.count as f64;
        self.m2 += d * (x - self.mean);
    }

    /// Merges another summary (the result equals pushing its values).
    pub fn merge(&mut self, other: &Summary) {
        if other.count == 0 {
            return;
        }
        let n = self.count + other.count;
        let d = other.mean - self.mean;
        self.mean += d * other.count as f64 / n as f64;
        self.m2 += other.m2 + d * d * self.count as f64 * other.count as f64 / n as f64;
        self.count = n;
    }

    /// Sample standard deviation (`n − 1` in the denominator).
    pub fn std(&self) -> f64 {
        if self.count < 2 {
            f64::NAN
        } else {
            (self.m2 / (self.count - 1) as f64).sqrt()
        }
    }

    /// Standard error of the mean, `std/√n`.
    pub fn se(&self) -> f64 {
        self.std() / (self.count as f64).sqrt()
    }
}

impl FromIterator<f64> for Summary {
    fn from_iter<I: IntoIterator<Item = f64>>(iter: I) -> Self {
        let mut s = Summary::default();
        iter.into_iter().for_each(|x| s.push(x));
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn welford_matches_two_pass_and_merges() {
        let xs: Vec<f64> = (0..1000)
            .map(|i| ((i * 37) % 101) as f64 * 0.1 + 1e6)
            .collect();
        let s: Summary = xs.iter().copied().collect();
        let mean = xs.iter().sum::<f64>() / xs.len() as f64;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (xs.len() - 1) as f64;
        assert!((s.mean - mean).abs() < 1e-9);
        assert!((s.std() - var.sqrt()).abs() < 1e-9);
        let mut a: Summary = xs[..300].iter().copied().collect();
        let b: Summary = xs[300..].iter().copied().collect();
        a.merge(&b);
        assert!((a.mean - s.mean).abs() < 1e-9 && (a.std() - s.std()).abs() < 1e-9);
    }

    #[test]
    fn results_do_not_depend_on_thread_count() {
        use rand::Rng;
        let f = |r: u64, rng: &mut StdRng| (r, rng.random::<f64>());
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(|| run(42, 0..64, f));
        let two = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap()
            .install(|| run(42, 0..64, f));
        assert_eq!(one, two);
        // A shard reproduces its slice of the whole study.
        assert_eq!(run(42, 16..32, f), one[16..32].to_vec());
    }
}
