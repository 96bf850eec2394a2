//! Merging: shard files of one study, checked to belong together and to be whole, into
//! the result of the unsharded study.
//!
//! A shard belongs to the study of the first shard when its program version, experiment
//! fingerprint (by content, not path), seed, method, run count, shard count, parameter names and
//! true values are the same. A shard is whole when its runs are exactly those of its index, every
//! realisation has one value per parameter, and its summaries, convergence count and termination
//! counts are what its realisations give (so a hand-edited value is caught).

use crate::csvio;
use crate::error::StudyResult;
use crate::montecarlo::{summarize, terminations, McJson, Realization, ShardInfo, MAX_RUNS};
use crate::study_err;
use std::path::{Path, PathBuf};

/// Largest number of shards of one study.
const MAX_SHARDS: u64 = 1_000_000;

/// A shard file, read.
struct Part {
    name: String,
    json: McJson,
    shard: ShardInfo,
    runs: Vec<Realization>,
}

fn read_part(path: &Path) -> StudyResult<Part> {
    let name = path.display().to_string();
    let text = csvio::read_text(path, &name, "a shard file")?;
    let json: McJson = serde_json::from_str(&text).map_err(|e| {
        study_err!(
            "{name}:{}:{}: not a shard file of `jitterid montecarlo --shard i/n --json`: {e}",
            e.line(),
            e.column()
        )
    })?;
    part_of(name, json)
}

/// A shard result called `name` in messages, checked to be a shard.
fn part_of(name: String, json: McJson) -> StudyResult<Part> {
    let (Some(shard), Some(runs)) = (json.shard.clone(), json.realizations.clone()) else {
        return Err(study_err!("{name}: not a shard file (no `shard` and `realizations`); write shards with montecarlo --shard i/n --json"));
    };
    if json.fingerprint.is_empty() || json.program.is_empty() {
        return Err(study_err!(
            "{name}: has no `fingerprint` and `program` (written by an older jitterid?); its study cannot be identified, so run the shard again"
        ));
    }
    Ok(Part {
        name,
        json,
        shard,
        runs,
    })
}

/// A text from a shard file as a message quotes it: between double quotes as it was written
/// (no escapes of quotes, backslashes or non-ASCII text, unlike Rust's `{:?}`), with only the
/// characters a terminal would act on (control characters) escaped, and at most
/// [`QUOTED_CHARS`] characters (`…` marks a cut) of a file that may not be the user's.
fn quoted(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars().take(QUOTED_CHARS) {
        if c.is_control() {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    if s.chars().count() > QUOTED_CHARS {
        out.push('…');
    }
    out.push('"');
    out
}

/// Most characters of a text from a shard file that a message quotes (a fingerprint is 64).
const QUOTED_CHARS: usize = 80;

/// The first field in which `p` and `first` differ, as (what, this value, first value), each
/// value as a message shows it: numbers as they are, texts [`quoted`].
fn identity_mismatch(p: &Part, first: &Part) -> Option<(&'static str, String, String)> {
    let text = |a: &str, b: &str| (a != b).then(|| (quoted(a), quoted(b)));
    let number = |a: u64, b: u64| (a != b).then(|| (a.to_string(), b.to_string()));
    let fields: [(&'static str, Option<(String, String)>); 6] = [
        (
            "program version",
            text(&p.json.program, &first.json.program),
        ),
        ("seed", number(p.json.seed, first.json.seed)),
        ("method", text(&p.json.method, &first.json.method)),
        (
            "run count",
            number(p.shard.runs_total, first.shard.runs_total),
        ),
        ("shard count", number(p.shard.count, first.shard.count)),
        // Last: the method is part of the parsed experiment too, so a more specific field
        // above names the difference when there is one.
        (
            "experiment (fingerprint of its contents)",
            text(&p.json.fingerprint, &first.json.fingerprint),
        ),
    ];
    fields
        .into_iter()
        .find_map(|(what, differ)| differ.map(|(this, theirs)| (what, this, theirs)))
}

/// An optional value as a message shows it: the number, or `none` (`null` in the file).
fn shown(v: Option<f64>) -> String {
    v.map_or_else(|| "none".to_string(), |x| x.to_string())
}

/// Checks that `p` is whole: its runs, value counts, and stored summaries agree.
fn check_whole(p: &Part, names: &[String], truth: &[Option<f64>]) -> StudyResult<()> {
    let name = &p.name;
    let s = &p.shard;
    let first = s.runs_total * s.index / s.count;
    let end = s.runs_total * (s.index + 1) / s.count;
    if s.first != first || s.end != end {
        return Err(study_err!(
            "{name}: shard {}/{} of {} runs covers runs {first}..{end}, but the file says {}..{}",
            s.index,
            s.count,
            s.runs_total,
            s.first,
            s.end
        ));
    }
    if p.runs.len() as u64 != end - first || p.json.runs != end - first {
        return Err(study_err!(
            "{name}: expected {} realisations (runs {first}..{end}), found {} (`runs` says {})",
            end - first,
            p.runs.len(),
            p.json.runs
        ));
    }
    for (i, r) in p.runs.iter().enumerate() {
        if r.run != first + i as u64 {
            return Err(study_err!(
                "{name}: realisation {i} is run {}, expected run {} (runs in order, each once)",
                r.run,
                first + i as u64
            ));
        }
        if r.values.len() != names.len() {
            return Err(study_err!(
                "{name}: run {}: expected {} values (one per parameter), found {}",
                r.run,
                names.len(),
                r.values.len()
            ));
        }
    }
    let converged = p.runs.iter().filter(|r| r.converged).count() as u64;
    if converged != p.json.converged {
        return Err(study_err!(
            "{name}: `converged` says {}, but {converged} of its realisations converged",
            p.json.converged
        ));
    }
    if terminations(&p.runs) != p.json.terminations {
        return Err(study_err!(
            "{name}: `terminations` do not count its realisations' terminations"
        ));
    }
    let recomputed = summarize(names, truth, &p.runs);
    if let Some((stored, again)) = p
        .json
        .parameters
        .iter()
        .zip(&recomputed)
        .find(|(a, b)| a != b)
    {
        return Err(study_err!(
            "{name}: the summary of `{}` is not that of its realisations (mean {} stored, {} computed): was the file edited?",
            stored.name,
            shown(stored.mean),
            shown(again.mean)
        ));
    }
    Ok(())
}

/// Reads shard files and combines them into the result of the unsharded study (what
/// `jitterid merge --json` prints).
pub fn merge_files(files: &[PathBuf]) -> StudyResult<McJson> {
    let parts = files
        .iter()
        .map(|f| read_part(f))
        .collect::<StudyResult<Vec<Part>>>()?;
    merge_parts(&parts)
}

/// Combines shard results, each with the name that messages call it by, into the result of
/// the unsharded study (what `jitterid merge --json` prints).
pub fn merge_values(shards: Vec<(String, McJson)>) -> StudyResult<McJson> {
    let parts = shards
        .into_iter()
        .map(|(name, json)| part_of(name, json))
        .collect::<StudyResult<Vec<Part>>>()?;
    merge_parts(&parts)
}

fn merge_parts(parts: &[Part]) -> StudyResult<McJson> {
    let Some(first) = parts.first() else {
        return Err(study_err!("merge: expected at least one shard file"));
    };
    let s0 = &first.shard;
    if !(1..=MAX_SHARDS).contains(&s0.count) || !(1..=MAX_RUNS).contains(&s0.runs_total) {
        return Err(study_err!(
            "{}: shard count {} or run total {} out of range (1 to {MAX_SHARDS} shards, 1 to {MAX_RUNS} runs)",
            first.name,
            s0.count,
            s0.runs_total
        ));
    }
    let names: Vec<String> = first
        .json
        .parameters
        .iter()
        .map(|p| p.name.clone())
        .collect();
    let truth: Vec<Option<f64>> = first.json.parameters.iter().map(|p| p.truth).collect();
    let mut seen = vec![false; s0.count as usize];
    for p in parts {
        if let Some((what, this, theirs)) = identity_mismatch(p, first) {
            return Err(study_err!(
                "{}: belongs to another study than {}: its {what} is {this}, not {theirs}",
                p.name,
                first.name
            ));
        }
        if p.json.parameters.iter().map(|q| &q.name).ne(names.iter()) {
            return Err(study_err!(
                "{}: its parameters differ from those of {}",
                p.name,
                first.name
            ));
        }
        if let Some(q) = p
            .json
            .parameters
            .iter()
            .zip(&truth)
            .find(|(q, t)| q.truth.map(f64::to_bits) != t.map(f64::to_bits))
        {
            return Err(study_err!(
                "{}: the true value of `{}` is {}, not {} as in {}",
                p.name,
                q.0.name,
                shown(q.0.truth),
                shown(*q.1),
                first.name
            ));
        }
        let slot = seen
            .get_mut(p.shard.index as usize)
            .ok_or_else(|| study_err!("{}: shard index {} out of range", p.name, p.shard.index))?;
        if *slot {
            return Err(study_err!(
                "{}: shard {}/{} given twice",
                p.name,
                p.shard.index,
                p.shard.count
            ));
        }
        *slot = true;
        check_whole(p, &names, &truth)?;
    }
    if let Some(missing) = seen.iter().position(|s| !s) {
        return Err(study_err!("merge: shard {missing}/{} is missing", s0.count));
    }
    let mut all: Vec<Realization> = parts.iter().flat_map(|p| p.runs.clone()).collect();
    all.sort_by_key(|r| r.run);
    let merged = McJson {
        method: first.json.method.clone(),
        runs: s0.runs_total,
        converged: all.iter().filter(|r| r.converged).count() as u64,
        terminations: terminations(&all),
        // Summed where every shard has its time; absent if one has none.
        seconds: parts.iter().map(|p| p.json.seconds).sum(),
        seed: first.json.seed,
        experiment: first.json.experiment.clone(),
        fingerprint: first.json.fingerprint.clone(),
        program: first.json.program.clone(),
        parameters: summarize(&names, &truth, &all),
        shard: None,
        realizations: None,
    };
    Ok(merged)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Shard `index` of a two-shard study of two runs, with no parameters.
    fn shard(index: u64, program: &str, seed: u64) -> (String, McJson) {
        let runs = vec![Realization {
            run: index,
            converged: true,
            termination: "converged".into(),
            values: Vec::new(),
        }];
        let json = McJson {
            method: "bcls".into(),
            runs: 1,
            converged: 1,
            terminations: terminations(&runs),
            seconds: None,
            seed,
            experiment: "e.toml".into(),
            fingerprint: "f".repeat(64),
            program: program.into(),
            parameters: Vec::new(),
            shard: Some(ShardInfo {
                index,
                count: 2,
                runs_total: 2,
                first: index,
                end: index + 1,
            }),
            realizations: Some(runs),
        };
        (format!("s{index}.json"), json)
    }

    /// A shard of another study is named with its value as written: a text between plain
    /// double quotes (its quotes, backslash and accent as they are, unlike Rust's `{:?}`, with
    /// only a control character escaped), a number bare.
    #[test]
    fn a_mismatch_quotes_the_values_as_written() {
        let ours = "jitterid 0.1.0";
        let theirs = "jitterid \"next\" C:\\build é\u{1b}";
        let e = merge_values(vec![shard(0, ours, 5), shard(1, theirs, 5)]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "s1.json: belongs to another study than s0.json: its program version is \
             \"jitterid \"next\" C:\\build é\\u{1b}\", not \"jitterid 0.1.0\""
        );
        let e = merge_values(vec![shard(0, ours, 5), shard(1, ours, 6)]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "s1.json: belongs to another study than s0.json: its seed is 6, not 5"
        );
        // A long text is cut.
        let long = "x".repeat(500);
        let e = merge_values(vec![shard(0, ours, 5), shard(1, &long, 5)]).unwrap_err();
        assert!(
            e.to_string()
                .contains(&format!("is \"{}…\", not", "x".repeat(QUOTED_CHARS))),
            "{e}"
        );
        // The two shards of one study merge.
        let merged = merge_values(vec![shard(0, ours, 5), shard(1, ours, 5)]).unwrap();
        assert_eq!(merged.runs, 2);
    }
}
