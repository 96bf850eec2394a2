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
