//! The frequency response of `validate --bode`: one diagram for one input, one per input for
//! a system with several (the CSV's first column names the input).

use crate::error::StudyResult;
use crate::fit::Structure;
use crate::study_err;
use crate::validate::{
    bode_csv, bode_frequencies, bode_row, frequency_response, system_block, BODE_COLUMNS,
};
use jitterid::estimate::validation::BodePoint;
use jitterid::signal::superposition::Superposition;
use jitterid::signal::{Offset, SampleGrid, Signal};

/// One input's name and frequency response.
pub type InputResponse = (String, Vec<BodePoint>);

/// Each input's frequency response `G_i(i2πf)` of the multi-input system `s`, with its
/// delta-method band from the channel's block of the covariance `cov` (of the sum's
/// parameters; a fixed channel has none); `None` when `s` has one input. `flag` names the
/// option in messages.
///
/// # Errors
///
/// A channel that is not a rational system, and the responses' own errors.
pub fn channel_responses(
    s: &Structure,
    grid: &SampleGrid,
    cov: Option<&[Vec<f64>]>,
    flag: &str,
) -> StudyResult<Option<Vec<InputResponse>>> {
    let Some(sum) = s.signal.downcast::<Offset<Superposition>>() else {
        return Ok(None);
    };
    let freqs = bode_frequencies(grid, flag)?;
    let all = s.signal.param_names();
    let shared = sum.signal().is_shared();
    let mut out = Vec::new();
    for c in sum.signal().channels() {
        let own = c.signal.param_names();
        // The channel's parameters in the sum's: prefixed by the input's name, or (one model
        // with a column per input) its own names, shared by every input.
        let place = |p: &String| {
            let name = if shared {
                p.clone()
            } else {
                format!("{}.{p}", c.name)
            };
            all.iter().position(|n| *n == name)
        };
        let block = match (cov, own.iter().map(place).collect::<Option<Vec<usize>>>()) {
            (Some(cov), Some(idx)) if c.estimated => Some(
                idx.iter()
                    .map(|&i| idx.iter().map(|&j| cov[i][j]).collect())
                    .collect::<Vec<Vec<f64>>>(),
            ),
            _ => None,
        };
        let block = system_block(&own, block.as_deref());
        let points = crate::export::bode_of(&c.signal, &freqs, block.as_deref())
            .ok_or_else(|| {
                study_err!(
                    "{flag}: input `{}`: the system is not a rational transfer function",
                    c.name
                )
            })?
            .map_err(|e| study_err!("{flag}: input `{}`: {e}", c.name))?;
        out.push((c.name.clone(), points));
    }
    Ok(Some(out))
}

/// The CSV of `validate --bode`: for one input the frequency response's columns (`f_hz`,
/// `omega_rad_s`, `magnitude_db`, `phase_deg` and the band's four), for several inputs the
/// same columns after `input`, the rows of each input's response in input order.
///
/// # Errors
///
/// A system that is not rational, and the responses' errors.
pub fn bode_text(
    s: &Structure,
    grid: &SampleGrid,
    cov: Option<&[Vec<f64>]>,
    flag: &str,
) -> StudyResult<String> {
    if let Some(responses) = channel_responses(s, grid, cov, flag)? {
        let mut out = format!("input,{BODE_COLUMNS}\n");
        for (name, points) in &responses {
            for p in points {
                out.push_str(&format!("{name},{}\n", bode_row(p)));
            }
        }
        return Ok(out);
    }
    let points = frequency_response(s, grid, cov, flag)?
        .ok_or_else(|| study_err!("{flag}: the system is not a rational transfer function"))?;
    Ok(bode_csv(&points))
}
