//! The articulated-body forward dynamics (`crate::articulated`) as two generated functions,
//! and the choice, made per model by operation count, between it and the dense route
//! (M, F, Q formed and the reduced mass matrix factored at run time).
//!
//! `articulated_terms` reads the position level's cache like `velocity_terms` and writes
//! the free coordinates' accelerations without constraint forces, the driven coordinates'
//! loads, the constraints' c and the factors; `articulated_response` reads the factors and a
//! generalised force τ and writes M_ff⁻¹ τ and its driven rows. The factors are the values
//! the response needs that do not depend on τ (U, 1/D, sines, cosines and offsets of the
//! joints), found on the graph as the boundary between what depends on τ and what does not.

use super::spec::{FunctionSpec, Param, param};
use crate::derive::Derivation;
use crate::expr::{Graph, Id, Node};
use std::collections::HashSet;

pub use crate::model::Formulation;

/// A function's outputs: (target, expression).
pub(super) type Outputs = Vec<(String, Id)>;

/// Function specifications, each with the nodes it reads rather than computes.
pub(super) type Specs = Vec<(FunctionSpec, Vec<(Id, String)>)>;

/// The formulation chosen for a model and the estimates it was chosen by.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Choice {
    /// True when the articulated functions are emitted and the runtime uses them.
    pub articulated: bool,
    /// True when the choice was asked for rather than made by the estimates.
    pub forced: bool,
    /// Estimated operations per right-hand side of the dense route: `velocity_terms` plus
    /// the run-time reduction and factorisation.
    pub dense: usize,
    /// … of the articulated route: `articulated_terms`, one `articulated_response` per
    /// constraint row, and the multipliers' solve.
    pub articulated_ops: usize,
    /// True when M is formed column by column by `mass_times` (a large model on the
    /// articulated route) instead of from its emitted entries.
    pub mass_by_columns: bool,
}

/// The outputs of the two functions, before the position level's trigonometry is shared.
/// The outputs of the articulated functions, and of `mass_times` when M is given column by
/// column.
#[derive(Debug, Clone, Default)]
pub(super) struct Groups {
    pub(super) main: Outputs,
    pub(super) response: Outputs,
    /// `out[i]` = (M x)_i, when the model gives M column by column.
    pub(super) mass: Outputs,
}

/// [`outputs`] grouped, with `mass_times`'s when `mass_by_columns`.
pub(super) fn groups(d: &Derivation, mass_by_columns: bool) -> Groups {
    let (main, response) = outputs(d);
    let mass = if mass_by_columns {
        (d.articulated.mass_product.iter().enumerate())
            .map(|(i, &e)| (format!("out[{i}]"), e))
            .collect()
    } else {
        Vec::new()
    };
    Groups {
        main,
        response,
        mass,
    }
}

/// `mass_times(q, cache, x, out)`: out = M(q) x, reading the position level's cache.
pub(super) fn mass_times_spec(
    d: &Derivation,
    mass: &Outputs,
    cache_given: &[(Id, String)],
    derived: &[(Id, String)],
) -> (FunctionSpec, Vec<(Id, String)>) {
    let mut given = [cache_given, derived].concat();
    for (i, &var) in d.articulated.mass_x.iter().enumerate() {
        given.push((var, format!("x[{i}]")));
    }
    let spec = FunctionSpec {
        doc: "M(q) x by the recursions (no velocities, weights or loads), reading the cache \
              `position_terms` filled at q: `velocity_terms` forms M column by column with it \
              (docs/method.md §14.4)."
            .into(),
        name: "mass_times".into(),
        params: vec![
            param("q", "&[f64]"),
            param("cache", "&[f64]"),
            param("x", "&[f64]"),
            param("out", "&mut [f64]"),
        ],
        ret: None,
        outputs: mass.clone(),
        tail: String::new(),
    };
    (spec, given)
}

/// The end of `velocity_terms` for a model that gives M column by column: M e_j for every j.
pub(super) fn mass_columns_tail(n: usize) -> String {
    format!(
        "// M column by column: M e_j by `mass_times` (docs/method.md §14.4).\n\
         let mut unit = [0.0; {n}];\n\
         let mut column = [0.0; {n}];\n\
         for j in 0..{n} {{\n\
             unit[j] = 1.0;\n\
             self.mass_times(q, cache, &unit, &mut column);\n\
             unit[j] = 0.0;\n\
             for (i, value) in column.iter().enumerate() {{\n\
                 out.mass[i * {n} + j] = *value;\n\
             }}\n\
         }}\n"
    )
}

pub(super) fn outputs(d: &Derivation) -> (Outputs, Outputs) {
    let a = &d.articulated;
    let mut main: Vec<(String, Id)> = Vec::new();
    // A model of one constraint row returns q̈ with the row's force when given the row (and
    // without it when not): the free accelerations' own forward sweep is not emitted.
    let (accelerations, drive_loads) = match a.row_solution {
        Some(_) => (&a.solved_accelerations, &a.solved_drive_loads),
        None => (&a.accelerations, &a.drive_loads),
    };
    for &(i, e) in accelerations {
        main.push((format!("out.qdd[{i}]"), e));
    }
    for &(i, e) in drive_loads {
        main.push((format!("out.drive[{i}]"), e));
    }
    if let Some((lambda, delassus)) = a.row_solution {
        main.push(("out.solved.lambda".to_string(), lambda));
        main.push(("out.solved.delassus".to_string(), delassus));
    }
    // The row the sweeps solve has its c as they compute it (the same value).
    match (a.row_bias, d.constraint_rows().as_slice()) {
        (Some(c), [_]) => main.push(("out.bias[0]".to_string(), c)),
        (_, rows) => {
            for (k, row) in rows.iter().enumerate() {
                main.push((format!("out.bias[{k}]"), row.2));
            }
        }
    }
    let mut response: Vec<(String, Id)> = Vec::new();
    for &(i, e) in &a.response {
        response.push((format!("qdd[{i}]"), e));
    }
    for &(i, e) in &a.response_loads {
        response.push((format!("drive[{i}]"), e));
    }
    (main, response)
}

/// The response's inputs computed by `articulated_terms`: every node the response reaches
/// that does not depend on τ, is not a constant, and is an operand of a node that does (or a
/// root itself), in id order.
pub(super) fn factors(g: &Graph, response: &[Id], tau: &[Id]) -> Vec<Id> {
    let reach = g.reachable(response);
    let tau: HashSet<Id> = tau.iter().copied().collect();
    let mut depends = vec![false; g.len()];
    let mut boundary = vec![false; g.len()];
    for (i, &needed) in reach.iter().enumerate() {
        if !needed {
            continue;
        }
        let id = g.id_from_index(i);
        let children = g.children(id);
        depends[i] = tau.contains(&id) || children.iter().any(|c| depends[c.index()]);
        if depends[i] {
            for c in children {
                boundary[c.index()] |= !depends[c.index()];
            }
        }
    }
    for &root in response {
        boundary[root.index()] |= !depends[root.index()];
    }
    (0..g.len())
        .filter(|&i| boundary[i])
        .map(|i| g.id_from_index(i))
        .filter(|&id| !matches!(g.node(id), Node::Const(_)))
        .collect()
}

/// Chooses the formulation: `asked` unless it is `Auto`, else the smaller estimate.
/// `dense_ops`: the operations of the dense route's velocity level (M, F, Q and c).
pub(super) fn choose(d: &Derivation, dense_ops: usize, asked: Formulation) -> Choice {
    let n = d.symbols.q.len();
    let m = d.constraint_rows().len();
    let nd = d.articulated.driven.len();
    let nu = n.saturating_sub(m + nd);
    // The reduction (16)–(18) at run time: the residual M q̈ + F + Q (n² multiply-adds), B =
    // −J_v⁻¹ J_u (2 m² per column), M T (2 n m per column), Tᵀ M T (nu² (m + 1)) and the
    // factorisation nu³ / 3.
    let dense = dense_ops
        + 2 * n * n
        + 2 * m * m * nu
        + 2 * n * m * nu
        + nu * nu * (m + 1)
        + nu * nu * nu / 3;
    let (main, response) = outputs(d);
    let main_roots: Vec<Id> = main.iter().map(|o| o.1).collect();
    let response_roots: Vec<Id> = response.iter().map(|o| o.1).collect();
    let given: HashSet<Id> = factors(&d.graph, &response_roots, &d.articulated.tau)
        .into_iter()
        .collect();
    let response_ops = d.graph.op_count_until(&response_roots, &given).total();
    let main_ops = d.graph.op_count(&main_roots).total();
    // Per row: a response, J times it for every row (2 n m), the combination (2 n); the
    // multipliers' Cholesky m³ / 3. A model of one row solves it within the main function. The sweeps are a chain of dependent operations (each
    // body waits for its child's articulated inertia, a division among them) where the
    // dense route's terms are independent of each other: 40 n more, calibrated on the
    // scaling chains (`codegen/examples/formulations.rs`, BENCHMARKS.md), where the planar
    // chain of 8 bodies runs about as fast both ways and the spatial one of 16 faster
    // articulated.
    let per_row = match d.articulated.row_solution {
        Some(_) => 0,
        None => m * (response_ops + 2 * n * m + 2 * n) + m * m * m / 3,
    };
    let articulated_ops = main_ops + per_row + 40 * n;
    let (articulated, forced) = match asked {
        Formulation::Auto => (articulated_ops < dense, false),
        Formulation::Dense => (false, true),
        Formulation::Articulated => (true, true),
    };
    Choice {
        articulated,
        forced,
        dense,
        articulated_ops,
        mass_by_columns: false,
    }
}

/// The two function specifications with the nodes each reads rather than computes (the
/// cache's, as `velocity_terms` reads them, for the first; the factors and τ for the second),
/// and the number of factors.
pub(super) fn specs(
    d: &Derivation,
    main: &[(String, Id)],
    response: &[(String, Id)],
    cache_given: &[(Id, String)],
    uses_cache: bool,
    derived: &[(Id, String)],
) -> (Specs, usize) {
    let response_roots: Vec<Id> = response.iter().map(|o| o.1).collect();
    // Values of the run-time parameters alone are read where they are kept, not passed.
    let per_parameter_set: HashSet<Id> = derived.iter().map(|g| g.0).collect();
    let factors: Vec<Id> = factors(&d.graph, &response_roots, &d.articulated.tau)
        .into_iter()
        .filter(|id| !per_parameter_set.contains(id))
        .collect();
    let mut main_outputs = main.to_vec();
    for (k, &id) in factors.iter().enumerate() {
        main_outputs.push((format!("out.factors[{k}]"), id));
    }
    let mut main_given = [cache_given, derived].concat();
    for &(i, var) in &d.articulated.driven {
        main_given.push((var, format!("out.qdd[{i}]")));
    }
    if let Some(weight) = d.articulated.row_weight {
        let n = d.articulated.row.len();
        main_given.push((weight, format!("rt::row_weight(out.row, {n})")));
        for (i, &var) in d.articulated.row.iter().enumerate() {
            main_given.push((var, format!("rt::row_entry(out.row, {i})")));
        }
    }
    let terms = FunctionSpec {
        doc: match d.articulated.row_solution {
            Some(_) => "The articulated-body sweeps (docs/method.md §14) with the model's \
                        constraint row solved within them when `out.row` holds J (§14.6): q̈ of \
                        the free coordinates with the row's force (without it when `out.row` is \
                        empty; the driven ones' q̈ read from `out.qdd`), the driven coordinates' \
                        rows of M q̈ + F + Q + Jᵀ λ, λ, J M_ff⁻¹ Jᵀ, c, and the factors the \
                        response reads."
                .into(),
            None => "The articulated-body sweeps (docs/method.md §14): q̈ of the free \
                     coordinates without constraint forces (the driven ones' q̈ read from \
                     `out.qdd`), the driven coordinates' rows of M q̈ + F + Q, c, and the factors \
                     the response reads."
                .into(),
        },
        name: "articulated_terms".into(),
        params: vec![
            param("t", "f64"),
            param("q", "&[f64]"),
            param("qd", "&[f64]"),
            Param {
                name: "cache",
                ty: "&[f64]",
                always_used: uses_cache,
            },
            Param {
                name: "out",
                ty: "rt::ArticulatedTerms<'_>",
                always_used: true,
            },
        ],
        ret: None,
        outputs: main_outputs,
        tail: String::new(),
    };
    let mut response_given: Vec<(Id, String)> = factors
        .iter()
        .enumerate()
        .map(|(k, &id)| (id, format!("factors[{k}]")))
        .chain(derived.iter().cloned())
        .collect();
    for (i, &var) in d.articulated.tau.iter().enumerate() {
        response_given.push((var, format!("tau[{i}]")));
    }
    let answer = FunctionSpec {
        doc: "M_ff⁻¹ τ on the free coordinates and M_df M_ff⁻¹ τ on the driven ones, from the \
              factors of the last `articulated_terms`."
            .into(),
        name: "articulated_response".into(),
        params: vec![
            Param {
                name: "factors",
                ty: "&[f64]",
                always_used: !factors.is_empty(),
            },
            param("tau", "&[f64]"),
            param("qdd", "&mut [f64]"),
            param("drive", "&mut [f64]"),
        ],
        ret: None,
        outputs: response.to_vec(),
        tail: String::new(),
    };
    (
        vec![(terms, main_given), (answer, response_given)],
        factors.len(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emit::testing::derived;

    #[test]
    fn the_factors_are_what_the_response_reads_besides_tau() {
        let (_, d) = derived("double_pendulum");
        let (_, response) = outputs(&d);
        let roots: Vec<Id> = response.iter().map(|o| o.1).collect();
        let f = factors(&d.graph, &roots, &d.articulated.tau);
        assert!(!f.is_empty());
        // None depends on τ, and with them given the response needs nothing else but τ.
        let given: HashSet<Id> = f.iter().chain(&d.articulated.tau).copied().collect();
        let reach = d.graph.reachable_until(&roots, &given);
        for (i, &r) in reach.iter().enumerate() {
            let id = d.graph.id_from_index(i);
            if r && !given.contains(&id) {
                assert!(
                    !matches!(d.graph.node(id), Node::Var(_)),
                    "the response reads a variable that is not a factor"
                );
            }
        }
        for id in &f {
            assert!(!d.articulated.tau.contains(id));
        }
    }

    #[test]
    fn small_models_keep_the_dense_route_and_the_choice_can_be_forced() {
        let (_, d) = derived("paper_concave");
        let roots: Vec<Id> = d
            .dynamics
            .mass
            .iter()
            .flatten()
            .chain(&d.dynamics.inertial)
            .chain(&d.dynamics.applied)
            .copied()
            .collect();
        let auto = choose(&d, d.graph.op_count(&roots).total(), Formulation::Auto);
        assert!(!auto.articulated && !auto.forced, "{auto:?}");
        assert!(auto.dense < auto.articulated_ops);
        let forced = choose(
            &d,
            d.graph.op_count(&roots).total(),
            Formulation::Articulated,
        );
        assert!(forced.articulated && forced.forced);
        assert_eq!(forced.dense, auto.dense);
    }
}
