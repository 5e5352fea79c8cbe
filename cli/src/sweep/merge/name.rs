//! The merged CSV's file name, made from the model's name in the shards' first line: that
//! name is data (a model file's `name:` may hold any character, and a shard's first line
//! any text), so it becomes one plain file name inside the output directory, never a path.

/// The most characters of the model's name kept in a file name.
const MAX_CHARS: usize = 100;

/// Characters kept besides letters and digits (of any script).
const KEPT: &str = " _-.+()[]";

/// `<model>_sweep.csv` with `model` made a plain file name: every character other than a
/// letter, a digit or one of ` _-.+()[]` (a path separator, a colon, a control character,
/// a quote, …) becomes `_`; a run of dots becomes one dot; spaces and dots are removed from
/// both ends; at most 100 characters are kept; an empty result is `model`. So `x (v2)`
/// stays `x (v2)`, `/some/dir/PWNED` becomes `_some_dir_PWNED` and `..` becomes `model`.
pub fn merged_csv(model: &str) -> String {
    format!("{}_sweep.csv", file_stem(model))
}

/// The model's name as a file name's stem (see [`merged_csv`]).
pub fn file_stem(model: &str) -> String {
    let mut plain = String::new();
    for c in model.chars() {
        let c = if c.is_alphanumeric() || KEPT.contains(c) {
            c
        } else {
            '_'
        };
        if !(c == '.' && plain.ends_with('.')) {
            plain.push(c);
        }
    }
    let cut: String = plain
        .trim_matches([' ', '.'])
        .chars()
        .take(MAX_CHARS)
        .collect();
    let stem = cut.trim_end_matches([' ', '.']);
    if stem.is_empty() {
        "model".to_string()
    } else {
        stem.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn model_names_become_plain_file_names() {
        for (model, stem) in [
            ("paper_concave", "paper_concave"),
            ("x (v2)", "x (v2)"),
            ("Nocken-Modell [3]", "Nocken-Modell [3]"),
            ("modèle", "modèle"),
            ("/some/dir/PWNED", "_some_dir_PWNED"),
            ("../../etc/passwd", "_._etc_passwd"),
            ("..", "model"),
            ("", "model"),
            (" . ", "model"),
            ("C:\\Windows\\x", "C__Windows_x"),
            ("a\u{1b}[31m\nb", "a_[31m_b"),
            ("a...b.", "a.b"),
        ] {
            assert_eq!(file_stem(model), stem, "{model:?}");
            let name = merged_csv(model);
            assert!(
                !name.contains(['/', '\\']) && !name.starts_with('.'),
                "{name}"
            );
            assert!(!name.chars().any(char::is_control), "{name}");
        }
        let long = "m".repeat(1000);
        assert_eq!(file_stem(&long).chars().count(), MAX_CHARS);
    }
}
