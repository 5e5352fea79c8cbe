//! Rendering of the generated module: the text parsed by `syn` and printed by `prettyplease`,
//! then the section markers the emitter left as macro statements turned back into `//`
//! comments (a comment does not survive a syntax tree).

use std::fmt::Write;

/// Prefix of the statements that become section comments after formatting.
pub(super) const SECTION_MACRO: &str = "__section__";

/// Turns the section marker statements back into comments after formatting (prettyplease
/// may have wrapped a long marker over several lines).
pub(super) fn restore_comments(code: &str) -> String {
    let marker = format!("{SECTION_MACRO}!(");
    let mut out = String::with_capacity(code.len());
    let mut pending: Option<(String, String)> = None;
    for line in code.lines() {
        let trimmed = line.trim_start();
        if let Some((indent, mut text)) = pending.take() {
            text.push_str(trimmed);
            if trimmed.ends_with(");") {
                push_comment(&mut out, &indent, &text);
            } else {
                pending = Some((indent, text));
            }
            continue;
        }
        if let Some(rest) = trimmed.strip_prefix(&marker) {
            let indent = line[..line.len() - trimmed.len()].to_string();
            if rest.ends_with(");") {
                push_comment(&mut out, &indent, rest);
            } else {
                pending = Some((indent, rest.to_string()));
            }
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

/// Writes `// text` for a marker's argument `"text");`.
pub(super) fn push_comment(out: &mut String, indent: &str, argument: &str) {
    let text = argument
        .trim_end_matches(';')
        .trim_end_matches(')')
        .trim()
        .trim_matches('"');
    let _ = writeln!(out, "{indent}// {text}");
}

/// The generated module `file` formatted: parsed, printed by prettyplease, its section
/// markers turned into comments. An error if it does not parse (a bug of the emitter).
#[cfg(feature = "format")]
pub(super) fn format(file: &str) -> Result<String, String> {
    let syntax =
        syn::parse_file(file).map_err(|e| format!("generated code does not parse: {e}"))?;
    Ok(restore_comments(&prettyplease::unparse(&syntax)))
}

/// Without the `format` feature: the emitter's text as it is, its section markers turned into
/// comments (the emitter writes one statement per line).
#[cfg(not(feature = "format"))]
pub(super) fn format(file: &str) -> Result<String, String> {
    Ok(restore_comments(file))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn section_markers_become_comments_even_when_wrapped() {
        let code = "fn f() {\n    __section__!(\"body arm\");\n    let a = 1;\n    \
                    __section__!(\n        \"a long one\"\n    );\n}\n";
        assert_eq!(
            restore_comments(code),
            "fn f() {\n    // body arm\n    let a = 1;\n    // a long one\n}\n"
        );
    }

    #[cfg(feature = "format")]
    #[test]
    fn formatting_prints_with_prettyplease_and_refuses_what_does_not_parse() {
        assert_eq!(
            format("fn f(){__section__!(\"x\");let a=1;}").as_deref(),
            Ok("fn f() {\n    // x\n    let a = 1;\n}\n")
        );
        assert!(format("fn (").is_err_and(|e| e.starts_with("generated code does not parse")));
    }
}
