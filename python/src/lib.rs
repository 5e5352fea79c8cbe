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
//! - `build_model`: `camchain.compile`, a model file built into a library with cargo, cached,
//!   loaded behind the `Dynamics` contract;
//! - `errors`: the exceptions.

mod build_model;
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

/// A model file as generated code: checked, generated, built once with cargo into a library
/// of its own (cached, keyed by the file's text, its tables and the package's version) and
/// loaded; returns the `Model`, which runs at the built-in models' speed. `cache_dir`
/// (default `$CAMCHAIN_CACHE`, else `~/.cache/camchain`) holds the builds; `quiet=True`
/// hides cargo's progress. Raises `ModelError` for the file, `CamchainError` when cargo is
/// missing or fails, `KeyboardInterrupt` on Ctrl-C (cargo is stopped).
#[pyfunction(name = "compile")]
#[pyo3(signature = (path, cache_dir = None, quiet = false))]
fn compile_file(
    py: Python<'_>,
    path: std::path::PathBuf,
    cache_dir: Option<std::path::PathBuf>,
    quiet: bool,
) -> PyResult<model::Model> {
    use build_model::Failure;
    let built = py.detach(|| {
        let mut say = |text: &str| {
            if !quiet {
                eprint!("{text}");
            }
        };
        let mut interrupted = || Python::attach(|py| py.check_signals().err());
        build_model::compile(&path, cache_dir, quiet, &mut say, &mut interrupted)
    });
    let built = built.map_err(|failure| match failure {
        Failure::Model(location) => location.into_py_err(py),
        Failure::Interrupted(e) => e,
        Failure::NoCargo(m) | Failure::Build(m) | Failure::Load(m) | Failure::Cache(m) => {
            errors::CamchainError::new_err(m)
        }
    })?;
    if !quiet {
        let how = if built.cached { "loaded" } else { "built" };
        eprintln!("camchain: {how} {}", built.library.display());
    }
    let origin = load::Origin::Compiled {
        path,
        loaded: built.loaded,
        info: std::sync::Arc::new(built.info),
    };
    model::Model::load(py, origin)
}

/// The extension module.
#[pymodule]
fn _camchain(module: &Bound<'_, PyModule>) -> PyResult<()> {
    module.add_function(wrap_pyfunction!(models, module)?)?;
    module.add_function(wrap_pyfunction!(compile_file, module)?)?;
    module.add_class::<model::Model>()?;
    errors::register(module)?;
    module.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
