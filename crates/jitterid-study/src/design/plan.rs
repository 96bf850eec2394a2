//! The experiment as a document that designs edit: its text, where it came from, the user's
//! own edits, and its `[design]` section.

use super::blind::without_jitter;
use super::candidate::Design;
use super::criterion::criterion_value;
use super::jitter_scaling::at_interval;
use super::predict::{predict, Prediction};
use super::prior::{prior_draws, PriorDraw};
use super::progress::{DesignObserver, DesignProgress};
use crate::error::StudyResult;
use crate::experiment::{
    directory_of, parse_edited, read_text, DesignCriterion, DesignSpec, Experiment, Purpose,
    ReadOptions,
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
    /// Whether the prior's jitter is replaced by none (see [`Plan::jitter_blind`]).
    blind: bool,
    /// A robust design's prior draws (empty without a prior spread), drawn once: they move
    /// the truth alone, the same at every design.
    prior: Vec<PriorDraw>,
    /// Who is told of the search's progress (a front end's display), if anyone.
    observer: Option<DesignObserver>,
}

/// A design of the random binary input's levels with `low = high` is refused: such an input
/// never changes level, so its switches, which the design is about, excite nothing. Any
/// information left comes from the one step at the record's start where the system was at
/// rest before it (an artefact of the input's history that no random binary design means),
/// and with both levels 0 there is no signal and the information matrix is singular. The
/// search counts it as infeasible, like a singular information matrix.
fn no_excitation(file: &str, design: &Design) -> StudyResult<()> {
    match (design.low, design.high) {
        (Some(low), Some(high)) if low == high => Err(study_err!(
            "{file}: [design] low = {low}, high = {high}: the random binary input never switches (low = high): no excitation; a design of the levels needs low != high"
        )),
        _ => Ok(()),
    }
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
        // A prior draw that makes the model invalid is refused here, naming its key.
        let prior = match &spec.prior {
            Some(p) => prior_draws(&baseline, p, spec.seed)?,
            None => Vec::new(),
        };
        let plan = Plan {
            registries: Arc::clone(registries),
            file: file.to_string(),
            text,
            dir: dir.to_path_buf(),
            options: options.clone(),
            baseline,
            spec,
            blind: false,
            prior,
            observer: None,
        };
        // A budget on a fixed interval is one record: it must be one the experiment allows
        // (the jitter's reach within it, the input's switches), or no design can meet it.
        if let (Some(key), None) = (plan.spec.budget_key, plan.spec.interval) {
            plan.experiment(&plan.budget_design()).map_err(|e| {
                study_err!("{file}: [design] {key}: a budget that cannot be met: {e}")
            })?;
        }
        Ok(plan)
    }

    /// The baseline's design on the budget's record (`[design] duration` or `samples`): where
    /// the search starts, and every candidate's record.
    pub fn budget_design(&self) -> Design {
        let mut d = self.baseline_design();
        d.samples = self.spec.budget.samples_at(d.interval);
        d
    }

    /// The same plan on the jitter-blind prior: every experiment it reads has its jitter
    /// replaced by none (`γ ≡ 1`, no jitter noise, nothing of the jitter estimated), so that a
    /// search on it is the design of a user who ignores the jitter.
    ///
    /// # Errors
    ///
    /// The registry has no family `none`.
    pub fn jitter_blind(&self) -> StudyResult<Plan> {
        Ok(Plan {
            baseline: without_jitter(self.baseline.clone())?,
            blind: true,
            // The jitter-blind prior has no jitter to move.
            prior: self.prior.iter().map(PriorDraw::without_jitter).collect(),
            ..self.clone()
        })
    }

    /// The same plan with its predictions averaged over `draws` input draws of master seed
    /// `seed` (a Monte Carlo of `draws` runs with that seed sees the same inputs); a robust
    /// design's prior is drawn again from `seed`.
    ///
    /// # Errors
    ///
    /// A prior draw of `seed` that makes the model invalid (see [`Plan::parse`]).
    pub fn with_draws(&self, draws: usize, seed: u64) -> StudyResult<Plan> {
        let mut plan = self.clone();
        plan.spec.draws = draws;
        plan.spec.seed = seed;
        if let Some(p) = &plan.spec.prior {
            plan.prior = prior_draws(&plan.baseline, p, seed)?;
        }
        Ok(plan)
    }

    /// The same plan reporting its searches' progress to `observer` (the plans derived from
    /// it, such as [`Plan::jitter_blind`], too); the numbers do not depend on it.
    pub fn with_observer(&self, observer: DesignObserver) -> Plan {
        Plan {
            observer: Some(observer),
            ..self.clone()
        }
    }

    /// Tells the observer, if any, of `p`.
    pub(crate) fn observe(&self, p: DesignProgress) {
        if let Some(o) = &self.observer {
            o.report(&p);
        }
    }

    /// Whether this is the jitter-blind plan.
    pub fn is_jitter_blind(&self) -> bool {
        self.blind
    }

    /// The predicted precision of `design` under this plan's prior, with the `[design]`
    /// section's estimator, draws and seed.
    ///
    /// # Errors
    ///
    /// Those of [`Plan::experiment`] and [`predict`]; a design of the levels with `low =
    /// high` (an input that never switches: no excitation).
    pub fn predict(&self, design: &Design) -> StudyResult<Prediction> {
        no_excitation(&self.file, design)?;
        let exp = self.experiment(design)?;
        predict(&exp, self.spec.estimator, self.spec.draws, self.spec.seed)
    }

    /// The criterion a search minimises at `design`, given its `prediction` at the prior's
    /// point and that prediction's criterion value `nominal`: `nominal` itself, or for a
    /// robust design (`[design] prior_spread`, `prior_jitter_spread`) the criterion averaged
    /// over the prior's draws, each predicted on the same input draws.
    ///
    /// # Errors
    ///
    /// The design's experiment is invalid; a draw's prediction fails (a singular information
    /// matrix).
    pub fn robust_value(
        &self,
        design: &Design,
        criterion: &DesignCriterion,
        nominal: f64,
    ) -> StudyResult<f64> {
        if self.prior.is_empty() {
            return Ok(nominal);
        }
        let exp = self.experiment(design)?;
        let mut sum = 0.0;
        for (i, draw) in self.prior.iter().enumerate() {
            let e = draw.apply(&exp);
            let p = predict(&e, self.spec.estimator, self.spec.draws, self.spec.seed)?;
            sum += criterion_value(criterion, &p)?;
            self.observe(DesignProgress::PriorDraw {
                done: i + 1,
                total: self.prior.len(),
            });
        }
        Ok(sum / self.prior.len() as f64)
    }

    /// The edits the plan was read with (the user's `--set`), in order.
    pub(crate) fn edits(&self) -> &[crate::experiment::Override] {
        &self.options.overrides
    }

    /// The experiment's text as written.
    pub(crate) fn text(&self) -> &str {
        &self.text
    }

    /// The baseline's design.
    pub fn baseline_design(&self) -> Design {
        let mut d = Design::of(&self.baseline);
        // Under a design of the levels the file's own pair is part of the baseline's design
        // (both, so that the fixed one is shown beside the free one).
        if self.spec.low.is_some() || self.spec.high.is_some() {
            if let Some((low, high)) = super::realization::levels_of(&self.baseline) {
                d.low = Some(low);
                d.high = Some(high);
            }
        }
        // Under a multisine design the file's own tones are part of the baseline's design.
        if self.spec.multisine.is_some() {
            let start = self.baseline.grid.start();
            let span = (start, start + d.samples as f64 * d.interval);
            d.multisine = super::realization::tones_of(&self.baseline)
                .map(|t| super::multisine::MultisineDesign::of_tones(&t, span));
        }
        d
    }

    /// The experiment of `design`: the document with the design's edits, read again.
    ///
    /// # Errors
    ///
    /// The edited experiment is invalid (the message names the design's edit).
    pub fn experiment(&self, design: &Design) -> StudyResult<Experiment> {
        let mut options = self.options.clone();
        options.overrides.extend(design.edits());
        let exp = parse_edited(
            &self.registries,
            &self.file,
            &self.text,
            &self.dir,
            Purpose::Simulate,
            &options,
        )?;
        if self.blind {
            without_jitter(exp)
        } else {
            // The jitter at the design's interval, when it depends on the interval (the
            // prediction checks the moved jitter's reach against the record).
            at_interval(
                exp,
                &self.baseline.jitter.truth,
                self.baseline.grid.interval(),
                self.spec.jitter_exponent,
            )
        }
    }
}
