//! The RON model file: format, parsing and validation. (Being written.)

use crate::error::ModelError;
use crate::model::Model;
use std::path::Path;

/// Reads and validates a model file.
pub fn load_model(path: &Path) -> Result<Model, ModelError> {
    let source = std::fs::read_to_string(path).map_err(|e| ModelError {
        file: path.to_path_buf(),
        line: 0,
        column: 0,
        field: String::new(),
        message: format!("cannot read the file: {e}"),
    })?;
    parse_model(&source, path)
}

/// Parses and validates model source text; `file` is used in error messages and for the
/// default model name (the file stem).
pub fn parse_model(_source: &str, file: &Path) -> Result<Model, ModelError> {
    Err(ModelError {
        file: file.to_path_buf(),
        line: 0,
        column: 0,
        field: String::new(),
        message: "not implemented yet".into(),
    })
}

/// Error at a dotted field path (stub: no location yet).
pub fn field_error(
    file: &Path,
    _source: &str,
    field: &str,
    message: impl Into<String>,
) -> ModelError {
    ModelError {
        file: file.to_path_buf(),
        line: 0,
        column: 0,
        field: field.into(),
        message: message.into(),
    }
}
