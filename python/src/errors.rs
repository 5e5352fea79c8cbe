//! The exceptions of the `camchain` package and the conversions into them.
//!
//! - `camchain.CamchainError` (a `RuntimeError`): the base of the package's own errors;
//! - `camchain.ModelError` (also a `ValueError`): a problem in a model file or in a value given
//!   for one of its fields (a parameter), located like the build's errors: its `file`,
//!   `line`, `column` (1-based, 0 when unknown), `field` (`bodies[2].mass`) and `message`;
//! - `camchain.SimulationError`: a run that failed, with its `time` (s, or None) and the
//!   `result` computed until then;
//! - `ValueError` for a bad option (`rtol=-1`, an unknown coordinate), naming the option.
//!
//! A run interrupted by Ctrl-C raises `KeyboardInterrupt` whose `result` holds what was
//! computed until then.

use camchain_codegen::ModelError as Located;
use camchain_runtime::ParameterError;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;

pyo3::create_exception!(
    camchain,
    CamchainError,
    PyRuntimeError,
    "The base of camchain's own errors."
);
pyo3::create_exception!(
    camchain,
    SimulationError,
    CamchainError,
    "A run that failed: `time` (s) where it stopped, `result` what it computed until then."
);

/// The located error's fields, whichever way it arrived (the file's validation, or a
/// parameter value refused by generated code).
pub struct Location {
    pub file: String,
    pub line: usize,
    pub column: usize,
    pub field: String,
    pub message: String,
}

impl From<Located> for Location {
    fn from(e: Located) -> Self {
        Location {
            file: e.file.display().to_string(),
            line: e.line,
            column: e.column,
            field: e.field,
            message: e.message,
        }
    }
}

impl From<ParameterError> for Location {
    fn from(e: ParameterError) -> Self {
        Location {
            file: e.file,
            line: e.line,
            column: e.column,
            field: e.field,
            message: e.message,
        }
    }
}

impl Location {
    /// Not in the file's content: a file that cannot be read.
    pub fn unlocated(file: &str, message: String) -> Self {
        Location {
            file: file.to_string(),
            line: 0,
            column: 0,
            field: String::new(),
            message,
        }
    }

    /// `file:line:column: field: message`, as the build and the command line print it (the
    /// model error's own format), on one line.
    pub fn text(&self) -> String {
        Located {
            file: self.file.clone().into(),
            line: self.line,
            column: self.column,
            field: self.field.clone(),
            message: self.message.replace('\n', " "),
        }
        .to_string()
    }

    /// The `camchain.ModelError` it raises (the class is defined in Python, `camchain/_errors.py`,
    /// as a subclass of both `CamchainError` and `ValueError`).
    pub fn into_py_err(self, py: Python<'_>) -> PyErr {
        let text = self.text();
        let made = (|| -> PyResult<PyErr> {
            let class = py.import("camchain._errors")?.getattr("ModelError")?;
            let value = class.call1((
                text.clone(),
                self.file,
                self.line,
                self.column,
                self.field,
                self.message,
            ))?;
            Ok(PyErr::from_value(value))
        })();
        made.unwrap_or_else(|e| e)
    }
}

/// The command line's errors in Python's terms: a usage error is a `ValueError`, any other
/// failure a `CamchainError`; the CLI's option names become the method's arguments
/// (`--speed` → `speed`).
pub fn cli_error(e: camchain_cli::CliError) -> PyErr {
    let mut text = e.to_string().replace("--param ", "params: ");
    for option in ["jobs", "samples", "speed", "contact", "turns"] {
        text = text.replace(&format!("--{option}"), option);
    }
    match e {
        camchain_cli::CliError::Usage(_) => PyValueError::new_err(text),
        _ => CamchainError::new_err(text),
    }
}

/// A bad option of a call: a `ValueError` naming it.
pub fn bad_option(option: &str, message: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(format!("{option}: {message}"))
}

/// Registers the exception classes defined in Rust.
pub fn register(module: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = module.py();
    module.add("CamchainError", py.get_type::<CamchainError>())?;
    module.add("SimulationError", py.get_type::<SimulationError>())?;
    Ok(())
}
