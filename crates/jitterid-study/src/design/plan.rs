//! The experiment as a document that designs edit: its text, where it came from, the user's
//! own edits, and its `[design]` section.

use super::candidate::Design;
use crate::error::StudyResult;
use crate::experiment::{
    directory_of, parse_edited, read_text, DesignSpec, Experiment, Purpose, ReadOptions,
};
use crate::study_err;
use crate::Registries;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// An experiment file read for design: every candidate design is the file with that design's
/// edits applied after the user's, read again.
#[derive(Debug, Clone)]
pub struct Plan {
    registries: Arc<Registries>,
    file: String,
    text: String,
    dir: PathBuf,
    options: ReadOptions,
    /// The experiment as written (with the user's edits): the baseline design.
    pub baseline: Experiment,
    /// Its `[design]` section.
    pub spec: DesignSpec,
}

impl Plan {
    /// Reads the experiment file at `path`, edited as `options` says.
    ///
    /// # Errors
    ///
    /// Those of reading the experiment; a file without a `[design]` section.
    pub fn read(path: &Path, options: &ReadOptions) -> StudyResult<Self> {
        let text = read_text(path)?;
        Self::parse(
            &Registries::builtin(),
            &path.display().to_string(),
            text,
            &directory_of(path),
            options,
        )
    }

    /// The experiment text `text` (named `file` in messages, relative paths resolved from
    /// `dir`), edited as `options` says, looking names up in `registries`.
    ///
    /// # Errors
    ///
    /// Those of [`parse_edited`]; a document without a `[design]` section.
    pub fn parse(
        registries: &Arc<Registries>,
        file: &str,
        text: String,
        dir: &Path,
        options: &ReadOptions,
    ) -> StudyResult<Self> {
        let baseline = parse_edited(registries, file, &text, dir, Purpose::Simulate, options)?;
        let spec = baseline.design.clone().ok_or_else(|| {
            study_err!(
                "{file}: no [design] section; expected one naming the free design variables (mean_dwell = [min, max], interval = [min, max])"
            )
        })?;
        Ok(Plan {
            registries: Arc::clone(registries),
            file: file.to_string(),
            text,
            dir: dir.to_path_buf(),
            options: options.clone(),
            baseline,
            spec,
        })
    }

    /// The baseline's design.
    pub fn baseline_design(&self) -> Design {
        Design::of(&self.baseline)
    }

    /// The experiment of `design`: the document with the design's edits, read again.
    ///
    /// # Errors
    ///
    /// The edited experiment is invalid (the message names the design's edit).
    pub fn experiment(&self, design: &Design) -> StudyResult<Experiment> {
        let mut options = self.options.clone();
        options.overrides.extend(design.edits());
        parse_edited(
            &self.registries,
            &self.file,
            &self.text,
            &self.dir,
            Purpose::Simulate,
            &options,
        )
    }
}
