//! Plain forms of a linear model for export and display: transfer-function coefficients
//! ([`TfForm`]), zeros, poles and gain ([`ZpkForm`]) and a state-space realisation
//! ([`StateSpace`]), with conversions between them.
//!
//! These are descriptions, not parameterisations: they carry no parameter derivatives and put
//! no condition on the poles (repeated, marginal or unstable poles convert like any other), so
//! any fitted [`RationalModel`](crate::RationalModel) can be taken out of the library in the
//! form a user's tools expect. `s` is the Laplace variable in rad/s, so a frequency response
//! at `f` Hz is the value at `s = i2πf`.
//!
//! ```
//! use jitterid_signal::forms::TfForm;
//! // G(s) = (0.2 s + 0.1) / (s² + 0.5 s + 0.1525)
//! let tf = TfForm::new(&[0.2, 0.1], &[1.0, 0.5, 0.1525]).unwrap();
//! let zpk = tf.to_zpk().unwrap();
//! assert!((zpk.gain() - 0.2).abs() < 1e-15);
//! let ss = tf.to_state_space();
//! let back = ss.to_tf().unwrap();
//! assert!((back.num()[1] - 0.1).abs() < 1e-12);
//! println!("{tf}\n{zpk}\n{ss}");
//! ```

mod display;
mod state_space;
mod tf;
mod zpk;

pub use state_space::StateSpace;
pub use tf::TfForm;
pub use zpk::ZpkForm;
