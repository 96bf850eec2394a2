//! Reproduction case of the robustness issue: `starts`.

use crate::Options;

pub fn starts(_o: &Options) -> Result<(), String> {
    Err("starts is not implemented yet".into())
}
