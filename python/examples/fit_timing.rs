//! The Table 2 fit timed from Rust, for the Python package's overhead figure
//! (`docs/performance.md`, "Python"): the same calls `Experiment.fit` makes, without Python.
//!
//! `cargo run -p jitterid-python --example fit_timing [--release] -- [repeats]`

use jitterid_study::experiment::{self, Purpose};
use jitterid_study::fit::fit_values;
use jitterid_study::fit::signal_of;
use jitterid_study::montecarlo::DEFAULT_SEED;
use jitterid_study::simulate::simulate_data;
use std::path::Path;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let repeats: usize = std::env::args().nth(1).map_or(Ok(200), |s| s.parse())?;
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/experiments/table2.toml");
    let exp = experiment::read(&path, Purpose::Estimate(None))?;
    let data = simulate_data(&exp, DEFAULT_SEED, 0)?;
    let mut times = Vec::with_capacity(repeats);
    for _ in 0..repeats {
        let t0 = Instant::now();
        let signal = signal_of(&exp, &data.inputs)?;
        let fit = fit_values(
            &exp,
            signal,
            data.y.clone(),
            "y",
            &jitterid_study::Watch::none(),
        )?;
        times.push(t0.elapsed().as_secs_f64());
        assert!(fit.converged, "the Table 2 fit converges");
    }
    times.sort_by(f64::total_cmp);
    println!(
        "Table 2 fit from Rust: median {:.3} ms, min {:.3} ms over {repeats} fits",
        1e3 * times[repeats / 2],
        1e3 * times[0]
    );
    Ok(())
}
