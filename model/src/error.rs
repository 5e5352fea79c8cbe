//! Errors that point at the model file: file, line, column and field.

use std::fmt;
use std::path::PathBuf;

/// A problem in a model description, located in its source file.
///
/// Displayed as `file:line:column: field: message`, the format compilers use, so editors and
/// terminals can jump to the spot. `line` and `column` are 1-based; 0 means "unknown".
#[derive(Clone, PartialEq)]
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

impl fmt::Debug for ModelError {
    /// The one-line message of `Display`, so that a `main` returning
    /// `Result<(), Box<dyn std::error::Error>>` prints it as it is after `Error: `. The
    /// fields stay public for a program that needs them.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }
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

#[cfg(test)]
mod tests {
    use super::ModelError;

    /// A build script's `main` returning `Result<(), Box<dyn Error>>` prints the error's
    /// `Debug` after `Error: `: it must be the located line, not the struct's fields.
    #[test]
    fn model_error_debug_is_the_located_message() {
        let error = ModelError {
            file: "models/follower.ron".into(),
            line: 12,
            column: 5,
            field: "bodies[2].mass".into(),
            message: "must be positive".into(),
        };
        let main = || -> Result<(), Box<dyn std::error::Error>> { Err(error)? };
        let printed = match main() {
            Err(boxed) => format!("{boxed:?}"),
            Ok(()) => String::new(),
        };
        assert_eq!(
            printed,
            "models/follower.ron:12:5: bodies[2].mass: must be positive"
        );
    }
}
