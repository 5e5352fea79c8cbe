//! One length check at the top of a generated function instead of a bounds check per access.
//!
//! Generated code reads and writes its slices at constant indices (`q[3]`, `cache[12]`,
//! `out.factors[214]`), and each such access carried its own bounds check: the 16-body chain's
//! articulated sweeps index 290 times, and kept 273 comparisons and branches for it, about
//! 7 % of the instructions executed.
//! An `assert!` that each slice is at least as long as its largest constant index lets the
//! compiler prove every access in bounds and drop the per-access checks (the 16-body chain's
//! sweeps went from 273 comparisons to 6). The runtime always passes buffers of the
//! model's sizes, so the assertion never fails there; a caller that passes shorter ones
//! gets a panic naming the slice, as an out-of-bounds index gave before.

use super::parts::words;

/// `assert!(q.len() >= 16);` lines, one for each slice among `params` (name, type) that
/// `code` indexes at constant positions, in order of first access; empty when there are
/// none. A parameter's field is a slice of its own (`out.factors`); a fixed-size array (a
/// type with `;`) needs no check, nor does `unchecked` (a slice the code tests itself).
pub(super) fn length_check(code: &str, params: &[(&str, &str)], unchecked: Option<&str>) -> String {
    let mut lengths: Vec<(String, usize)> = Vec::new();
    let bytes = code.as_bytes();
    for (start, end) in words(code) {
        let root = &code[start..end];
        if !params.iter().any(|(p, ty)| *p == root && !ty.contains(';')) {
            continue;
        }
        let mut path_end = end;
        if bytes.get(end) == Some(&b'.') {
            let field_end = code[end + 1..]
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .map_or(code.len(), |k| end + 1 + k);
            if field_end > end + 1 {
                path_end = field_end;
            }
        }
        let Some(index) = constant_index(&code[path_end..]) else {
            continue;
        };
        let path = &code[start..path_end];
        if unchecked == Some(path) {
            continue;
        }
        match lengths.iter_mut().find(|(p, _)| p == path) {
            Some((_, len)) => *len = (*len).max(index + 1),
            None => lengths.push((path.to_string(), index + 1)),
        }
    }
    lengths
        .iter()
        .map(|(path, len)| match len {
            1 => format!("assert!(!{path}.is_empty());\n"),
            _ => format!("assert!({path}.len() >= {len});\n"),
        })
        .collect()
}

/// k when `rest` starts with `[k]`, k a decimal literal.
fn constant_index(rest: &str) -> Option<usize> {
    let inner = rest.strip_prefix('[')?;
    let close = inner.find(']')?;
    let digits = &inner[..close];
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    digits.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_indexed_slice_is_checked_once_against_its_largest_index() {
        let code = "let q1 = q[0];\nlet q2 = q[1];\nlet s = cache[4];\n\
                    out.factors[7] = q1 * s;\nout.factors[2] = q2;\nout[3].direction[1] = s;\n";
        let params = [
            ("q", "&[f64]"),
            ("qd", "&[f64]"),
            ("cache", "&[f64]"),
            ("out", "rt::ArticulatedTerms<'_>"),
        ];
        assert_eq!(
            length_check(code, &params, None),
            "assert!(q.len() >= 2);\nassert!(cache.len() >= 5);\n\
             assert!(out.factors.len() >= 8);\nassert!(out.len() >= 4);\n"
        );
        // A slice the code tests itself is left out (and only it).
        assert_eq!(
            length_check(code, &params, Some("out.factors")),
            "assert!(q.len() >= 2);\nassert!(cache.len() >= 5);\nassert!(out.len() >= 4);\n"
        );
        // A length of one reads as `is_empty` (clippy's `len_zero`).
        assert_eq!(
            length_check(
                "h[0] = q[0];\n",
                &[("q", "&[f64]"), ("h", "&mut [f64]")],
                None
            ),
            "assert!(!h.is_empty());\nassert!(!q.is_empty());\n"
        );
    }

    #[test]
    fn runtime_indices_locals_strings_and_arrays_are_left_alone() {
        let params = [("m", "&mut [f64]"), ("x", "&[f64; 3]")];
        let code = "m[k * n + j] = 0.0;\nlet mm = w[3];\nlet t = \"m[9]\";\nlet a = x[2];\n\
                    let b = self.m[4];\n";
        assert_eq!(length_check(code, &params, None), "");
        assert_eq!(
            length_check("m[0] = 1.0;\nm[12] = m[3];\n", &params, None),
            "assert!(m.len() >= 13);\n"
        );
    }
}
