//! What the design tests share.

use jitterid_study::design::Plan;
use jitterid_study::experiment::ReadOptions;
use jitterid_study::Registries;
use std::path::Path;

/// The experiment text `text` read as a design plan (named `exp.toml`, paths from `.`).
pub fn plan(text: &str) -> Result<Plan, String> {
    Plan::parse(
        &Registries::builtin(),
        "exp.toml",
        text.to_string(),
        Path::new("."),
        &ReadOptions::default(),
    )
    .map_err(|e| e.to_string())
}

/// A random binary input of mean dwell 8 s between 0 and 1 (the paper's).
// Each test binary compiles this module; not every one uses every helper.
#[allow(dead_code)]
pub const RANDOM_BINARY: &str = "kind = \"random-binary\"\nmean_dwell = 8.0";

/// Table 2's system, known uniform-sum jitter and noise 0.01 at `T = 1 s` with `samples`
/// samples, driven by the `[input]` keys `input`, with `extra` appended.
#[allow(dead_code)]
pub fn setup(samples: usize, input: &str, extra: &str) -> String {
    format!(
        r#"
[sampling]
interval = 1.0
samples = {samples}
[input]
{input}
[system]
kind = "zpk"
gain = 0.2
zeros = [-0.5]
poles = [[-0.25, 0.3]]
estimate = true
[jitter]
family = "uniform-sum"
n = 2
a = 0.28867513459481287
[noise]
std = 0.01
{extra}
"#
    )
}

/// The Table 2 setup (as `examples/experiments/table2.toml`: `N = 200`, the paper's input),
/// with `extra` appended.
#[allow(dead_code)]
pub fn table2(extra: &str) -> String {
    setup(200, RANDOM_BINARY, extra)
}
