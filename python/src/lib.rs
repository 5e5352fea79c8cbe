//! camchain-python: the extension module `camchain._camchain` of the Python package
//! `camchain` (`python/camchain/`, which re-exports it with the pure-Python parts: the
//! result class, the exceptions' Python side).
//!
//! Modules:
//! - `load`: which model a name or a file is, its dynamics with given parameter values;
//! - `model`: the `Model` class, what a model declares, `simulate`;
//! - `run`: one run with the GIL released, its samples kept as columns, Ctrl-C;
//! - `summary`: a run's summary as a dict;
//! - `sweep`: `Model.sweep`, the command line's sweep with its rows as arrays;
//! - `cam`: `Model.cam`, the cam designer's report as numbers and arrays;
//! - `calls`: the generated functions one call each (`equations`, `jacobian`, `rhs`, …);
//! - `errors`: the exceptions.

mod calls;
mod cam;
mod errors;
mod load;
mod model;
mod run;
mod summary;
mod sweep;

use pyo3::prelude::*;

/// The names of the built-in models, whose generated code the package carries.
#[pyfunction]
fn models() -> Vec<&'static str> {
    load::names()
}

/// The extension module.
#[pymodule]
fn _camchain(module: &Bound<'_, PyModule>) -> PyResult<()> {
    module.add_function(wrap_pyfunction!(models, module)?)?;
    module.add_class::<model::Model>()?;
    errors::register(module)?;
    module.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
