//! The integration tests of `camchain-codegen`, in one test binary: each file of `tests/suite/` is
//! a module here (it used to be a binary of its own; one binary links the crate and its
//! dependencies once). `cargo test -p camchain-codegen --test suite NAME` runs the tests whose path
//! contains NAME, e.g. a module's name.

#[path = "../common/chain.rs"]
mod chain;
#[path = "../common/mod.rs"]
mod common;
mod contacts;
mod deep_chains;
mod derivation;
mod emit;
mod features;
mod file_sizes;
mod fuzz;
mod linear_pass;
mod parameters;
mod scaling;
#[path = "../common/scenes.rs"]
mod scenes;
mod tables;
mod yardstick;
