//! The standalone entry points (`mass_matrix`, `equations`, `constraint`, …) written as calls
//! of the fused pair `position_terms`/`velocity_terms`, with stack scratch for what the pair
//! computes and the entry point does not return: one template, driven by a table of what
//! each entry point takes and returns.

use crate::model::Model;
use std::fmt::Write;

/// An entry point the fused pair can stand for.
struct EntryPoint {
    /// The `Dynamics` method.
    name: &'static str,
    /// Whether it takes the time `t` (the others evaluate at t = 0).
    time: bool,
    /// Whether it takes the rates `qd` (the others evaluate at q̇ = 0).
    rates: bool,
    /// The arrays it returns, in the order of its parameters.
    returns: &'static [&'static str],
}

/// Every entry point that can be a call of the fused pair.
const ENTRY_POINTS: [EntryPoint; 8] = [
    entry("mass_matrix", false, false, &["m"]),
    entry("inertial_forces", false, true, &["f"]),
    entry("applied_forces", true, true, &["applied"]),
    entry("equations", true, true, &["m", "f", "applied"]),
    entry("constraint", false, false, &["h"]),
    entry("constraint_jacobian", false, false, &["j"]),
    entry("constraint_bias", false, true, &["c"]),
    entry("constraint_terms", false, true, &["j", "c"]),
];

const fn entry(
    name: &'static str,
    time: bool,
    rates: bool,
    returns: &'static [&'static str],
) -> EntryPoint {
    EntryPoint {
        name,
        time,
        rates,
        returns,
    }
}

/// The arrays of the velocity level, in `rt::VelocityTerms` order.
const VELOCITY: [&str; 4] = ["m", "f", "applied", "c"];

/// The body of `name` as a call of the fused pair (whose cache has `cache_len` entries),
/// with stack scratch for the outputs it does not return; `None` for the functions that keep
/// their own expressions. The returned arrays of `cleared` (`m`, `j`: those the pair writes
/// within their rows' extents only) are zeroed first.
pub(super) fn wrapper(
    model: &Model,
    cache_len: usize,
    name: &str,
    cleared: &[&str],
) -> Option<String> {
    let entry = ENTRY_POINTS.iter().find(|e| e.name == name)?;
    let (n, nc) = (model.n(), model.n_constraints());
    let length = |array: &str| match array {
        "m" => n * n,
        "j" => nc * n,
        "h" | "c" => nc,
        _ => n,
    };
    let returned = |array: &str| entry.returns.contains(&array);
    let mut params = vec!["&self".to_string()];
    if entry.time {
        params.push("t: f64".into());
    }
    params.push("q: &[f64]".into());
    if entry.rates {
        params.push("qd: &[f64]".into());
    }
    params.extend(entry.returns.iter().map(|a| format!("{a}: &mut [f64]")));
    let mut body = format!(
        "/// Calls the fused pair `position_terms`/`velocity_terms` (large model: every \
         expression is compiled once).\nfn {name}({}) {{\nlet mut cache = [0.0; {cache_len}];\n",
        params.join(", ")
    );
    for array in entry.returns.iter().filter(|a| cleared.contains(a)) {
        let _ = writeln!(body, "{array}.fill(0.0);");
    }
    let scratch = |body: &mut String, array: &str| {
        if !returned(array) {
            let _ = writeln!(body, "let {array} = &mut [0.0; {}];", length(array));
        }
    };
    scratch(&mut body, "h");
    scratch(&mut body, "j");
    body.push_str("self.position_terms(q, h, j, &mut cache);\n");
    if VELOCITY.iter().any(|a| returned(a)) {
        if !entry.rates {
            scratch(&mut body, "qd");
        }
        for array in VELOCITY {
            scratch(&mut body, array);
        }
        let t = if entry.time { "t" } else { "0.0" };
        let _ = writeln!(
            body,
            "self.velocity_terms({t}, q, qd, &cache, rt::VelocityTerms {{ mass: m, inertial: f, \
             applied, bias: c }});"
        );
    }
    body.push_str("}\n");
    Some(body)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emit::testing::model;

    /// The doc line every wrapper starts with.
    const DOC: &str = "/// Calls the fused pair `position_terms`/`velocity_terms` (large model: every \
                       expression is compiled once).\n";

    #[test]
    fn constraint_calls_the_position_level_only_with_scratch_for_j() {
        let m = model("four_bar");
        assert_eq!((m.n(), m.n_constraints()), (3, 2));
        assert_eq!(
            wrapper(&m, 7, "constraint", &[]).as_deref(),
            Some(
                format!(
                    "{DOC}fn constraint(&self, q: &[f64], h: &mut [f64]) {{\n\
                     let mut cache = [0.0; 7];\n\
                     let j = &mut [0.0; 6];\n\
                     self.position_terms(q, h, j, &mut cache);\n}}\n"
                )
                .as_str()
            )
        );
    }

    #[test]
    fn mass_matrix_evaluates_at_rest_at_time_zero_with_scratch_for_the_rest() {
        let m = model("four_bar");
        assert_eq!(
            wrapper(&m, 0, "mass_matrix", &[]).as_deref(),
            Some(
                format!(
                    "{DOC}fn mass_matrix(&self, q: &[f64], m: &mut [f64]) {{\n\
                     let mut cache = [0.0; 0];\n\
                     let h = &mut [0.0; 2];\n\
                     let j = &mut [0.0; 6];\n\
                     self.position_terms(q, h, j, &mut cache);\n\
                     let qd = &mut [0.0; 3];\n\
                     let f = &mut [0.0; 3];\n\
                     let applied = &mut [0.0; 3];\n\
                     let c = &mut [0.0; 2];\n\
                     self.velocity_terms(0.0, q, qd, &cache, rt::VelocityTerms {{ mass: m, \
                     inertial: f, applied, bias: c }});\n}}\n"
                )
                .as_str()
            )
        );
    }

    #[test]
    fn equations_pass_time_and_rates_and_return_three_arrays() {
        let text = wrapper(&model("four_bar"), 1, "equations", &[]).unwrap_or_default();
        assert!(text.contains(
            "fn equations(&self, t: f64, q: &[f64], qd: &[f64], m: &mut [f64], f: &mut [f64], \
             applied: &mut [f64])"
        ));
        assert!(text.contains("self.velocity_terms(t, q, qd,"));
        assert!(!text.contains("let m ="), "{text}");
        assert!(text.contains("let c = &mut [0.0; 2];"), "{text}");
    }

    #[test]
    fn functions_with_their_own_expressions_have_no_wrapper() {
        let m = model("four_bar");
        assert_eq!(wrapper(&m, 0, "energy", &[]), None);
        assert_eq!(wrapper(&m, 0, "position_terms", &[]), None);
        assert_eq!(ENTRY_POINTS.len(), 8);
    }
}
