//! `cargo xtask memory`: the peak resident memory of the command line's `simulate`, `fit` and
//! `montecarlo` on one long record, each command a process of the release binary measured by
//! `/usr/bin/time` (GNU time's `%M`, the largest resident set of the process).
//!
//! The figures it prints are a report, never a test: the memory of a process depends on the
//! allocator and the machine, so no threshold is checked here.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The experiment every measurement runs: Table 2's, with `samples` samples and a mean dwell
/// of 40 s.
const EXPERIMENT: &str = "examples/experiments/table2.toml";

/// The release binary: `$CARGO_TARGET_DIR/release/jitterid`, or `target/release/jitterid`.
fn binary() -> PathBuf {
    let target =
        std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| PathBuf::from("target"), PathBuf::from);
    target.join("release").join("jitterid")
}

/// Runs `args` on the binary under `/usr/bin/time`: its peak resident memory in KiB and its
/// wall time in seconds.
fn measured(bin: &Path, args: &[&str]) -> Result<(u64, f64), String> {
    let out = Command::new("/usr/bin/time")
        .arg("-f")
        .arg("%M KB %e s")
        .arg(bin)
        .args(args)
        .output()
        .map_err(|e| {
            format!("/usr/bin/time: {e} (GNU time is needed to measure a process's peak memory)")
        })?;
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        return Err(format!("jitterid {}: {}", args.join(" "), stderr.trim()));
    }
    let last = stderr.lines().last().unwrap_or("");
    let mut words = last.split_whitespace();
    let kib = words.next().and_then(|w| w.parse().ok());
    let secs = words.nth(1).and_then(|w| w.parse().ok());
    match (kib, secs) {
        (Some(k), Some(s)) => Ok((k, s)),
        _ => Err(format!("cannot read the measurement from `{last}`")),
    }
}

/// Simulates one record of `samples` samples of the Table 2 experiment, then fits it from its
/// CSV (as written, with columns `k,t,y,u`, and with `y` alone) and runs a Monte Carlo study of
/// two realisations on two threads, printing each command's peak memory as a Markdown table.
pub fn run(samples: u64, dir: &Path) -> Result<(), String> {
    let bin = binary();
    if !bin.is_file() {
        return Err(format!(
            "{}: not built; run `cargo build --release -p jitterid-cli` first",
            bin.display()
        ));
    }
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let template = std::fs::read_to_string(EXPERIMENT).map_err(|e| format!("{EXPERIMENT}: {e}"))?;
    let exp_text: String = template
        .lines()
        .map(|l| {
            if l.trim_start().starts_with("samples") {
                format!("samples = {samples}")
            } else if l.trim_start().starts_with("mean_dwell") {
                // The input's switches are bounded (10⁶ over the span it covers): a dwell of
                // 40 s keeps a record of 10⁷ s within it.
                "mean_dwell = 40.0".to_string()
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    let exp = dir.join("memory.toml");
    std::fs::write(&exp, exp_text + "\n").map_err(|e| format!("{}: {e}", exp.display()))?;
    let data = dir.join("memory.csv");
    let y_only = dir.join("memory-y.csv");
    let s = |p: &Path| p.display().to_string();
    let (exp_s, data_s, y_s) = (s(&exp), s(&data), s(&y_only));

    let mut rows: Vec<(String, (u64, f64))> = Vec::new();
    let simulate = ["simulate", &exp_s, "--out", &data_s];
    rows.push((simulate.join(" "), measured(&bin, &simulate)?));
    write_y_only(&data, &y_only)?;
    // The input realisation beside the `y`-only file, as `fit` looks for it.
    let side = |p: &Path| {
        p.with_file_name(format!(
            "{}.input.csv",
            p.file_stem().unwrap_or_default().to_string_lossy()
        ))
    };
    std::fs::copy(side(&data), side(&y_only))
        .map_err(|e| format!("{}: {e}", side(&data).display()))?;
    for file in [&data_s, &y_s] {
        let fit = ["fit", &exp_s, "--data", file.as_str()];
        rows.push((fit.join(" "), measured(&bin, &fit)?));
    }
    let mc = [
        "montecarlo",
        &exp_s,
        "--runs",
        "2",
        "--threads",
        "2",
        "--no-timing",
    ];
    rows.push((mc.join(" "), measured(&bin, &mc)?));

    println!("N = {samples} (Table 2 experiment), {}:\n", bin.display());
    println!("| command | peak RSS (MiB) | wall (s) |");
    println!("|---|---|---|");
    for (command, (kib, secs)) in rows {
        println!(
            "| `jitterid {command}` | {:.0} | {secs:.1} |",
            kib as f64 / 1024.0
        );
    }
    Ok(())
}

/// The column `y` of a data file, alone, in a new file.
fn write_y_only(data: &Path, out: &Path) -> Result<(), String> {
    use std::io::{BufRead, BufWriter, Write};
    let err = |p: &Path, e: std::io::Error| format!("{}: {e}", p.display());
    let input = std::io::BufReader::new(std::fs::File::open(data).map_err(|e| err(data, e))?);
    let mut output = BufWriter::new(std::fs::File::create(out).map_err(|e| err(out, e))?);
    let mut lines = input.lines();
    let header = lines
        .next()
        .ok_or_else(|| format!("{}: empty", data.display()))?;
    let header = header.map_err(|e| err(data, e))?;
    let column = header
        .split(',')
        .position(|c| c.trim() == "y")
        .ok_or_else(|| format!("{}: no column y", data.display()))?;
    writeln!(output, "y").map_err(|e| err(out, e))?;
    for line in lines {
        let line = line.map_err(|e| err(data, e))?;
        let cell = line.split(',').nth(column).unwrap_or("");
        writeln!(output, "{cell}").map_err(|e| err(out, e))?;
    }
    output.flush().map_err(|e| err(out, e))
}
