//! Validation of a fitted model on a record: how much of the data's variation the model's
//! expected samples explain ([`fit_percent`], [`compare`]), whether its standardised residuals
//! are white and unrelated to the input ([`standardized_residuals`], [`whiteness`],
//! [`cross_correlation`], with portmanteau statistics and χ² p-values on the residuals
//! projected off the fitted parameters' directions: [`residual_projection`]), and its frequency and step responses with delta-method confidence
//! bands ([`bode`], [`step_response`]; with an input delay [`delayed_bode`],
//! [`delayed_step_response`]) on log-spaced grids ([`log_spaced`]). A validation
//! record's own initial state, for a model with one, comes from [`fit_initial_state`], and
//! [`on_record`] carries a fitted model over to another record with its own input.
//! `docs/method.md` ("Validation") states the definitions.

mod compare;
mod correlation;
mod delayed;
mod fit_percent;
mod initial;
mod log_grid;
mod portmanteau;
mod residuals;
mod response;

pub use compare::{compare, Comparison};
pub use correlation::{
    allowed_outside, cross_correlation, default_max_lag, whiteness, CorrelationTest,
    DEFAULT_MAX_LAG, LAG_ALPHA, TEST_ALPHA, Z_99,
};
pub use delayed::{delayed_bode, delayed_step_response};
pub use fit_percent::fit_percent;
pub use initial::{fit_initial_state, on_record, INITIAL_PREFIX};
pub use log_grid::log_spaced;
pub use portmanteau::{
    check_level, chi2_p_value, input_statistic, ljung_box, project_out, residual_projection,
    DEFAULT_LEVEL,
};
pub use residuals::{standardized_residuals, Residuals};
pub use response::{
    bode, check_covariance, delta_method_variance, log_response_gradient, step_response,
    step_value_and_gradient, BodePoint, StepPoint, BAND_SIGMAS,
};
