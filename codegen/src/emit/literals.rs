//! Values written as Rust literals: floats that read back to the same `f64`, lists of them,
//! raw strings, and the `allow` attributes generated items carry.

/// `text` as a raw string literal, with enough `#` that it reads as written.
pub(super) fn raw_string(text: &str) -> String {
    let mut hashes = String::from("#");
    while text.contains(&format!("\"{hashes}")) {
        hashes.push('#');
    }
    format!("r{hashes}\"{text}\"{hashes}")
}

/// A program uses what it needs of the generated API (in a binary crate, unused public
/// items of a private module would warn).
pub(super) const ALLOW_UNUSED: &str = "#[allow(dead_code)]";

/// Literals come verbatim from the model file (e.g. −π/2 written out in full): the lints
/// about them do not apply to generated code.
pub(super) const ALLOW_LITERALS: &str =
    "#[allow(clippy::approx_constant, clippy::excessive_precision)]";

/// A list of float literals, `[a, b, …]`.
pub(super) fn float_list(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|&x| lit(x)).collect();
    format!("[{}]", items.join(", "))
}

/// A float literal that reads back to the same f64.
pub(super) fn lit(v: f64) -> String {
    let s = format!("{v:?}");
    if s.contains('.') || s.contains('e') || s.contains("inf") || s.contains("NaN") {
        s
    } else {
        format!("{s}.0")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn float_literals_read_back_as_floats() {
        assert_eq!(lit(1.0), "1.0");
        assert_eq!(lit(-2.5), "-2.5");
        assert_eq!(lit(1e-20), "1e-20");
        assert_eq!(lit(f64::INFINITY), "inf");
        assert_eq!(float_list(&[0.0, 3.0]), "[0.0, 3.0]");
        assert_eq!(float_list(&[]), "[]");
    }

    #[test]
    fn raw_strings_take_more_hashes_than_the_text_holds() {
        assert_eq!(raw_string("a"), "r#\"a\"#");
        assert_eq!(raw_string("say \"#hi\""), "r##\"say \"#hi\"\"##");
    }
}
