//! The fused pair a right-hand side calls: `position_terms` (h, J) and `velocity_terms`
//! (M, F, Q, c), the values the first hands to the second through the cache, and the
//! operation counts that decide whether the other entry points call the pair.

use super::contacts::contact_output_roots;
use super::docs::ConstraintDocs;
use super::names::id_at;
use super::spec::{FunctionSpec, Param, param};
use super::trigonometry::{TrigMemo, reuse_position_trigonometry, trig_pairs};
use crate::derive::Derivation;
use crate::expr::{Id, Node, OpCount};
use std::collections::HashSet;

/// The two functions a right-hand side calls, position level (h, J) then velocity level
/// (M, F, Q, c), and the q-only values the first hands to the second through `cache`.
pub(super) struct FusedTerms {
    /// Nodes both levels need whose computation is worth a store and a load: elementary
    /// functions (sines, cosines, profile terms), powers and divisions.
    pub(super) cached: Vec<Id>,
    /// The sine–cosine pairs of joint angles the position level computes, each with three
    /// cache entries (angle, sine, cosine) at the start of the cache: the position level
    /// reuses them when it is evaluated again at the same angles (Newton moving a sliding
    /// coordinate, the step's end evaluated again), and the velocity level reads them.
    pub(super) memo: Vec<TrigMemo>,
    pub(super) position: Vec<(String, Id)>,
    pub(super) velocity: Vec<(String, Id)>,
    /// The outputs of `articulated_terms` (which reads the cache as `velocity_terms` does)
    /// and of `articulated_response`, when the model is given them.
    pub(super) articulated: Vec<(String, Id)>,
    pub(super) response: Vec<(String, Id)>,
    /// `mass_times`'s outputs when `velocity_terms` forms M column by column (M's entries
    /// are then not among its outputs).
    pub(super) mass: Vec<(String, Id)>,
}

impl FusedTerms {
    /// The pair, and with `articulated` (the outputs of `articulated_terms` and
    /// `articulated_response`) those two functions, sharing the position level's values.
    pub(super) fn new(d: &mut Derivation, articulated: Option<super::articulated::Groups>) -> Self {
        let n = d.symbols.q.len();
        let dy = &d.dynamics;
        let mut position = Vec::new();
        let rows = d.constraint_rows();
        for (k, row) in rows.iter().enumerate() {
            position.push((format!("h[{k}]"), row.0));
        }
        for (k, row) in rows.iter().enumerate() {
            for (i, &e) in row.1.iter().enumerate() {
                position.push((format!("j[{}]", k * n + i), e));
            }
        }
        let mut velocity = Vec::new();
        let by_columns = articulated.as_ref().is_some_and(|a| !a.mass.is_empty());
        for i in 0..n {
            for j in 0..n {
                if !by_columns {
                    velocity.push((format!("out.mass[{}]", i * n + j), dy.mass[i][j]));
                }
            }
        }
        for (i, &e) in dy.inertial.iter().enumerate() {
            velocity.push((format!("out.inertial[{i}]"), e));
        }
        for (i, &e) in dy.applied.iter().enumerate() {
            velocity.push((format!("out.applied[{i}]"), e));
        }
        for (k, row) in rows.iter().enumerate() {
            velocity.push((format!("out.bias[{k}]"), row.2));
        }
        drop(rows);
        let roots = |outputs: &[(String, Id)]| -> Vec<Id> { outputs.iter().map(|o| o.1).collect() };
        let groups = articulated.unwrap_or_default();
        let at = velocity.len();
        let lengths = [groups.main.len(), groups.response.len()];
        velocity.extend(groups.main);
        velocity.extend(groups.response);
        velocity.extend(groups.mass);
        reuse_position_trigonometry(&mut d.graph, &roots(&position), &mut velocity);
        let mut articulated = velocity.split_off(at);
        let mut response = articulated.split_off(lengths[0]);
        let mass = response.split_off(lengths[1]);
        let g = &d.graph;
        let in_position = g.reachable(&roots(&position));
        let velocity_roots = [roots(&velocity), roots(&articulated), roots(&mass)].concat();
        let in_velocity = g.reachable(&velocity_roots);
        let frontier = shared_frontier(g, &in_position, &in_velocity, &velocity_roots);
        let cached = (0..g.len())
            .filter(|&i| in_position[i] && in_velocity[i])
            .filter(|&i| {
                let id = id_at(g, i);
                frontier[i]
                    || matches!(
                        g.node(id),
                        Node::Call(..)
                            | Node::Powf(..)
                            | Node::Div(..)
                            | Node::Table(..)
                            | Node::Grid(..)
                    )
                    || g.implicit_of(id).is_some()
            })
            .map(|i| id_at(g, i))
            .collect();
        let memo = trig_pairs(g, &in_position, &d.symbols.params);
        FusedTerms {
            cached,
            memo,
            position,
            velocity,
            articulated,
            response,
            mass,
        }
    }

    /// The cached nodes that are not in a memo triple, with their cache index.
    pub(super) fn plain_cached(&self) -> Vec<(usize, Id)> {
        let in_memo = |id: Id| self.memo.iter().any(|m| m.sin == id || m.cos == id);
        self.cached
            .iter()
            .filter(|&&id| !in_memo(id))
            .enumerate()
            .map(|(k, &id)| (3 * self.memo.len() + k, id))
            .collect()
    }

    /// Entries of the cache.
    pub(super) fn cache_len(&self) -> usize {
        3 * self.memo.len() + self.plain_cached().len()
    }

    /// The nodes a function of the velocity level reads from the cache, with their places.
    pub(super) fn cache_given(&self) -> Vec<(Id, String)> {
        let mut given: Vec<(Id, String)> = self
            .plain_cached()
            .into_iter()
            .map(|(k, id)| (id, format!("cache[{k}]")))
            .collect();
        for m in &self.memo {
            given.push((m.sin, format!("cache[{}]", m.slot + 1)));
            given.push((m.cos, format!("cache[{}]", m.slot + 2)));
        }
        given
    }

    /// The two function specifications, each with the nodes it reads from the cache.
    pub(super) fn specs(&self, docs: &ConstraintDocs) -> Vec<(FunctionSpec, Vec<(Id, String)>)> {
        let uses_cache = self.cache_len() > 0;
        let cache_param = |ty| Param {
            name: "cache",
            ty,
            always_used: uses_cache,
        };
        let mut position_outputs = self.position.clone();
        for (k, id) in self.plain_cached() {
            position_outputs.push((format!("cache[{k}]"), id));
        }
        let position = FunctionSpec {
            doc: docs.position_terms(),
            name: "position_terms".into(),
            params: vec![
                param("q", "&[f64]"),
                param("h", "&mut [f64]"),
                param("j", "&mut [f64]"),
                cache_param("&mut [f64]"),
            ],
            ret: None,
            outputs: position_outputs,
            tail: String::new(),
        };
        let by_columns = !self.mass.is_empty();
        let velocity = FunctionSpec {
            doc: docs.velocity_terms(),
            name: "velocity_terms".into(),
            params: vec![
                param("t", "f64"),
                Param {
                    name: "q",
                    ty: "&[f64]",
                    always_used: by_columns,
                },
                param("qd", "&[f64]"),
                Param {
                    name: "cache",
                    ty: "&[f64]",
                    always_used: uses_cache || by_columns,
                },
                Param {
                    name: "out",
                    ty: "rt::VelocityTerms<'_>",
                    always_used: true,
                },
            ],
            ret: None,
            outputs: self.velocity.clone(),
            tail: if by_columns {
                super::articulated::mass_columns_tail(self.mass.len())
            } else {
                String::new()
            },
        };
        vec![(position, Vec::new()), (velocity, self.cache_given())]
    }
}

/// The values both levels compute that the velocity level reads directly: each operation
/// node the position level computes that is a velocity-level output or an operand of a
/// velocity-level node the position level does not compute (through negations, which cost
/// nothing). Read from the cache, they leave everything beneath them to the position level:
/// a long chain's tip rotation, its contact point and the cam's profile there are computed
/// once per right-hand side instead of twice.
fn shared_frontier(
    g: &crate::expr::Graph,
    in_position: &[bool],
    in_velocity: &[bool],
    velocity_roots: &[Id],
) -> Vec<bool> {
    let shared = |id: Id| in_position[id.index()] && in_velocity[id.index()];
    let mut frontier = vec![false; g.len()];
    let mut mark = |mut id: Id| {
        while let Node::Neg(a) = g.node(id) {
            id = a;
        }
        if shared(id) && matches!(g.node(id), Node::Add(..) | Node::Mul(..) | Node::Powi(..)) {
            frontier[id.index()] = true;
        }
    };
    for &root in velocity_roots {
        mark(root);
    }
    for i in (0..g.len()).filter(|&i| in_velocity[i] && !in_position[i]) {
        for c in g.children(id_at(g, i)) {
            mark(c);
        }
    }
    frontier
}

/// Operation count of a function's outputs (what it computes when emitted on its own), the
/// nodes of `given` read rather than computed.
pub(super) fn function_count(
    d: &Derivation,
    spec: &FunctionSpec,
    given: &[(Id, String)],
) -> OpCount {
    let roots: Vec<Id> = spec.outputs.iter().map(|(_, id)| *id).collect();
    let given: HashSet<Id> = given.iter().map(|(id, _)| *id).collect();
    d.graph.op_count_until(&roots, &given)
}

/// The outputs of every generated function (the standalone entry points, the fused pair and
/// the contact kinematics).
pub(super) fn all_roots(d: &Derivation, specs: &[FunctionSpec], fused: &FusedTerms) -> Vec<Id> {
    let mut roots: Vec<Id> = specs
        .iter()
        .flat_map(|s| s.outputs.iter().map(|(_, id)| *id))
        .chain(fused.position.iter().map(|(_, id)| *id))
        .chain(fused.velocity.iter().map(|(_, id)| *id))
        .chain(fused.articulated.iter().map(|(_, id)| *id))
        .chain(fused.response.iter().map(|(_, id)| *id))
        .chain(fused.mass.iter().map(|(_, id)| *id))
        .collect();
    for c in &d.contacts {
        roots.extend(contact_output_roots(c));
    }
    for (_, def) in d.graph.implicits() {
        roots.extend([def.residual, def.derivative, def.objective]);
    }
    roots
}

/// Operation count of a fused function, the cached nodes read rather than computed.
pub(super) fn fused_count(d: &Derivation, spec: &FunctionSpec, given: &[(Id, String)]) -> usize {
    let roots: Vec<Id> = spec.outputs.iter().map(|(_, id)| *id).collect();
    let given: HashSet<Id> = given.iter().map(|(id, _)| *id).collect();
    d.graph.op_count_until(&roots, &given).total()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emit::testing::derived;

    #[test]
    fn without_constraints_the_position_level_is_empty_and_caches_nothing() {
        let (m, mut d) = derived("double_pendulum");
        let fused = FusedTerms::new(&mut d, None);
        assert!(fused.position.is_empty());
        // M (2×2), F (2), Q (2); no c.
        assert_eq!(fused.velocity.len(), 8);
        assert_eq!(fused.cache_len(), 0);
        let specs = fused.specs(&ConstraintDocs::new(&m, &d));
        assert_eq!(specs[0].0.name, "position_terms");
        assert_eq!(specs[1].0.name, "velocity_terms");
        assert!(!specs[0].0.params.iter().any(|p| p.always_used));
    }

    #[test]
    fn the_velocity_level_computes_nothing_the_position_level_computes() {
        // Every operation of both levels is read from the cache by the second: with the
        // cached nodes given, what the velocity level still computes is disjoint from the
        // position level but for constants, variables and negations (which cost nothing).
        for name in ["paper_concave", "cycloidal_roller", "four_bar"] {
            let (_, mut d) = derived(name);
            let fused = FusedTerms::new(&mut d, None);
            let g = &d.graph;
            let position: Vec<Id> = fused.position.iter().map(|o| o.1).collect();
            let velocity: Vec<Id> = fused.velocity.iter().map(|o| o.1).collect();
            let given: HashSet<Id> = fused.cache_given().iter().map(|(id, _)| *id).collect();
            let in_position = g.reachable(&position);
            let computed = g.reachable_until(&velocity, &given);
            let recomputed: Vec<usize> = (0..g.len())
                .filter(|&i| computed[i] && in_position[i])
                .filter(|&i| !given.contains(&id_at(g, i)))
                .filter(|&i| {
                    !matches!(
                        g.node(id_at(g, i)),
                        Node::Const(_) | Node::Var(_) | Node::Neg(_)
                    )
                })
                .collect();
            assert!(
                recomputed.is_empty(),
                "{name}: {} nodes computed twice",
                recomputed.len()
            );
            // And the cache does hold sums and products, not only function values.
            let arithmetic = |id: &Id| matches!(g.node(*id), Node::Add(..) | Node::Mul(..));
            assert!(fused.cached.iter().any(arithmetic), "{name}");
        }
    }

    #[test]
    fn the_cache_holds_a_slot_triple_per_memoised_angle_then_the_plain_values() {
        // A cam on a revolute joint: its angle's sine and cosine, and the contact parameter.
        let (m, mut d) = derived("cycloidal_roller");
        let fused = FusedTerms::new(&mut d, None);
        assert_eq!(fused.position.len(), 1 + m.n());
        assert!(!fused.memo.is_empty());
        for (k, memo) in fused.memo.iter().enumerate() {
            assert_eq!(memo.slot, 3 * k);
        }
        let plain = fused.plain_cached();
        assert_eq!(plain.first().map(|p| p.0), Some(3 * fused.memo.len()));
        assert_eq!(fused.cache_len(), 3 * fused.memo.len() + plain.len());
        let (_, given) = &fused.specs(&ConstraintDocs::new(&m, &d))[1];
        assert_eq!(given.len(), plain.len() + 2 * fused.memo.len());
    }
}
