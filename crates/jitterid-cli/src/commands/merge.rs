//! `jitterid merge`: shard files of one study combined by the study layer into the result of
//! the unsharded study.

use super::emit;
use crate::exit::{Outcome, Status};
use crate::output::OutputSet;
use jitterid_study::error::StudyResult;
use jitterid_study::merge::merge_files;
use std::path::{Path, PathBuf};

/// `jitterid merge`: combines shard files into the result of the unsharded study; exit status
/// [`Status::NotConverged`] when no fit of the study converged (unless `accept_unconverged`).
/// Without `timing` the merged wall time (`seconds`) is left out.
pub fn merge(
    files: &[PathBuf],
    json: bool,
    out: Option<&Path>,
    accept_unconverged: bool,
    timing: bool,
) -> StudyResult<Outcome> {
    let mut merged = merge_files(files)?;
    if !timing {
        merged.seconds = None;
    }
    let status = Status::of_convergence(merged.converged > 0, accept_unconverged);
    let text = emit(&merged, json, out, OutputSet::new())?;
    Ok(Outcome { text, status })
}
