//! Project tasks: `cargo xtask demo`, `cargo xtask reproduce <case>`.
#![allow(clippy::type_complexity)]

mod demo;
mod memory;
mod outputs;
mod paper;
mod reproduce;
mod reproduce_design;
mod reproduce_initial;
mod reproduce_ml;
mod reproduce_models;
mod reproduce_select;
mod reproduce_starts;
mod reproduce_validate;
mod scale;

use std::process::ExitCode;

const USAGE: &str = "usage:
  cargo xtask demo
      simulate the paper's Table 2 setup and print μ_Y by both routes
  cargo xtask scale [N ...]
      BCLS evaluation and fit time against the record length (default 200 … 10^6)
  cargo xtask speedup
      the Table 2 study on 1 and 2 threads: wall time and identical results
  cargo xtask memory [N] [--out DIR]
      peak memory of the release binary's simulate, fit and montecarlo at N samples (default 10^7)
  cargo xtask reproduce <case> [--runs R] [--seed S] [--shard i/n] [--json FILE] [--out DIR]
      cases: table1, table2, ls-bias, alias, table1-ml, sine, starts, initial, models, select, validate, design, design-bcls, design-multisine, all";

/// Options of `reproduce`.
#[derive(Debug, Clone)]
pub struct Options {
    pub runs: Option<u64>,
    pub seed: u64,
    pub shard: (u64, u64),
    pub json: Option<String>,
    pub out: String,
}

fn parse(args: &[String]) -> Result<(String, Options), String> {
    let mut case = None;
    let mut o = Options {
        runs: None,
        seed: 20_051_205,
        shard: (0, 1),
        json: None,
        out: "results".into(),
    };
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut value = |name: &str| {
            it.next()
                .cloned()
                .ok_or_else(|| format!("{name} needs a value"))
        };
        match a.as_str() {
            "--runs" => {
                o.runs = Some(
                    value("--runs")?
                        .parse()
                        .map_err(|_| "--runs takes a whole number".to_string())?,
                )
            }
            "--seed" => {
                o.seed = value("--seed")?
                    .parse()
                    .map_err(|_| "--seed takes a whole number".to_string())?
            }
            "--shard" => {
                let v = value("--shard")?;
                let (i, n) = v
                    .split_once('/')
                    .and_then(|(i, n)| Some((i.parse().ok()?, n.parse().ok()?)))
                    .filter(|&(i, n): &(u64, u64)| n > 0 && i < n)
                    .ok_or_else(|| format!("--shard takes i/n with 0 <= i < n, got {v}"))?;
                o.shard = (i, n);
            }
            "--json" => o.json = Some(value("--json")?),
            "--out" => o.out = value("--out")?,
            s if s.starts_with("--") => return Err(format!("unknown option {s}")),
            s => {
                if case.replace(s.to_string()).is_some() {
                    return Err(format!("unexpected argument {s}"));
                }
            }
        }
    }
    Ok((case.ok_or("which case?")?, o))
}

/// `memory [N] [--out DIR]`: the record length (default 10⁷) and where its files go.
fn memory_args(args: &[String]) -> Result<(u64, std::path::PathBuf), String> {
    let mut n = 10_000_000;
    let mut dir = std::path::PathBuf::from("target/memory");
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--out" => dir = it.next().ok_or("--out needs a directory")?.into(),
            s => {
                n = s
                    .parse()
                    .map_err(|_| format!("memory takes a record length, found `{s}`"))?
            }
        }
    }
    Ok((n, dir))
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("demo") => demo::run(),
        Some("scale") => {
            let sizes: Result<Vec<usize>, _> =
                args[1..].iter().map(|a| a.parse::<usize>()).collect();
            match sizes {
                Ok(s) if !s.is_empty() => scale::run(&s),
                Ok(_) => scale::run(&[200, 2_000, 20_000, 200_000, 1_000_000]),
                Err(_) => {
                    Err("scale takes record lengths, e.g. `cargo xtask scale 200 2000`".into())
                }
            }
        }
        Some("speedup") => scale::speedup(),
        Some("memory") => memory_args(&args[1..]).and_then(|(n, dir)| memory::run(n, &dir)),
        Some("reproduce") => parse(&args[1..]).and_then(|(case, o)| reproduce::run(&case, &o)),
        _ => Err(USAGE.to_string()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
