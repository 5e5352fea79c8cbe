//! The implicit variables' functions: the residual ψ(s) with ψ′(s) and the objective of
//! every contact parameter a Newton solve finds (`rt::contact::solve` calls them).

use super::function::emit_function_given;
use super::literals::ALLOW_LITERALS;
use super::names::Names;
use super::spec::{FunctionSpec, Param, RETURN};
use crate::derive::Derivation;
use crate::expr::{Id, OpCount};

/// The residual ψ(s; p) with ψ′(s), and the objective, of every implicit variable (a contact
/// parameter), as free functions `<name>_residual` and `<name>_objective` that the solves
/// call (`rt::contact::solve`).
pub(super) fn implicit_helpers(
    d: &Derivation,
    counts: &mut Vec<(String, OpCount)>,
    derived: &[(Id, String)],
) -> String {
    let g = &d.graph;
    let names = Names::of_vars(g);
    let parametric = d.has_runtime_parameters();
    let mut out = String::new();
    for (id, def) in g.implicits() {
        let base = names.var(g, id);
        let mut params: Vec<Param> = Vec::new();
        if parametric {
            params.push(Param {
                name: "derived",
                ty: "&Derived",
                always_used: false,
            });
        }
        let input_names = &def.input_names;
        for &name in input_names {
            params.push(Param {
                name,
                ty: "f64",
                always_used: false,
            });
        }
        params.push(Param {
            name: "s",
            ty: "f64",
            always_used: false,
        });
        let mut given: Vec<(Id, String)> = derived.to_vec();
        given.push((def.unknown, "s".to_string()));
        for (&p, name) in def.placeholders.iter().zip(input_names) {
            given.push((p, name.to_string()));
        }
        let residual = FunctionSpec {
            doc: format!(
                "{}: ψ(s) and ψ′(s), whose root with ψ′ < 0 Newton finds.",
                def.description
            ),
            name: format!("{base}_residual"),
            params: params.clone(),
            ret: Some("[f64; 2]"),
            outputs: vec![
                ("let value".to_string(), def.residual),
                ("let slope".to_string(), def.derivative),
            ],
            tail: "[value, slope]".to_string(),
        };
        let objective = FunctionSpec {
            doc: format!(
                "{}: the objective the root minimises (what a scan of the range compares).",
                def.description
            ),
            name: format!("{base}_objective"),
            params,
            ret: Some("f64"),
            outputs: vec![(RETURN.to_string(), def.objective)],
            tail: String::new(),
        };
        for spec in [residual, objective] {
            let (text, count) = emit_function_given(d, &spec, "", false, &given);
            out.push_str(ALLOW_LITERALS);
            out.push('\n');
            out.push_str(&text);
            counts.push((spec.name.clone(), count));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emit::testing::derived;

    #[test]
    fn no_contact_parameter_means_no_helper() {
        let (_, d) = derived("double_pendulum");
        let mut counts = Vec::new();
        assert_eq!(implicit_helpers(&d, &mut counts, &[]), "");
        assert!(counts.is_empty());
    }

    #[test]
    fn a_contact_parameter_gets_its_residual_and_objective() {
        let (_, d) = derived("cycloidal_roller");
        let mut counts = Vec::new();
        // The profile's dimensions are constant: the residual reads nothing derived.
        let text = implicit_helpers(&d, &mut counts, &[]);
        let names: Vec<&str> = counts.iter().map(|c| c.0.as_str()).collect();
        assert_eq!(
            names,
            ["roller_parameter_residual", "roller_parameter_objective"]
        );
        assert!(text.contains("fn roller_parameter_residual(_derived: &Derived, x: f64, y: f64, s: f64) -> [f64; 2]"), "{text}");
        assert!(text.contains("[value, slope]"));
        assert!(text.contains("whose root with ψ′ < 0 Newton finds"));
    }
}
