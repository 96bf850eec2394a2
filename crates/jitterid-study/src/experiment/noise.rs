//! `[noise]`: the measurement noise's level and shape.

use super::diagnostics::Source;
use super::range;
use super::raw::RawNoise;
use super::spec::{quoted_list, NoiseSpec};
use crate::error::StudyResult;
use jitterid::estimate::{AnyNoise, ArmaNoise, WhiteNoise};

const S: &str = "noise";

/// Keys of `[noise]` the command line reads itself, whatever the model.
const OWN_KEYS: &[&str] = &["std", "model", "estimate"];

pub(super) fn parse_noise(cx: &Source, r: &RawNoise) -> StudyResult<NoiseSpec> {
    let present = r.present();
    let std = match &r.std {
        Some(v) => {
            let x = cx.checked(S, "std", v, range::level)?;
            if x < 0.0 {
                return Err(cx.err(
                    S,
                    "std",
                    &v.span(),
                    format!("expected a standard deviation >= 0, found {x}"),
                ));
            }
            x
        }
        None => 0.0,
    };
    let estimate = r.estimate.as_ref().is_some_and(|e| *e.get_ref());
    let model = r.model.as_ref().map_or("white", |m| m.get_ref().as_str());
    let registry = &cx.registries.noise;
    let names: Vec<&str> = registry.entries().iter().map(|e| e.name).collect();
    let model_span = || r.model.as_ref().map(|m| m.span()).unwrap_or(0..0);
    let Some(entry) = registry.entry(model) else {
        return Err(cx.err(
            S,
            "model",
            &model_span(),
            format!(
                "unknown noise model \"{model}\"; expected {}",
                quoted_list(&names)
            ),
        ));
    };
    let mut keys = OWN_KEYS.to_vec();
    keys.extend(entry.params.iter().map(|p| p.key.as_str()));
    let shape = match model {
        "white" => {
            cx.only(S, &present, "model", &keys, "white")?;
            AnyNoise::new(WhiteNoise)
        }
        "arma" => {
            let c = match &r.c {
                Some(v) => cx.finite_list(S, "c", v)?,
                None => Vec::new(),
            };
            let d = match &r.d {
                Some(v) => cx.finite_list(S, "d", v)?,
                None => Vec::new(),
            };
            AnyNoise::new(ArmaNoise::new(c, d).map_err(|e| {
                let span = r.model.as_ref().map(|m| m.span()).unwrap_or(0..0);
                cx.err(S, "model", &span, e)
            })?)
        }
        other => {
            return Err(cx.err(
                S,
                "model",
                &model_span(),
                format!("the command line has no reader for the noise model \"{other}\""),
            ));
        }
    };
    Ok(NoiseSpec {
        std,
        model: model.to_string(),
        shape,
        estimate,
    })
}
