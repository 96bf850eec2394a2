//! Reproduction cases of the maximum-likelihood issue: `table1-ml` and `sine`.

use crate::Options;

pub fn table1_ml(_o: &Options) -> Result<(), String> {
    Err("table1-ml is not implemented yet".into())
}

pub fn sine(_o: &Options) -> Result<(), String> {
    Err("sine is not implemented yet".into())
}
