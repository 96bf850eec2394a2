//! `cargo xtask scale`: BCLS cost against the record length, and the Monte Carlo speedup.

use crate::paper;
use jitterid::estimate::montecarlo::realization_rng;
use jitterid::estimate::solver::LeastSquares;
use jitterid::estimate::{
    fit, Bcls, FitOptions, FitProblem, FrequencyData, ModelStructure, Record,
};
use jitterid::prelude::*;
use jitterid::window::{DirichletWindow, FrequencySet};
use std::time::Instant;

fn peak_rss_mib() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        })
        .map_or(f64::NAN, |kib| kib / 1024.0)
}

/// Resets the peak resident set size (`VmHWM`) to the current one, so that each record length
/// reports its own peak (Linux ≥ 4.0; elsewhere the peak stays cumulative).
fn reset_peak_rss() {
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Times one evaluation of the residuals and normal equations (`JᵀJ`, `Jᵀr`, what each
/// Levenberg–Marquardt step needs) and one fit (with and without covariance) of the Table 2
/// system at each record length, with the peak memory of that record length.
pub fn run(sizes: &[usize]) -> Result<(), String> {
    println!("| N | steps | residual + normal equations (ms) | fit (ms) | fit + covariance (ms) | iterations | peak RSS (MiB) |");
    println!("|---|---|---|---|---|---|---|");
    let jitter = UniformSum::new(2, 0.5 / 3f64.sqrt()).map_err(|e| e.to_string())?;
    let mut base = None;
    let mut estimates = Vec::new();
    for &n in sizes {
        reset_peak_rss();
        let mut rng = realization_rng(7, n as u64);
        let u = paper::input_of(&mut rng, 8.0, n);
        let steps = u.steps().len();
        let g = paper::eq17(0.2, 0.5, -0.25, 0.3).map_err(|e| e.to_string())?;
        let grid = paper::grid_of(n);
        let y = simulate(
            &LtiResponse::new(g, u.clone()),
            &jitter,
            &grid,
            paper::NOISE_STD,
            &mut rng,
        )
        .map_err(|e| e.to_string())?
        .y;
        let record = Record::new(grid, y).map_err(|e| e.to_string())?;
        let start = paper::eq17(0.21, 0.45, -0.27, 0.33).map_err(|e| e.to_string())?;
        let structure = ModelStructure::oe(LtiResponse::new(start, u), jitter);
        let data = FrequencyData::new(record.clone(), DirichletWindow, FrequencySet::dft(&grid))
            .map_err(|e| e.to_string())?;
        let reps = match n {
            0..=20_000 => 7,
            20_001..=1_000_000 => 3,
            _ => 1,
        };
        let theta = structure.params();
        let eval = median(
            (0..reps)
                .map(|_| {
                    // A fresh problem each time: a problem memoises its last point, and a
                    // repeated evaluation there would time a copy.
                    let problem = FitProblem::new(&structure, &Bcls, &data);
                    let t = Instant::now();
                    let r = problem.residuals(&theta).expect("residuals");
                    let ne = problem
                        .normal_equations(&theta, &r)
                        .expect("normal equations");
                    std::hint::black_box((r, ne));
                    t.elapsed().as_secs_f64() * 1e3
                })
                .collect(),
        );
        drop(data);
        let no_cov = FitOptions::default().with_covariance(false);
        let mut iters = 0;
        let fit = median(
            (0..reps)
                .map(|_| {
                    let t = Instant::now();
                    let e = fit(&structure, &record, &Bcls, &no_cov).expect("fit runs");
                    iters = e.iterations;
                    t.elapsed().as_secs_f64() * 1e3
                })
                .collect(),
        );
        let t = Instant::now();
        let e = jitterid::estimate::fit(&structure, &record, &Bcls, &FitOptions::default())
            .map_err(|e| e.to_string())?;
        let full = t.elapsed().as_secs_f64() * 1e3;
        if !e.converged {
            return Err(format!(
                "N = {n}: the fit did not converge ({})",
                e.termination
            ));
        }
        println!(
            "| {n} | {steps} | {eval:.2} | {fit:.2} | {full:.2} | {iters} | {:.0} |",
            peak_rss_mib()
        );
        // Shortest round-trip form of every estimate, so that two runs can be compared for
        // bit-identical results.
        estimates.push(format!("N = {n}: {:?}", e.params));
        if let Some(b) = base {
            if n == 20_000 {
                println!("\nfit time ratio N = 20 000 / N = 200: {:.1}\n", fit / b);
            }
        } else {
            base = Some(fit);
        }
    }
    println!("\nBCLS estimates (with covariance):");
    for line in estimates {
        println!("{line}");
    }
    Ok(())
}

/// The Table 2 study on 1 and on 2 threads: wall times and whether the estimates are identical.
pub fn speedup() -> Result<(), String> {
    let jitter = UniformSum::new(2, 0.5 / 3f64.sqrt()).map_err(|e| e.to_string())?;
    let study = || {
        jitterid::estimate::montecarlo::run(20_051_205, 0..128, |_, rng| {
            let u = paper::input(rng, 8.0);
            let g = paper::eq17(0.2, 0.5, -0.25, 0.3).expect("valid");
            let grid = paper::grid();
            let y = simulate(
                &LtiResponse::new(g, u.clone()),
                &jitter,
                &grid,
                paper::NOISE_STD,
                rng,
            )
            .expect("valid")
            .y;
            let s = paper::perturb(&[0.2, 0.5, -0.25, 0.3], 0.2, rng);
            let start = paper::eq17(s[0], s[1], s[2], s[3]).expect("stable start");
            let structure = ModelStructure::oe(LtiResponse::new(start, u), jitter);
            fit(
                &structure,
                &Record::new(grid, y).expect("finite"),
                &Bcls,
                &FitOptions::default(),
            )
            .map(|e| e.params)
            .ok()
        })
    };
    // The study takes a tenth of a second: alternate the two pools and keep the fastest of
    // REPEATS runs of each, so that a moment of load elsewhere does not decide the ratio.
    const REPEATS: usize = 7;
    let pools = [1, 2].map(|threads| rayon::ThreadPoolBuilder::new().num_threads(threads).build());
    let mut times = [f64::INFINITY; 2];
    let mut results: [Vec<_>; 2] = [Vec::new(), Vec::new()];
    for _ in 0..REPEATS {
        for (i, pool) in pools.iter().enumerate() {
            let pool = pool.as_ref().map_err(|e| e.to_string())?;
            let t = Instant::now();
            let r = pool.install(study);
            times[i] = times[i].min(t.elapsed().as_secs_f64());
            if results[i].is_empty() {
                results[i] = r;
            } else if results[i] != r {
                return Err(format!(
                    "{} thread(s): estimates differ between runs",
                    i + 1
                ));
            }
        }
    }
    println!("Table 2 study, 128 BCLS fits with covariance (fastest of {REPEATS} runs each):");
    println!(
        "1 thread: {:.3} s, 2 threads: {:.3} s, speedup {:.2}",
        times[0],
        times[1],
        times[0] / times[1]
    );
    println!(
        "estimates bit-for-bit identical on 1 and 2 threads: {}",
        results[0] == results[1]
    );
    Ok(())
}
