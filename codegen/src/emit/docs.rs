//! The docs of the generated constraint functions in the model's own terms: which contacts
//! (of which kinds) and which loops make up h, J and c, with the equations each uses, or that
//! there is none. A four-bar's `constraint` names its loop, not the paper's knife edge.

use crate::derive::Derivation;
use crate::model::Model;

/// One source of constraint rows: a contact or a loop.
struct Source {
    /// "contact `cam` (a knife edge on y = f(x))", "loop `closure` (x, y)".
    what: String,
    /// How it writes h.
    h: String,
    /// How it writes J.
    jacobian: String,
    /// The equations of its c.
    bias: String,
}

/// What the model's constraints are, for the docs of the functions that evaluate them.
pub(super) struct ConstraintDocs {
    sources: Vec<Source>,
}

/// Said of every constraint function of a model without constraints.
const NONE: &str = "the model has no contact and no loop, so there is no row";

impl ConstraintDocs {
    /// The contacts of `d` (in order), then its loops: the order of the rows of h.
    pub(super) fn new(model: &Model, d: &Derivation) -> Self {
        let mut sources: Vec<Source> = d
            .contacts
            .iter()
            .zip(&model.contacts)
            .map(|(terms, contact)| {
                let f = &terms.formulas;
                Source {
                    what: format!("contact `{}` ({})", contact.name, f.kind),
                    h: f.h.to_string(),
                    jacobian: f.jacobian.to_string(),
                    bias: f.bias.to_string(),
                }
            })
            .collect();
        sources.extend(model.loops.iter().map(|l| Source {
            what: format!("loop `{}` ({})", l.name, l.equations().join(", ")),
            h: "the cut joint's equations h = X·Y, eq. (K1)".to_string(),
            jacobian: "J = X_q·Y + X·Y_q, eq. (K2)".to_string(),
            bias: "eq. (K3)".to_string(),
        }));
        ConstraintDocs { sources }
    }

    /// "head: a; b." over the sources, or "head: none (…)." without any.
    fn list(&self, head: &str, item: impl Fn(&Source) -> String) -> String {
        if self.sources.is_empty() {
            return format!("{head}: none ({NONE}).");
        }
        let items: Vec<String> = self.sources.iter().map(item).collect();
        format!("{head}: {}.", items.join("; "))
    }

    /// The doc of `constraint`.
    pub(super) fn constraint(&self) -> String {
        self.list("h(q), one row per equation", |s| {
            format!("{}, {}", s.what, s.h)
        })
    }

    /// The doc of `constraint_jacobian`.
    pub(super) fn jacobian(&self) -> String {
        self.list("J = ∂h/∂q, row-major nc×n", |s| {
            format!("{}, {}", s.what, s.jacobian)
        })
    }

    /// The doc of `constraint_bias`.
    pub(super) fn bias(&self) -> String {
        self.list("c of J q̈ + c = 0", |s| format!("{}, {}", s.what, s.bias))
    }

    /// The doc of `constraint_terms`.
    pub(super) fn terms(&self) -> String {
        if self.sources.is_empty() {
            return format!("J and c: none ({NONE}).");
        }
        "J and c sharing one evaluation of the kinematics.".to_string()
    }

    /// The doc of `position_terms`.
    pub(super) fn position_terms(&self) -> String {
        let what = if self.sources.is_empty() {
            format!("h and J are empty ({NONE}); ")
        } else {
            "h and J for Newton (15) and the velocities (16), in one pass (see `constraint` \
             and `constraint_jacobian`); "
                .to_string()
        };
        format!(
            "{what}leaves the sines, cosines and profile values `velocity_terms` reuses in `cache`."
        )
    }

    /// The doc of `velocity_terms`.
    pub(super) fn velocity_terms(&self) -> String {
        let c = if self.sources.is_empty() {
            " (no c: the model has no constraint)"
        } else {
            " and c (see `constraint_bias`)"
        };
        format!(
            "M, F, Q (13){c} in one pass, reading `cache` as `position_terms` left it at the same q."
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emit::testing::derived;

    #[test]
    fn a_model_without_constraints_says_it_has_no_rows() {
        let (m, d) = derived("double_pendulum");
        let docs = ConstraintDocs::new(&m, &d);
        assert_eq!(
            docs.constraint(),
            "h(q), one row per equation: none (the model has no contact and no loop, so there \
             is no row)."
        );
        assert_eq!(
            docs.terms(),
            "J and c: none (the model has no contact and no loop, so there is no row)."
        );
        assert!(docs.velocity_terms().starts_with("M, F, Q (13) (no c:"));
    }

    #[test]
    fn a_four_bar_constraint_doc_names_its_loop_not_the_knife_edge() {
        let (m, d) = derived("four_bar");
        let docs = ConstraintDocs::new(&m, &d);
        let h = docs.constraint();
        assert_eq!(
            h,
            "h(q), one row per equation: loop `pin` (x, y), the cut joint's equations h = X·Y, \
             eq. (K1)."
        );
        assert!(!h.contains("f3"), "{h}");
        assert_eq!(
            docs.bias(),
            "c of J q̈ + c = 0: loop `pin` (x, y), eq. (K3)."
        );
    }

    #[test]
    fn a_knife_edge_on_an_explicit_profile_keeps_the_papers_equations() {
        let (m, d) = derived("driven_convex");
        let docs = ConstraintDocs::new(&m, &d);
        let name = &m.contacts[0].name;
        assert_eq!(
            docs.constraint(),
            format!(
                "h(q), one row per equation: contact `{name}` (a knife edge on y = f(x)), \
                 h = f2 − f3(f1), eq. (3)."
            )
        );
        assert_eq!(
            docs.jacobian(),
            format!(
                "J = ∂h/∂q, row-major nc×n: contact `{name}` (a knife edge on y = f(x)), \
                 J = J2 − f3′ J1, eq. (5b)."
            )
        );
    }

    #[test]
    fn a_roller_names_the_nearest_point_equations() {
        let (m, d) = derived("cycloidal_roller");
        let docs = ConstraintDocs::new(&m, &d);
        assert!(
            docs.constraint()
                .contains("(a roller on the profile's nearest point), h = D − ρ, eq. (C7)")
        );
        assert!(docs.bias().ends_with("eq. (C9)."));
    }
}
