//! The file as written: one serde type per section, every key optional and spanned, unknown
//! keys rejected. Nothing here judges a value; that is the section parsers' job.

use serde::Deserialize;
use std::collections::BTreeMap;
use std::ops::Range;
use toml::Spanned;

/// A section whose keys depend on a choice made in it (`[jitter]`: the family's keys): every
/// value spanned, the keys judged by the section's parser.
pub(super) type RawTable = BTreeMap<String, Spanned<toml::Value>>;

macro_rules! section {
    ($name:ident, $title:literal { $($field:ident : $ty:ty),* $(,)? }) => {
        #[derive(Debug, Clone, Deserialize)]
        #[serde(deny_unknown_fields, rename = $title)]
        pub(super) struct $name {
            $( #[serde(default)] pub(super) $field: Option<Spanned<$ty>>, )*
        }
        impl $name {
            pub(super) const KEYS: &'static [&'static str] = &[$(stringify!($field)),*];
            // Only sections whose `kind`/`family` excludes keys ask which keys are present.
            #[allow(dead_code)]
            pub(super) fn present(&self) -> Vec<(&'static str, Range<usize>)> {
                #[allow(unused_mut)]
                let mut v = Vec::new();
                $( if let Some(s) = &self.$field { v.push((stringify!($field), s.span())); } )*
                v
            }
        }
    };
}

section!(RawSampling, "table [sampling]" {
    interval: f64,
    samples: i64,
    start: f64,
});

section!(RawInput, "table [input]" {
    name: String,
    kind: String,
    mean_dwell: f64,
    low: f64,
    high: f64,
    frequency: f64,
    amplitude: f64,
    phase: f64,
    frequencies: Vec<f64>,
    amplitudes: Vec<f64>,
    phases: Vec<f64>,
    times: Vec<f64>,
    values: Vec<f64>,
    path: String,
    time_column: String,
    value_column: String,
    history: f64,
    level: f64,
    estimate_level: bool,
});

section!(RawSystem, "table [system]" {
    kind: String,
    gain: f64,
    zeros: Vec<toml::Value>,
    poles: Vec<toml::Value>,
    num: Vec<f64>,
    den: Vec<f64>,
    amplitude: f64,
    frequency: f64,
    phase: f64,
    estimate: bool,
    initial: String,
    delay: f64,
    unstable: bool,
    integrators: i64,
    params: toml::Value,
    fixed: toml::Value,
    bounds: toml::Value,
    a: toml::Value,
    b: toml::Value,
    c: toml::Value,
    d: toml::Value,
});

section!(RawOutput, "table [output]" {
    offset: f64,
    estimate_offset: bool,
});

section!(RawNoise, "table [noise]" {
    std: f64,
    model: String,
    c: Vec<f64>,
    d: Vec<f64>,
    estimate: bool,
});

section!(RawEstimate, "table [estimate]" {
    method: String,
    frequencies: toml::Value,
    solver: String,
    multistart: i64,
    multistart_radius: f64,
    perturb: f64,
    max_iterations: i64,
});

section!(RawSelect, "table [select]" {
    poles: Vec<i64>,
    zeros: Vec<i64>,
    families: Vec<String>,
    orders: BTreeMap<String, Vec<Vec<i64>>>,
});

section!(RawDesign, "table [design]" {
    mean_dwell: Vec<f64>,
    low: Vec<f64>,
    high: Vec<f64>,
    interval: Vec<f64>,
    jitter_exponent: f64,
    hold: String,
    duration: f64,
    samples: i64,
    criterion: String,
    estimator: String,
    draws: i64,
    grid: i64,
    seed: i64,
    prior_spread: f64,
    prior_jitter_spread: f64,
    prior_draws: i64,
    derived: Vec<String>,
    band: Vec<f64>,
    tones: i64,
    power: f64,
    peak: f64,
    phases: String,
    dac_rate: f64,
});

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, rename = "experiment file")]
pub(super) struct RawExperiment {
    #[serde(default)]
    pub(super) title: Option<String>,
    #[serde(default)]
    pub(super) sampling: Option<RawSampling>,
    #[serde(default)]
    pub(super) input: Option<OneOrMany<RawInput>>,
    #[serde(default)]
    pub(super) system: Option<OneOrMany<RawSystem>>,
    #[serde(default)]
    pub(super) jitter: Option<RawTable>,
    #[serde(default)]
    pub(super) output: Option<RawOutput>,
    #[serde(default)]
    pub(super) noise: Option<RawNoise>,
    #[serde(default)]
    pub(super) estimate: Option<RawEstimate>,
    #[serde(default)]
    pub(super) select: Option<RawSelect>,
    #[serde(default)]
    pub(super) design: Option<RawDesign>,
}

/// A section written once (`[input]`) or as an array of tables (`[[input]]`, one per input of
/// a multi-input system). Read by hand rather than as an untagged enum so that an error inside
/// a table (an unknown key, a wrong type) keeps its own message and place.
#[derive(Debug)]
pub(super) enum OneOrMany<T> {
    /// `[name]`.
    One(T),
    /// `[[name]]`, in file order.
    Many(Vec<T>),
}

impl<T> OneOrMany<T> {
    /// The tables, in file order.
    pub(super) fn items(&self) -> Vec<&T> {
        match self {
            OneOrMany::One(t) => vec![t],
            OneOrMany::Many(v) => v.iter().collect(),
        }
    }

    /// The first table (the only one of `[name]`).
    pub(super) fn first(&self) -> Option<&T> {
        match self {
            OneOrMany::One(t) => Some(t),
            OneOrMany::Many(v) => v.first(),
        }
    }
}

impl<'de, T: Deserialize<'de>> Deserialize<'de> for OneOrMany<T> {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visit<T>(std::marker::PhantomData<T>);
        impl<'de, T: Deserialize<'de>> serde::de::Visitor<'de> for Visit<T> {
            type Value = OneOrMany<T>;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a table or an array of tables")
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(
                self,
                map: A,
            ) -> Result<Self::Value, A::Error> {
                T::deserialize(serde::de::value::MapAccessDeserializer::new(map))
                    .map(OneOrMany::One)
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                seq: A,
            ) -> Result<Self::Value, A::Error> {
                Vec::<T>::deserialize(serde::de::value::SeqAccessDeserializer::new(seq))
                    .map(OneOrMany::Many)
            }
        }
        d.deserialize_any(Visit(std::marker::PhantomData))
    }
}

pub(super) const SECTIONS: &[&str] = &[
    "title", "sampling", "input", "system", "output", "jitter", "noise", "estimate", "select",
    "design",
];

pub(super) fn keys_of(section: &str) -> &'static [&'static str] {
    match section {
        "sampling" => RawSampling::KEYS,
        "input" => RawInput::KEYS,
        "system" => RawSystem::KEYS,
        "output" => RawOutput::KEYS,
        "noise" => RawNoise::KEYS,
        "estimate" => RawEstimate::KEYS,
        "select" => RawSelect::KEYS,
        "design" => RawDesign::KEYS,
        _ => SECTIONS,
    }
}

/// The keys listed in the first column of the key table under `heading` in
/// `docs/experiments.md`, in order: what the tests that keep the reference beside the reader
/// compare with a section's `KEYS`.
#[cfg(test)]
pub(super) fn docs_table_keys(heading: &str) -> Vec<String> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/experiments.md");
    let text = std::fs::read_to_string(path).expect("docs/experiments.md is readable");
    let start = text
        .find(heading)
        .unwrap_or_else(|| panic!("docs/experiments.md has no {heading} section"));
    text[start..]
        .lines()
        .skip_while(|l| !l.starts_with("| key |"))
        .skip(2)
        .take_while(|l| l.starts_with('|'))
        .filter_map(|l| l.split('`').nth(1))
        .map(String::from)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::{docs_table_keys, RawInput, RawOutput};

    /// The `[output]` table of `docs/experiments.md` lists exactly the keys the reader takes,
    /// in order: the reference cannot drift from the reader.
    #[test]
    fn the_docs_output_table_lists_the_reader_s_keys() {
        assert_eq!(docs_table_keys("### `[output]`"), RawOutput::KEYS);
    }

    /// The input's level table lists the reader's last two `[input]` keys.
    #[test]
    fn the_docs_level_table_lists_the_reader_s_keys() {
        let keys = RawInput::KEYS;
        assert_eq!(
            docs_table_keys("#### The input's level"),
            keys[keys.len() - 2..]
        );
    }
}
