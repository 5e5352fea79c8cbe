//! Identifiers of the graph's variables in generated code: sanitised, unique, and never one
//! of the names the generated code gives its parameters, outputs and intermediates.

use crate::expr::{Graph, Id, Node};
use std::collections::{HashMap, HashSet};

/// Rust identifiers for variables: sanitised names, unique.
pub(super) struct Names {
    pub(super) by_var: HashMap<u32, String>,
}

impl Names {
    pub(super) fn of_vars(g: &Graph) -> Self {
        let mut taken = HashSet::new();
        let mut by_var = HashMap::new();
        for (k, name) in g.var_names().iter().enumerate() {
            let plain = sanitize(name);
            let base = if name == "t" {
                "t".to_string()
            } else if is_reserved(&plain) {
                format!("v_{plain}")
            } else {
                plain
            };
            let mut ident = base.clone();
            let mut suffix = 1;
            while !taken.insert(ident.clone()) {
                suffix += 1;
                ident = format!("{base}_{suffix}");
            }
            by_var.insert(k as u32, ident);
        }
        Names { by_var }
    }

    pub(super) fn var(&self, g: &Graph, id: Id) -> String {
        match g.node(id) {
            Node::Var(k) => self
                .by_var
                .get(&k)
                .cloned()
                .unwrap_or_else(|| format!("var{k}")),
            _ => String::from("_"),
        }
    }
}

/// Names the generated code uses for parameters, outputs and intermediates, and Rust
/// keywords: a variable with such a name gets a `v_` prefix.
fn is_reserved(name: &str) -> bool {
    const WORDS: &[&str] = &[
        "q",
        "qd",
        "qdd",
        "t",
        "m",
        "f",
        "j",
        "c",
        "h",
        "out",
        "rt",
        "applied",
        "power",
        "cache",
        "kinetic",
        "gravity",
        "spring",
        "x",
        "y",
        "slope",
        "curvature",
        "conv1",
        "conv2",
        "p0",
        "p1",
        "p2",
        "j1",
        "j2",
        "k",
        "self",
        "as",
        "break",
        "const",
        "continue",
        "crate",
        "else",
        "enum",
        "extern",
        "false",
        "fn",
        "for",
        "if",
        "impl",
        "in",
        "let",
        "loop",
        "match",
        "mod",
        "move",
        "mut",
        "pub",
        "ref",
        "return",
        "static",
        "struct",
        "super",
        "trait",
        "true",
        "type",
        "unsafe",
        "use",
        "where",
        "while",
        "async",
        "await",
        "dyn",
        "gen",
        "abstract",
        "become",
        "box",
        "do",
        "final",
        "macro",
        "override",
        "priv",
        "typeof",
        "unsized",
        "virtual",
        "yield",
        "try",
    ];
    let numbered = |p: &str| {
        name.strip_prefix(p)
            .is_some_and(|r| !r.is_empty() && r.chars().all(|c| c.is_ascii_digit()))
    };
    WORDS.contains(&name)
        || numbered("x")
        || name.starts_with("s_")
        || name.starts_with("c_")
        || name.starts_with(|c: char| c.is_ascii_digit())
        || name.starts_with("__")
}

/// True for a plain Rust identifier (a function's scalar argument).
pub(super) fn is_identifier(source: &str) -> bool {
    !source.is_empty()
        && source
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_')
        && !source.starts_with(|c: char| c.is_ascii_digit())
}

/// Lower-case ASCII identifier fragment from arbitrary text.
pub(super) fn sanitize(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect();
    if s.is_empty() { "x".into() } else { s }
}

pub(super) fn id_at(g: &Graph, i: usize) -> Id {
    // Ids are dense indices; rebuild one from its index through the graph's node list.
    g.id_from_index(i)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn variables_get_sanitised_unique_names_that_avoid_the_generated_ones() {
        let mut g = Graph::new();
        let ids = ["Link 1", "link_1", "m", "t", "s_q1", "2x"].map(|n| g.var(n));
        let names = Names::of_vars(&g);
        let got: Vec<String> = ids.iter().map(|&id| names.var(&g, id)).collect();
        assert_eq!(got, ["link_1", "link_1_2", "v_m", "t", "v_s_q1", "v_2x"]);
    }

    #[test]
    fn identifiers_and_sanitising() {
        assert_eq!(sanitize("Cam-Angle"), "cam_angle");
        assert_eq!(sanitize(""), "x");
        assert!(is_identifier("cache"));
        assert!(!is_identifier("cache[3]"));
        assert!(!is_identifier("3x"));
        assert!(!is_identifier(""));
    }
}
