//! Checks of single fields shared by every part of the model: identifiers, finite, positive
//! and unit values, name lookups and unique names.

use super::super::Locator;
use super::{Checked, KEYWORDS};
use camchain_runtime::parameters::checks;
use std::collections::HashMap;

/// True for an ASCII Rust identifier that is not a keyword.
pub(crate) fn is_identifier(name: &str) -> bool {
    let mut chars = name.chars();
    let starts_well = chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_');
    starts_well && chars.all(|c| c.is_ascii_alphanumeric() || c == '_') && !KEYWORDS.contains(&name)
}

/// Names end up as Rust identifiers in the generated code.
pub(super) fn identifier(at: &Locator, field: &str, name: &str, what: &str) -> Checked<()> {
    if is_identifier(name) {
        Ok(())
    } else {
        Err(at.error(
            field,
            format!(
                "{what} `{name}` is not a valid Rust identifier (ASCII letters, digits and `_`, \
                 not starting with a digit, not a keyword)"
            ),
        ))
    }
}

pub(super) fn finite(at: &Locator, field: &str, value: f64) -> Checked<f64> {
    checks::finite(value).map_err(|m| at.error(field, m))
}

pub(super) fn finite3(at: &Locator, field: &str, v: [f64; 3]) -> Checked<[f64; 3]> {
    for (k, &c) in v.iter().enumerate() {
        finite(at, &format!("{field}[{k}]"), c)?;
    }
    Ok(v)
}

pub(super) fn positive(at: &Locator, field: &str, what: &str, value: f64) -> Checked<f64> {
    checks::positive(what, value).map_err(|m| at.error(field, m))
}

pub(super) fn non_negative(at: &Locator, field: &str, what: &str, value: f64) -> Checked<f64> {
    checks::non_negative(what, value).map_err(|m| at.error(field, m))
}

/// `v / |v|`, or `None` for a zero or non-finite vector.
pub(super) fn unit(v: [f64; 3]) -> Option<[f64; 3]> {
    let norm = v.iter().map(|c| c * c).sum::<f64>().sqrt();
    (norm.is_finite() && norm > 0.0).then(|| v.map(|c| c / norm))
}

pub(super) fn unit_vector(at: &Locator, field: &str, what: &str, v: [f64; 3]) -> Checked<[f64; 3]> {
    finite3(at, field, v)?;
    unit(v).ok_or_else(|| {
        at.error(
            field,
            format!(
                "{what} must be a non-zero vector, got ({}, {}, {})",
                v[0], v[1], v[2]
            ),
        )
    })
}

/// Finds `name` in `names` (a name → index map) or explains what was expected.
pub(super) fn lookup(
    at: &Locator,
    field: &str,
    index: &HashMap<&str, usize>,
    name: &str,
    what: &str,
) -> Checked<usize> {
    index
        .get(name)
        .copied()
        .ok_or_else(|| at.error(field, unknown(index, name, what)))
}

/// "unknown {what} `{name}`; known: …" with the known names sorted.
pub(super) fn unknown(index: &HashMap<&str, usize>, name: &str, what: &str) -> String {
    let mut known: Vec<&str> = index.keys().copied().collect();
    known.sort_unstable();
    format!("unknown {what} `{name}`; known: {}", known.join(", "))
}

/// Indexes `names`, reporting the second occurrence of a repeated name.
pub(super) fn unique_names<'n>(
    at: &Locator,
    names: impl Iterator<Item = (String, &'n str)>,
    what: &str,
) -> Checked<HashMap<&'n str, usize>> {
    let mut index = HashMap::new();
    for (i, (field, name)) in names.enumerate() {
        identifier(at, &field, name, what)?;
        if index.insert(name, i).is_some() {
            return Err(at.error(&field, format!("duplicate {what} `{name}`")));
        }
    }
    Ok(index)
}

/// A polar profile is periodic: r(θ + 2π) = r(θ) (a disc cam closes on itself), checked at
/// 16 angles to 1e-9 of the radius.
pub(super) fn closes(at: &Locator, field: &str, r: &crate::profile::Scalar) -> Checked<()> {
    for k in 0..16 {
        let theta = std::f64::consts::TAU * k as f64 / 16.0;
        let (a, b) = (r.eval(theta), r.eval(theta + std::f64::consts::TAU));
        if (a - b).abs() > 1e-9 * a.abs().max(b.abs()).max(1e-3) {
            return Err(at.error(
                field,
                format!(
                    "a polar profile must close on itself, r(theta + 2π) = r(theta), but \
                     r({theta:.6}) = {a:e} m and r({:.6}) = {b:e} m",
                    theta + std::f64::consts::TAU
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_vectors_and_their_refusals() {
        assert_eq!(unit([0.0, 3.0, 4.0]), Some([0.0, 0.6, 0.8]));
        assert_eq!(unit([0.0; 3]), None);
        assert_eq!(unit([f64::NAN, 1.0, 0.0]), None);
    }

    #[test]
    fn an_unknown_name_lists_the_known_ones_sorted() {
        let index: HashMap<&str, usize> = [("wheel", 0), ("arm", 1)].into_iter().collect();
        assert_eq!(
            unknown(&index, "cam", "body"),
            "unknown body `cam`; known: arm, wheel"
        );
        assert!(is_identifier("link_2"));
        assert!(!is_identifier("2link"));
    }
}
