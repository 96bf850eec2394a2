//! Validation of a fitted model on a record: how much of the data's variation the model's
//! expected samples explain ([`fit_percent`]).

mod fit_percent;

pub use fit_percent::fit_percent;
