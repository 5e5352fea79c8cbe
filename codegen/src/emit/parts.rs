//! A large generated method's body moved into a module of its own, the method calling it.
//!
//! Why: rustc compiles each module as its own codegen unit and LLVM optimises the units in
//! parallel, but the generated module was one unit: a long chain's functions (the 64-body
//! chain's articulated sweeps alone are 30 000 operations, 17 000 lines) were optimised one
//! after the other on one core. With its large bodies in modules of their own, the build
//! uses every core. The body is moved whole, so its operations, their order and their
//! values are unchanged; the call costs one jump. (Cutting one body into several functions
//! would spread it further, but the values crossing each cut go through memory: cut in
//! four, the 64-body chain's sweeps passed 2900 values and its step took 15 % longer.)

use super::literals::ALLOW_LITERALS;

/// Methods of at least this many operations get a module of their own (the 64-body chain's
/// `articulated_terms` has 30 000, its `mass_times` 5500; no built-in model has a function
/// of 3000).
pub(super) const OWN_MODULE_OPS: usize = 4000;

/// The method `function`'s body moved to `mod {function}_body`: returns the method's new body
/// (the call) and the module. `params` are the method's parameters after `&self`, as
/// (name, type, whether the body reads it); `ret` its return type (` -> T` or empty); `body`
/// the statements, which may read the receiver as `self`.
pub(super) fn moved(
    function: &str,
    params: &[(String, &str, bool)],
    ret: &str,
    body: &str,
) -> (String, String) {
    let body = receiver_renamed(body);
    let this = if identifiers(&body).iter().any(|w| w == "this") {
        "this"
    } else {
        "_this"
    };
    let mut signature = vec![format!("{this}: &Model")];
    let mut args = vec!["self".to_string()];
    for (name, ty, read) in params {
        let shown = if *read {
            name.clone()
        } else {
            format!("_{name}")
        };
        signature.push(format!("{shown}: {ty}"));
        args.push(name.clone());
    }
    let module = format!("{function}_body");
    let item = format!(
        "{ALLOW_LITERALS}\n#[allow(clippy::too_many_arguments)]\nmod {module} {{\n\
         use super::*;\n\
         /// The body of `Model::{function}`, in a module of its own so that it is compiled in \
         parallel with the rest of the model.\n\
         #[inline(never)]\n\
         pub(super) fn run({}){ret} {{\n{body}}}\n}}\n",
        signature.join(", ")
    );
    (format!("{module}::run({})\n", args.join(", ")), item)
}

/// `text` with the receiver `self` renamed `this`: as a word of its own, not a field or a
/// path segment, outside string literals.
fn receiver_renamed(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    for (start, end) in words(text) {
        if &text[start..end] == "self" {
            let offset = text.len() - rest.len();
            out.push_str(&text[offset..start]);
            out.push_str("this");
            rest = &text[end..];
        }
    }
    out.push_str(rest);
    out
}

/// The identifiers `text` reads: words not after `.` (fields, methods) or `::` (paths), nor
/// inside string literals; numbers skipped whole (`1e-3`, `0.5_f64`).
fn identifiers(text: &str) -> Vec<String> {
    words(text)
        .into_iter()
        .map(|(start, end)| text[start..end].to_string())
        .collect()
}

/// The byte ranges of the words [`identifiers`] returns.
pub(super) fn words(text: &str) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let bytes = text.as_bytes();
    let mut i = 0;
    let mut previous = b' ';
    while i < bytes.len() {
        let c = bytes[i];
        if c == b'"' {
            i += 1;
            while i < bytes.len() && bytes[i] != b'"' {
                i += if bytes[i] == b'\\' { 2 } else { 1 };
            }
            i += 1;
            previous = b'"';
            continue;
        }
        if c.is_ascii_digit() {
            while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                i += 1;
            }
            previous = b'0';
            continue;
        }
        if c.is_ascii_alphabetic() || c == b'_' {
            let start = i;
            while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                i += 1;
            }
            let path = start >= 2 && &bytes[start - 2..start] == b"::";
            if previous != b'.' && !path {
                out.push((start, i));
            }
            previous = b'a';
            continue;
        }
        if !c.is_ascii_whitespace() {
            previous = c;
        }
        i += 1;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identifiers_skip_fields_methods_paths_numbers_and_strings() {
        let words = identifiers(
            "a_1 * self.derived.k + x.sin() - 1e-3 * \"y z\" + f(b, 0.5_f64) + rt::g(c) + S { d: e }",
        );
        assert_eq!(
            words,
            ["a_1", "self", "x", "f", "b", "rt", "c", "S", "d", "e"]
        );
    }

    #[test]
    fn the_receiver_is_renamed_where_it_is_a_word() {
        let text = "let k = self.derived.k * myself + x.self_ + \"self\";\nself.mass_times(q);";
        assert_eq!(
            receiver_renamed(text),
            "let k = this.derived.k * myself + x.self_ + \"self\";\nthis.mass_times(q);"
        );
    }

    #[test]
    fn a_moved_body_is_called_with_every_argument() {
        let params = vec![
            ("q".to_string(), "&[f64]", true),
            ("qd".to_string(), "&[f64]", false),
            ("out".to_string(), "&mut [f64]", true),
        ];
        let (call, item) = moved("f", &params, "", "out[0] = q[0] * self.derived.k;\n");
        assert_eq!(call, "f_body::run(self, q, qd, out)\n");
        assert!(item.contains("mod f_body {\nuse super::*;"), "{item}");
        assert!(
            item.contains("pub(super) fn run(this: &Model, q: &[f64], _qd: &[f64], out: &mut [f64]) {\nout[0] = q[0] * this.derived.k;\n}"),
            "{item}"
        );
        // A body that does not read the model names it `_this`.
        let (_, item) = moved("g", &params[..1], " -> f64", "q[0]\n");
        assert!(
            item.contains("fn run(_this: &Model, q: &[f64]) -> f64 {\nq[0]\n}"),
            "{item}"
        );
    }
}
