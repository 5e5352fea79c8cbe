//! camchain-model: the model file and the validated model, shared by the code generator
//! (`camchain-codegen`) and the numeric reference (`camchain-reference`), so that a program
//! running model files on the reference links no emitter.
//!
//! Module map:
//! - [`schema`]: the RON file format, parsing and validation with file/line/field errors.
//! - [`model`]: the validated model (bodies, joints, markers, contacts, loops, initial state,
//!   settings, run-time parameters).
//! - [`profile`]: one-variable expressions (cam profiles, drives, joint loads) in Rust
//!   syntax, parsed by the crate's own parser, and functions given by data
//!   ([`profile::Tabulated`]).
//! - [`design`]: cams designed from a follower's motion law (the envelope construction).
//! - [`jet`]: second-order forward-mode differentiation of those expressions.
//! - [`samples`]: a profile's polar radius and curvature along its range, for the checks that
//!   a follower can follow it.
//! - [`error`]: [`ModelError`], located at the file's line, column and field.

pub mod design;
pub mod error;
pub mod jet;
pub mod model;
pub mod profile;
pub mod samples;
pub mod schema;

pub use error::ModelError;
pub use model::{Model, ParameterMode};

use std::path::Path;

/// Reads a model file of at most [`schema::MAX_FILE_BYTES`] ([`schema::read_text`]: a longer
/// regular file is refused unread, a device without end once it has given that much); a
/// failure is a [`ModelError`] on `display` (line 0: not located).
pub fn read_model_file(path: &Path, display: &Path) -> Result<String, ModelError> {
    schema::read_text(path).map_err(|e| ModelError {
        file: display.to_path_buf(),
        line: 0,
        column: 0,
        field: String::new(),
        message: format!("cannot read the file: {e}"),
    })
}
