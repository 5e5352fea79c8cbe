//! The integration tests of `camchain-models`, in one test binary: each file of `tests/suite/` is
//! a module here (it used to be a binary of its own; one binary links the crate and its
//! dependencies once). `cargo test -p camchain-models --test suite NAME` runs the tests whose path
//! contains NAME, e.g. a module's name.

mod andrews;
mod backlash;
mod balls;
mod cams;
#[path = "../common/mod.rs"]
mod common;
mod contacts_compiled;
#[path = "../support/cycloidal.rs"]
mod cycloidal;
mod designs;
#[path = "../support/eccentric.rs"]
mod eccentric;
mod faces;
mod formulations;
mod generated_vs_numeric;
mod grids;
mod integrators;
mod loops;
mod metrics;
mod mushroom;
mod parameters;
mod random_compiled;
mod simulation;
mod surfaces;
mod tables;
mod unilateral;
