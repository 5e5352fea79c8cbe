//! Errors that point at the model file: file, line, column and field.

use std::fmt;
use std::path::PathBuf;

/// A problem in a model description, located in its source file.
///
/// Displayed as `file:line:column: field: message`, the format compilers use, so editors and
/// terminals can jump to the spot. `line` and `column` are 1-based; 0 means "unknown".
#[derive(Debug, Clone, PartialEq)]
pub struct ModelError {
    /// The model file (as given by the caller, usually relative to the workspace).
    pub file: PathBuf,
    /// 1-based line of the offending value (0 when it cannot be located).
    pub line: usize,
    /// 1-based column of the offending value (0 when it cannot be located).
    pub column: usize,
    /// Dotted path of the field, e.g. `bodies[2].mass` or `contacts[0].profile`.
    pub field: String,
    /// What is wrong, in plain words.
    pub message: String,
}

impl fmt::Display for ModelError {
    /// `file:line:column: field: message`; without a position (line 0) `file: field:
    /// message`, and without a field `file: message`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if self.line > 0 {
            write!(f, ":{}:{}", self.line, self.column)?;
        }
        if !self.field.is_empty() {
            write!(f, ": {}", self.field)?;
        }
        write!(f, ": {}", self.message)
    }
}

impl std::error::Error for ModelError {}
