//! The integration tests of `camchain-cli`, in one test binary: each file of `tests/suite/` is
//! a module here (it used to be a binary of its own; one binary links the crate and its
//! dependencies once). `cargo test -p camchain-cli --test suite NAME` runs the tests whose path
//! contains NAME, e.g. a module's name.

mod cam;
mod cli;
#[path = "../common/mod.rs"]
mod common;
mod destinations;
mod fmu;
mod merge;
mod repartition;
mod signals;
mod slurm;
mod special_files;
mod streaming;
mod stress;
mod sweep;
mod trust;
