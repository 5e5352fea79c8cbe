//! The whole symbolic derivation of a model: kinematics, cam constraints, dynamics, energy
//! and prescribed motions, all in one expression graph.

use crate::articulated::{ArticulatedTerms, articulated, contact_row_bias};
use crate::contact::{ContactTerms, contact_terms};
use crate::dynamics::{DynamicsTerms, EnergyTerms, backward, energy};
use crate::expr::scalar::{scalar_to_expr, value_and_derivatives};
use crate::expr::{Graph, Id};
use crate::kinematics::{Symbols, forward};
use crate::linear;
use crate::loops::{LoopTerms, loop_terms};
use crate::model::{Field, Model};

/// q(t), q̇(t), q̈(t) of a driven coordinate.
#[derive(Debug, Clone, Copy)]
pub struct DriveTerms {
    /// Index of the driven coordinate.
    pub coordinate: usize,
    /// q(t), q̇(t), q̈(t).
    pub motion: [Id; 3],
}

/// A profile's polar radius and curvature at a placeholder, for the generated code's run-time
/// check that a follower can follow it ([`crate::model::RuntimeCheck::Followable`]).
#[derive(Debug, Clone, Copy)]
pub struct ProfileCheck {
    /// The contact.
    pub contact: usize,
    /// The placeholder variable of the profile's parameter.
    pub at: Id,
    /// r of a polar profile.
    pub radius: Option<Id>,
    /// The curvature, positive where the profile is hollow seen from the follower.
    pub curvature: Id,
}

/// Every symbolic term of a model.
#[derive(Debug, Clone)]
pub struct Derivation {
    /// The expression graph holding all terms.
    pub graph: Graph,
    /// Symbols of q, q̇, t.
    pub symbols: Symbols,
    /// M, F, Q (13).
    pub dynamics: DynamicsTerms,
    /// One entry per contact (1)–(8).
    pub contacts: Vec<ContactTerms>,
    /// One entry per loop (docs/method.md §11).
    pub loops: Vec<LoopTerms>,
    /// Energy expressions.
    pub energy: EnergyTerms,
    /// Prescribed motions of driven joints.
    pub drives: Vec<DriveTerms>,
    /// The articulated-body forward dynamics (derived after the rest, so that the other
    /// terms' graph is what it would be without them).
    pub articulated: ArticulatedTerms,
    /// The value of every model parameter (what the interpreter gives the run-time ones).
    pub parameter_values: Vec<f64>,
    /// Every numeric field that depends on run-time parameters, as an expression of them
    /// (profiles and drives, which are functions of x and t, are not in it): what the
    /// generated code checks and the initial guess it computes.
    pub fields: std::collections::BTreeMap<Field, Id>,
    /// The profiles whose followers the generated code checks at run time.
    pub profile_checks: Vec<ProfileCheck>,
}

/// [`ProfileCheck`] of contact `k`.
fn profile_check(g: &mut Graph, model: &Model, s: &Symbols, k: usize) -> ProfileCheck {
    let contact = &model.contacts[k];
    g.set_section(format!(
        "contact {}: the profile's curvature, checked at run time",
        contact.name
    ));
    let at = g.var(&format!("__check_{}", contact.name));
    let c = crate::contact::curve::curve_at(g, model, s, k, at);
    let side = crate::contact::curve::follower_side(&contact.profile);
    let f = crate::contact::curve::frame(g, &c, side);
    let radius = match contact.profile.curve() {
        crate::model::Profile::Polar { r, .. } => {
            let r = s.expression(model, Field::Profile(k), r);
            Some(scalar_to_expr(g, r, at, &s.params))
        }
        // A barrel's pitch height g(θ), for its cylinder's length.
        crate::model::Profile::Barrel { .. } => Some(c.point[1]),
        _ => None,
    };
    ProfileCheck {
        contact: k,
        at,
        radius,
        curvature: f.curvature,
    }
}

/// A model whose derivation outgrew the expression graph's node limit
/// ([`crate::expr::NODE_LIMIT`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "the model is too large to derive: its {bodies} bodies need more than {limit} expression \
     nodes (the limit, which bounds the memory and time the derivation takes): split the \
     mechanism or use fewer bodies"
)]
pub struct TooLarge {
    /// The node limit reached.
    pub limit: usize,
    /// The model's bodies.
    pub bodies: usize,
}

/// The term group of F in [`Derivation::visit_roots`]: the kinematics' main user, whose
/// rewriting the articulated sweeps follow.
const INERTIAL_GROUP: usize = 1;

impl Derivation {
    /// Derives every term of `model` (with the linear combinations collected).
    ///
    /// A model that needs more than [`crate::expr::NODE_LIMIT`] nodes gives a derivation of
    /// meaningless terms (its graph [`exhausted`](Graph::exhausted)), in bounded time and
    /// memory: code that may meet such models derives with [`Derivation::checked`].
    pub fn new(model: &Model) -> Self {
        Self::limited(model, crate::expr::NODE_LIMIT)
    }

    /// [`Derivation::new`], refused when the model needs more than
    /// [`crate::expr::NODE_LIMIT`] nodes.
    pub fn checked(model: &Model) -> Result<Self, TooLarge> {
        Self::checked_with_limit(model, crate::expr::NODE_LIMIT)
    }

    /// [`Derivation::checked`] with a node limit of `limit` instead.
    pub fn checked_with_limit(model: &Model, limit: usize) -> Result<Self, TooLarge> {
        let d = Self::limited(model, limit);
        match d.too_large(model) {
            Some(e) => Err(e),
            None => Ok(d),
        }
    }

    /// The error to report when the graph outgrew its limit, if it did.
    pub fn too_large(&self, model: &Model) -> Option<TooLarge> {
        self.graph.exhausted().then(|| TooLarge {
            limit: self.graph.node_limit(),
            bodies: model.bodies.len(),
        })
    }

    fn limited(model: &Model, limit: usize) -> Self {
        let mut d = Self::uncollected_in(model, Graph::with_node_limit(limit));
        d.derive_articulated(model);
        if !d.graph.exhausted() {
            d.collect_linear();
        }
        d
    }

    /// The derivation before [`linear::collect_linear`]: what the recursions build, for
    /// comparisons (the pass must never cost operations).
    pub fn uncollected(model: &Model) -> Self {
        let mut d = Self::uncollected_in(model, Graph::new());
        d.derive_articulated(model);
        d
    }

    /// The articulated-body terms, on the kinematics (rebuilt: the graph returns the nodes
    /// it already holds).
    fn derive_articulated(&mut self, model: &Model) {
        if self.graph.exhausted() {
            return;
        }
        let kin = forward(&mut self.graph, model, &self.symbols);
        // A model of one constraint row solves it within the sweeps; a contact's c there
        // reads the sweeps' accelerations.
        let row_bias = match self.constraint_rows().as_slice() {
            [(_, _, c)] => Some(*c),
            _ => None,
        }
        .map(|c| contact_row_bias(&mut self.graph, model, &self.symbols, &kin).unwrap_or(c));
        self.articulated = articulated(&mut self.graph, model, &self.symbols, &kin, row_bias);
    }

    fn uncollected_in(model: &Model, mut g: Graph) -> Self {
        let symbols = Symbols::new(&mut g, model);
        let kin = forward(&mut g, model, &symbols);
        let contacts = contact_terms(&mut g, model, &kin, &symbols);
        let loops = loop_terms(&mut g, model, &kin, &symbols);
        let dynamics = backward(&mut g, model, &symbols, &kin);
        let energy = energy(&mut g, model, &symbols, &kin);
        let drives = model
            .bodies
            .iter()
            .enumerate()
            .filter_map(|(i, b)| {
                let p = b.joint.prescribed.as_ref()?;
                g.set_section(format!("prescribed motion of {}", b.joint.coordinate));
                let expr = symbols.expression(model, Field::Drive(i), &p.expr);
                let motion =
                    value_and_derivatives(&mut g, expr, "__drive_t", symbols.t, &symbols.params);
                Some(DriveTerms {
                    coordinate: i,
                    motion,
                })
            })
            .collect();
        g.set_section("parameters: fields read at run time");
        let zero = g.zero();
        let fields = model
            .symbolic
            .iter()
            .filter(|(f, _)| {
                !matches!(
                    f,
                    Field::Profile(_) | Field::ProfileY(_) | Field::Drive(_) | Field::Load(_)
                )
            })
            .map(|(&f, expr)| (f, scalar_to_expr(&mut g, expr, zero, &symbols.params)))
            .collect();
        let profile_checks = model
            .runtime_checks
            .iter()
            .filter_map(|c| match c {
                crate::model::RuntimeCheck::Followable(k, _) => Some(*k),
                _ => None,
            })
            .map(|k| profile_check(&mut g, model, &symbols, k))
            .collect();
        Derivation {
            graph: g,
            symbols,
            dynamics,
            contacts,
            loops,
            energy,
            drives,
            articulated: ArticulatedTerms::default(),
            parameter_values: model.parameters.iter().map(|p| p.value).collect(),
            fields,
            profile_checks,
        }
    }

    /// Runs [`linear::collect_linear`] over every term at once (so a node another term
    /// also uses is never expanded into one of them), then keeps, term group by term group
    /// (M, F, Q, energies, each contact's position level, each contact's J and c, each
    /// drive), the rewritten expressions only where they need fewer operations: the pass
    /// pulls shared factors out greedily, which on long contact Jacobians of spatial chains
    /// can cost a few percent more than it saves.
    fn collect_linear(&mut self) {
        let mut roots: Vec<Id> = Vec::new();
        let mut group_of: Vec<usize> = Vec::new();
        self.visit_roots(|group, id| {
            roots.push(*id);
            group_of.push(group);
        });
        let mut collected = roots.clone();
        // The sweeps ride on the rewritten kinematics (when F is rewritten, below), so that
        // the articulated route shares its velocities and accelerations with the contacts'
        // and loops' terms instead of holding a second copy; the rewriting is that of the
        // other terms alone.
        let mut ridden: Vec<Id> = self.articulated.roots_mut().map(|id| *id).collect();
        linear::collect_linear_with(&mut self.graph, &mut collected, &mut ridden);
        let groups = group_of.iter().copied().max().map_or(0, |g| g + 1);
        let mut keep_new = vec![false; groups];
        for (group, keep) in keep_new.iter_mut().enumerate() {
            let pick = |ids: &[Id]| -> Vec<Id> {
                ids.iter()
                    .zip(&group_of)
                    .filter(|&(_, &g)| g == group)
                    .map(|(&id, _)| id)
                    .collect()
            };
            let before = self.graph.op_count(&pick(&roots)).total();
            let after = self.graph.op_count(&pick(&collected)).total();
            *keep = after <= before;
        }
        if keep_new.get(INERTIAL_GROUP) == Some(&true) {
            for (id, new) in self.articulated.roots_mut().zip(ridden) {
                *id = new;
            }
        }
        let mut it = roots.into_iter().zip(collected);
        self.visit_roots(|group, id| {
            if let Some((old, new)) = it.next() {
                *id = if keep_new[group] { new } else { old };
            }
        });
    }

    /// Every expression the derivation holds, in a fixed order, with the index of its term
    /// group.
    fn visit_roots(&mut self, mut f: impl FnMut(usize, &mut Id)) {
        let dy = &mut self.dynamics;
        dy.mass.iter_mut().flatten().for_each(|id| f(0, id));
        dy.inertial.iter_mut().for_each(|id| f(INERTIAL_GROUP, id));
        dy.applied.iter_mut().for_each(|id| f(2, id));
        let e = &mut self.energy;
        for id in [
            &mut e.kinetic,
            &mut e.gravity,
            &mut e.spring,
            &mut e.damper_power,
            &mut e.load_power,
        ] {
            f(3, id);
        }
        let mut group = 4;
        for c in &mut self.contacts {
            let r = &mut c.relative;
            for id in r.point.iter_mut().chain(&mut r.xy).chain(&mut r.convective) {
                f(group, id);
            }
            for column in &mut r.columns {
                column.iter_mut().for_each(|id| f(group, id));
            }
            for id in c
                .position
                .iter_mut()
                .chain(&mut c.cam_point)
                .chain(&mut c.normal)
                .chain([
                    &mut c.force_scale,
                    &mut c.parameter,
                    &mut c.curvature,
                    &mut c.h,
                ])
            {
                f(group, id);
            }
            if let Some(z) = &mut c.cam_height {
                f(group, z);
            }
            c.jacobian.iter_mut().for_each(|id| f(group + 1, id));
            f(group + 1, &mut c.bias);
            f(group + 1, &mut c.sliding);
            group += 2;
        }
        for l in &mut self.loops {
            for id in l.points.iter_mut().flatten() {
                f(group, id);
            }
            for row in &mut l.rows {
                f(group, &mut row.h);
                row.jacobian.iter_mut().for_each(|id| f(group + 1, id));
                f(group + 1, &mut row.bias);
            }
            group += 2;
        }
        for d in &mut self.drives {
            d.motion.iter_mut().for_each(|id| f(group, id));
            group += 1;
        }
    }

    /// Every scalar constraint as (h, J, c): one per contact, then each loop's equations
    /// (the order of the rows of h in the generated code and the runtime).
    pub fn constraint_rows(&self) -> Vec<(Id, &[Id], Id)> {
        let contacts = self
            .contacts
            .iter()
            .map(|c| (c.h, c.jacobian.as_slice(), c.bias));
        let loops = self
            .loops
            .iter()
            .flat_map(|l| l.rows.iter().map(|r| (r.h, r.jacobian.as_slice(), r.bias)));
        contacts.chain(loops).collect()
    }

    /// True when the model reads parameters at run time (the generated code has `Derived`).
    pub fn has_runtime_parameters(&self) -> bool {
        self.symbols
            .params
            .iter()
            .any(|&p| matches!(self.graph.node(p), crate::expr::Node::Var(_)))
    }

    /// Values of the graph's variables for a state (q, q̇, t), for [`Graph::eval`].
    pub fn variables(&self, t: f64, q: &[f64], qd: &[f64]) -> Vec<f64> {
        let mut vars = vec![f64::NAN; self.graph.var_names().len()];
        let mut set = |id: Id, v: f64| {
            if let crate::expr::Node::Var(k) = self.graph.node(id) {
                vars[k as usize] = v;
            }
        };
        for (i, &id) in self.symbols.q.iter().enumerate() {
            set(id, q[i]);
        }
        for (i, &id) in self.symbols.qd.iter().enumerate() {
            set(id, qd[i]);
        }
        set(self.symbols.t, t);
        for (&id, value) in self.symbols.params.iter().zip(&self.parameter_values) {
            set(id, *value);
        }
        vars
    }

    /// Evaluates expressions at a state with the interpreter.
    pub fn eval(&self, roots: &[Id], t: f64, q: &[f64], qd: &[f64]) -> Vec<f64> {
        self.graph.eval(roots, &self.variables(t, q, qd))
    }
}
