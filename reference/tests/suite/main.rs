//! The integration tests of `camchain-reference`, in one test binary: each file of `tests/suite/` is
//! a module here (it used to be a binary of its own; one binary links the crate and its
//! dependencies once). `cargo test -p camchain-reference --test suite NAME` runs the tests whose path
//! contains NAME, e.g. a module's name.

mod assembly;
mod bad_models;
mod contacts;
mod layers;
mod random_models;
mod settings_ranges;
mod symbolic_vs_numeric;
mod tables;
