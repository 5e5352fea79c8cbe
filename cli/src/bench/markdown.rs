//! Sections of the benchmark report, each between `<!-- begin NAME -->` and
//! `<!-- end NAME -->`, so that every benchmark rewrites only its own part of the file.

use crate::CliError;
use std::path::Path;

/// Replaces the section `name` of the report at `path` by `body` (appending it when the file
/// or the section does not exist yet), through `output::write_file` (a temporary file and a
/// rename for a regular file). A FIFO or device is not read: it gets the section alone.
pub fn replace_section(path: &Path, name: &str, body: &str) -> Result<(), CliError> {
    let old = if crate::output::is_special(path) {
        String::new()
    } else {
        match std::fs::read_to_string(path) {
            Ok(text) => text,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => String::new(),
            Err(e) => return Err(CliError::Failed(format!("{}: {e}", path.display()))),
        }
    };
    let new = with_section(&old, name, body);
    crate::output::write_bytes(path, new.as_bytes()).map_err(CliError::Failed)
}

/// `text` with the section `name` replaced by (or extended with) `body`.
fn with_section(text: &str, name: &str, body: &str) -> String {
    let begin = format!("<!-- begin {name} -->");
    let end = format!("<!-- end {name} -->");
    let block = format!("{begin}\n{}\n{end}", body.trim_end());
    match (text.find(&begin), text.find(&end)) {
        (Some(b), Some(e)) if e > b => {
            format!("{}{block}{}", &text[..b], &text[e + end.len()..])
        }
        _ => {
            let separator = if text.is_empty() || text.ends_with("\n\n") {
                ""
            } else if text.ends_with('\n') {
                "\n"
            } else {
                "\n\n"
            };
            format!("{text}{separator}{block}\n")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::with_section;

    #[test]
    fn sections_are_replaced_in_place_or_appended() {
        let first = with_section("# Title\n", "a", "one");
        assert_eq!(first, "# Title\n\n<!-- begin a -->\none\n<!-- end a -->\n");
        let second = with_section(&first, "b", "two");
        let replaced = with_section(&second, "a", "uno");
        assert!(replaced.starts_with("# Title\n\n<!-- begin a -->\nuno\n<!-- end a -->\n"));
        assert!(replaced.ends_with("<!-- begin b -->\ntwo\n<!-- end b -->\n"));
    }
}
