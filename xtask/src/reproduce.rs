//! `cargo xtask reproduce <case>`: the paper's experiments and the project's demonstrations.

use crate::outputs::{fmt_opt, runs_range, write_outputs};
use crate::paper::{self, NOISE_STD, RUNS};
use crate::Options;
use jitterid::estimate::montecarlo::{run as mc_run, Summary};
use jitterid::estimate::{
    fit, fit_profile, Bcls, Criterion, FitOptions, Ls, ModelStructure, Record,
};
use jitterid::jitter::JitterModel;
use jitterid::prelude::*;
use serde::Serialize;
use serde_json::json;
use std::fmt::Write as _;
use std::time::Instant;

/// One parameter's Monte Carlo summary.
#[derive(Debug, Clone, Serialize)]
pub(crate) struct ParamRow {
    pub name: String,
    #[serde(rename = "true")]
    pub truth: Option<f64>,
    pub mean: f64,
    pub std: f64,
    pub se: f64,
    pub asymptotic_std: Option<f64>,
}

pub(crate) fn row(
    name: &str,
    truth: Option<f64>,
    values: &Summary,
    asym: Option<&Summary>,
) -> ParamRow {
    ParamRow {
        name: name.to_string(),
        truth,
        mean: values.mean,
        std: values.std(),
        se: values.se(),
        asymptotic_std: asym.map(|a| a.mean),
    }
}

pub(crate) fn table(rows: &[ParamRow], paper: Option<&[(f64, f64)]>) -> String {
    let mut s = String::from(
        "| parameter | true | paper mean | paper std | mean | std | se of mean | asymptotic std | (mean − true)/se |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    for (i, r) in rows.iter().enumerate() {
        let (pm, ps) = paper
            .and_then(|p| p.get(i))
            .map_or(("–".into(), "–".into()), |(m, s)| {
                (format!("{m:.4}"), format!("{s:.4}"))
            });
        let z = r
            .truth
            .map_or("–".into(), |t| format!("{:+.2}", (r.mean - t) / r.se));
        let _ = writeln!(
            s,
            "| {} | {} | {pm} | {ps} | {:.4} | {:.4} | {:.4} | {} | {z} |",
            r.name,
            fmt_opt(r.truth),
            r.mean,
            r.std,
            r.se,
            fmt_opt(r.asymptotic_std)
        );
    }
    s
}

pub fn run(case: &str, o: &Options) -> Result<(), String> {
    match case {
        "table2" => table2(o),
        "table1" => table1(o),
        "ls-bias" => ls_bias(o),
        "alias" => alias(o),
        "table1-ml" => crate::reproduce_ml::table1_ml(o),
        "sine" => crate::reproduce_ml::sine(o),
        "starts" => crate::reproduce_starts::starts(o),
        "initial" => crate::reproduce_initial::initial(o),
        "models" => crate::reproduce_models::models(o),
        "select" => crate::reproduce_select::select_case(o),
        "validate" => crate::reproduce_validate::validate_case(o),
        "design" => crate::reproduce_design::design(o),
        "design-bcls" => crate::reproduce_design::design_bcls(o),
        "design-multisine" => crate::reproduce_design::design_multisine(o),
        "all" => {
            for c in [
                "table2",
                "ls-bias",
                "alias",
                "table1",
                "table1-ml",
                "sine",
                "starts",
                "initial",
                "models",
                "select",
                "validate",
                "design",
            ] {
                run(c, &Options { json: None, ..o.clone() })?;
            }
            Ok(())
        }
        other => Err(format!(
            "unknown case `{other}` (expected table1, table2, ls-bias, alias, table1-ml, sine, starts, initial, models, select, validate, design, design-bcls, design-multisine or all)"
        )),
    }
}

/// One OE fit of the eq. (17) system; returns (converged, [k0, z, pr, pi], std errors).
fn fit_eq17<C: Criterion>(
    truth: [f64; 4],
    jitter: &UniformSum,
    mean_dwell: f64,
    samples: usize,
    criteria: &[&C],
    rng: &mut rand::rngs::StdRng,
) -> Vec<(bool, Vec<f64>, Option<Vec<f64>>)> {
    let g = paper::eq17(truth[0], truth[1], truth[2], truth[3]).expect("valid truth");
    let u = paper::input_of(rng, mean_dwell, samples);
    let grid = paper::grid_of(samples);
    let signal = LtiResponse::new(g, u);
    let data = simulate(&signal, jitter, &grid, NOISE_STD, rng).expect("valid setup");
    let record = Record::new(grid, data.y).expect("finite data");
    let start = paper::perturb(&truth, 0.2, rng);
    let Ok(start_model) = paper::eq17(start[0], start[1], start[2], start[3]) else {
        return vec![(false, vec![f64::NAN; 4], None); criteria.len()];
    };
    let structure = ModelStructure::oe(
        LtiResponse::new(start_model, signal.input().clone()),
        *jitter,
    );
    criteria
        .iter()
        .map(
            |c| match fit(&structure, &record, *c, &FitOptions::default()) {
                // Parameters are [gain, zero, pole.re, pole.im]; the paper's z is −zero.
                Ok(e) => {
                    let p = vec![e.params[0], -e.params[1], e.params[2], e.params[3]];
                    (e.converged, p, e.std_errors)
                }
                Err(_) => (false, vec![f64::NAN; 4], None),
            },
        )
        .collect()
}

const EQ17_NAMES: [&str; 4] = ["k0", "z", "pr", "pi"];

fn summarize_eq17(
    results: &[(bool, Vec<f64>, Option<Vec<f64>>)],
    truth: [f64; 4],
) -> (usize, Vec<ParamRow>) {
    let converged = results.iter().filter(|r| r.0).count();
    let rows = (0..4)
        .map(|i| {
            let vals: Summary = results.iter().filter(|r| r.0).map(|r| r.1[i]).collect();
            let asym: Summary = results
                .iter()
                .filter(|r| r.0)
                .filter_map(|r| r.2.as_ref().map(|s| s[i]))
                .collect();
            row(EQ17_NAMES[i], Some(truth[i]), &vals, Some(&asym))
        })
        .collect();
    (converged, rows)
}

fn table2(o: &Options) -> Result<(), String> {
    let truth = [0.2, 0.5, -0.25, 0.3];
    let jitter = UniformSum::new(2, 0.5 / 3f64.sqrt()).map_err(|e| e.to_string())?;
    let runs = runs_range(o, RUNS);
    let n = runs.end - runs.start;
    let t = Instant::now();
    let results: Vec<_> = mc_run(o.seed, runs, |_, rng| {
        fit_eq17(truth, &jitter, 8.0, paper::N, &[&Bcls], rng).remove(0)
    });
    let secs = t.elapsed().as_secs_f64();
    let (converged, rows) = summarize_eq17(&results, truth);
    let paper = [
        (0.2000, 0.0025),
        (0.5012, 0.0135),
        (-0.2504, 0.0019),
        (0.3001, 0.0029),
    ];
    let mut md = format!(
        "## Table 2: BCLS, second-order OE model, known jitter (uniform-sum n = 2, a = 1/(2√3))\n\n{n} realisations, {converged} converged, {secs:.2} s wall. Start: truth × (1 + U(−0.2, 0.2)).\n\n"
    );
    md += &table(&rows, Some(&paper));
    md += "\nMonte Carlo std over mean asymptotic std: ";
    md += &rows
        .iter()
        .map(|r| {
            format!(
                "{} {:.3}",
                r.name,
                r.std / r.asymptotic_std.unwrap_or(f64::NAN)
            )
        })
        .collect::<Vec<_>>()
        .join(", ");
    md.push('\n');
    // Analysis of the difference with the paper's std (not a tuning of the setup): the same
    // study with the jitter whose characteristic function is the paper's printed eq. (15),
    // sinc(πfa/(n+1))^{n+1}, i.e. a uniform sum on [−a/2, a/2] with a quarter of the variance.
    let narrow = UniformSum::new(2, 0.25 / 3f64.sqrt()).map_err(|e| e.to_string())?;
    let alt: Vec<_> = mc_run(o.seed, runs_range(o, RUNS), |_, rng| {
        fit_eq17(truth, &narrow, 8.0, paper::N, &[&Bcls], rng).remove(0)
    });
    let (alt_conv, alt_rows) = summarize_eq17(&alt, truth);
    md += &format!(
        "\nFor comparison only (not the stated setup): the same records with the jitter of the paper's printed CF \
         (uniform sum on [−a/2, a/2], a quarter of the variance), {alt_conv} converged:\n\n"
    );
    md += &table(&alt_rows, Some(&paper));
    let value = json!({"case": "table2", "runs": n, "converged": converged, "seconds": secs, "parameters": rows,
        "printed_cf_comparison": {"converged": alt_conv, "parameters": alt_rows}});
    write_outputs("table2", o, &value, &md)
}

/// Samples per record of the LS-bias case.
const LS_BIAS_N: usize = 1000;

fn ls_bias(o: &Options) -> Result<(), String> {
    // A faster system than Table 2 (poles at −1 ± 2i rad/s, 0.32 Hz) driven by a faster input,
    // with uniform jitter of ±0.35 sample: γ(0.32 Hz) ≈ 0.92, so the data's mean is damped by
    // 8% near the resonance. Naive LS explains the damping with a lower gain and a shifted
    // zero and pole; BCLS models it. N = 1000 keeps the estimators' own nonlinear (O(1/N))
    // bias well below one standard error of the Monte Carlo mean.
    let truth = [2.0, 1.0, -1.0, 2.0];
    let jitter = UniformSum::new(0, 0.35).map_err(|e| e.to_string())?;
    let runs = runs_range(o, RUNS);
    let n = runs.end - runs.start;
    let t = Instant::now();
    let results: Vec<_> = mc_run(o.seed, runs, |_, rng| {
        let ls = fit_eq17(truth, &jitter, 2.0, LS_BIAS_N, &[&Ls], &mut rng.clone()).remove(0);
        let bcls = fit_eq17(truth, &jitter, 2.0, LS_BIAS_N, &[&Bcls], rng).remove(0);
        (ls, bcls)
    });
    let secs = t.elapsed().as_secs_f64();
    let ls: Vec<_> = results.iter().map(|r| r.0.clone()).collect();
    let bc: Vec<_> = results.iter().map(|r| r.1.clone()).collect();
    let (ls_conv, ls_rows) = summarize_eq17(&ls, truth);
    let (bc_conv, bc_rows) = summarize_eq17(&bc, truth);
    let gamma = jitter.cf(0.32).re;
    let mut md = format!(
        "## LS bias: G(s) = 2 (s + 1) / ((s + 1)² + 4), uniform jitter a = 0.35 s, T = 1 s, N = {LS_BIAS_N}, input mean dwell 2 s\n\n\
         {n} realisations on the same data for both estimators ({secs:.2} s wall). γ(0.32 Hz) = {gamma:.3}: \
         naive LS fits the undamped model to damped data.\n\n### Naive LS ({ls_conv} converged)\n\n"
    );
    md += &table(&ls_rows, None);
    md += &format!("\n### BCLS ({bc_conv} converged)\n\n");
    md += &table(&bc_rows, None);
    let value = json!({"case": "ls-bias", "runs": n, "seconds": secs,
        "ls": {"converged": ls_conv, "parameters": ls_rows},
        "bcls": {"converged": bc_conv, "parameters": bc_rows}});
    write_outputs("ls-bias", o, &value, &md)
}

fn alias(o: &Options) -> Result<(), String> {
    // The paper's section 3.4: one tone at f0 = 0.78 Hz or at its alias 1.78 Hz, T = 1, uniform
    // jitter. The samples' mean is A·γ(−f0)·sin(2π f0 kT + φ): at kT the two tones coincide,
    // so the first moment sees only the damped amplitude A·|γ(f0)|.
    let jitter = UniformSum::new(0, 0.25).map_err(|e| e.to_string())?;
    let grid = paper::grid();
    let mut md = String::from(
        "## Alias: a tone at 0.78 Hz and at 1.78 Hz, T = 1 s, uniform jitter a = 0.25 s\n\n| f0 (Hz) | γ(f0) | |γ(f0)| | first-moment amplitude A·|γ| (A = 1) |\n|---|---|---|---|\n",
    );
    let mut cases = Vec::new();
    for f0 in [0.78, 1.78] {
        let g = jitter.cf(f0).re;
        let _ = writeln!(md, "| {f0} | {g:+.4} | {:.4} | {:.4} |", g.abs(), g.abs());
        cases.push(json!({"f0": f0, "gamma": g}));
    }
    // Fit the first moment of the 1.78 Hz tone with a sinusoid model started at each alias.
    let truth = Sinusoid::new(1.0, 1.78, 0.3).map_err(|e| e.to_string())?;
    let m = truth.expected_values(&grid, &jitter);
    let record = Record::new(grid, m).map_err(|e| e.to_string())?;
    md += "\nBCLS fits of a sinusoid to the exact first moment of the 1.78 Hz tone (A = 1, φ = 0.3):\n\n| start f0 | Â | f̂0 | φ̂ | cost |\n|---|---|---|---|---|\n";
    let mut fits = Vec::new();
    for start in [0.78, 1.78] {
        let s = Sinusoid::new(0.9, start + 0.001, 0.25).map_err(|e| e.to_string())?;
        let structure = ModelStructure::oe(s, jitter);
        let e = fit(
            &structure,
            &record,
            &Bcls,
            &FitOptions::default().with_covariance(false),
        )
        .map_err(|e| e.to_string())?;
        let _ = writeln!(
            md,
            "| {start} | {:.4} | {:.4} | {:.4} | {:.2e} |",
            e.params[0], e.params[1], e.params[2], e.cost
        );
        fits.push(json!({"start": start, "params": e.params, "cost": e.cost}));
    }
    md += "\nBoth fits reach zero cost: on the grid `kT` the first moment of a tone at `f0 + 1/T` with \
           amplitude `A` equals that of a tone at `f0` with amplitude `A·γ(f0+1/T)/γ(f0)`. The first \
           moment identifies the aliased frequency and the damped amplitude, never which alias. The \
           jitter's second moment does tell them apart.\n";
    let _ = o.runs;
    write_outputs(
        "alias",
        o,
        &json!({"case": "alias", "damping": cases, "fits": fits}),
        &md,
    )
}

fn table1(o: &Options) -> Result<(), String> {
    let g = Zpk::new(1.0, vec![], vec![Root::Real(-2.0)]).map_err(|e| e.to_string())?;
    let s3 = 3f64.sqrt();
    // (name, truth, paper E[n, a, σ], paper Std[n, a, σ])
    type Case = (
        &'static str,
        Box<dyn JitterModel>,
        Option<(u32, f64)>,
        f64,
        [f64; 3],
        [f64; 3],
    );
    let cases: Vec<Case> = vec![
        (
            "uniform-sum n=0 a=1/2",
            Box::new(UniformSum::new(0, 0.5).unwrap()),
            Some((0, 0.5)),
            0.5 / s3,
            [0.2145, 0.4683, 0.2599],
            [0.7360, 0.0678, 0.0489],
        ),
        (
            "uniform-sum n=0 a=1/(2√3)",
            Box::new(UniformSum::new(0, 0.5 / s3).unwrap()),
            Some((0, 0.5 / s3)),
            0.5 / 3.0,
            [1.1818, 0.3759, 0.1682],
            [1.6815, 0.1186, 0.0649],
        ),
        (
            "uniform-sum n=2 a=1/2",
            Box::new(UniformSum::new(2, 0.5).unwrap()),
            Some((2, 0.5)),
            0.5 / 3.0,
            [1.1386, 0.3752, 0.1676],
            [1.6608, 0.1088, 0.0592],
        ),
        (
            "uniform-sum n=2 a=1/(2√3)",
            Box::new(UniformSum::new(2, 0.5 / s3).unwrap()),
            Some((2, 0.5 / s3)),
            0.5 / (3.0 * s3),
            [1.6816, 0.2618, 0.1018],
            [1.9972, 0.1553, 0.0607],
        ),
        (
            "gaussian σ=1/6",
            Box::new(Gaussian::new(1.0 / 6.0).unwrap()),
            None,
            1.0 / 6.0,
            [1.8175, 0.3267, 0.1281],
            [2.0357, 0.1607, 0.0678],
        ),
        (
            "gaussian σ=1/(6√3)",
            Box::new(Gaussian::new(1.0 / (6.0 * s3)).unwrap()),
            None,
            1.0 / (6.0 * s3),
            [1.8807, 0.1958, 0.0752],
            [2.1966, 0.1425, 0.0530],
        ),
    ];
    let runs = runs_range(o, RUNS);
    let n_runs = runs.end - runs.start;
    let mut md = String::from(
        "## Table 1: BCLS, known G(s) = 1/(s+2), uniform-sum jitter [n, a] estimated (n profiled over 0..=9)\n\n",
    );
    let mut out = Vec::new();
    let t = Instant::now();
    for (name, truth, nu, sigma, pm, ps) in &cases {
        let results: Vec<Option<(f64, f64, f64, Option<f64>)>> =
            mc_run(o.seed, runs.clone(), |_, rng| {
                let u = paper::input(rng, 8.0);
                let grid = paper::grid();
                let signal = LtiResponse::new(g.clone(), u);
                let data = simulate(&signal, truth.as_ref(), &grid, NOISE_STD, rng).ok()?;
                let record = Record::new(grid, data.y).ok()?;
                // Start: the truth's σ perturbed by 1 + U(−0.2, 0.2); n is profiled.
                let s0 = paper::perturb(&[*sigma], 0.2, rng)[0];
                let start = paper::uniform_sum_with_std(s0)(0).ok()?;
                let structure =
                    ModelStructure::oe(signal, start).with_estimated(false, true, false);
                let p = fit_profile(
                    &structure,
                    &record,
                    &Bcls,
                    &FitOptions::default(),
                    0..=9,
                    paper::uniform_sum_with_std(structure.jitter.std_dev()),
                )
                .ok()?;
                let a_se = p
                    .estimate
                    .std_errors
                    .as_ref()
                    .map(|s| paper::uniform_sum_sigma(p.value, s[0]));
                p.estimate.converged.then(|| {
                    (
                        p.value as f64,
                        p.estimate.params[0],
                        paper::uniform_sum_sigma(p.value, p.estimate.params[0]),
                        a_se,
                    )
                })
            });
        let ok: Vec<_> = results.iter().flatten().collect();
        let sn: Summary = ok.iter().map(|r| r.0).collect();
        let sa: Summary = ok.iter().map(|r| r.1).collect();
        let ss: Summary = ok.iter().map(|r| r.2).collect();
        // The asymptotic std at n̂ has a heavy right tail (weakly identified a): report its median.
        let mut ses: Vec<f64> = ok.iter().filter_map(|r| r.3).collect();
        ses.sort_by(f64::total_cmp);
        let sse = Summary {
            count: 1,
            mean: ses.get(ses.len() / 2).copied().unwrap_or(f64::NAN),
            m2: 0.0,
        };
        let rows = vec![
            row("n", nu.map(|v| v.0 as f64), &sn, None),
            row("a", nu.map(|v| v.1), &sa, None),
            row("sigma", Some(*sigma), &ss, Some(&sse)),
        ];
        let paper: Vec<(f64, f64)> = pm.iter().copied().zip(ps.iter().copied()).collect();
        let _ = write!(md, "### {name} ({} of {n_runs} converged)\n\n", ok.len());
        md += &table(&rows, Some(&paper));
        md.push('\n');
        out.push(json!({"name": name, "runs": n_runs, "converged": ok.len(), "parameters": rows}));
    }
    let secs = t.elapsed().as_secs_f64();
    let _ = writeln!(md, "{secs:.1} s wall for all cases. The asymptotic std column of σ̂ is the median over runs of the sandwich std at the chosen n̂ (conditional on n̂).");
    write_outputs(
        "table1",
        o,
        &json!({"case": "table1", "seconds": secs, "cases": out}),
        &md,
    )
}
