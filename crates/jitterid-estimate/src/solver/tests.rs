//! Unit tests of the optimisation layer.
