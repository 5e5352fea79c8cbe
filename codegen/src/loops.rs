//! Loops (docs/method.md §11): a joint cut to make the tree comes back as equations
//! h(q) = 0 between a point A of one body and a point B of another, with J = ∂h/∂q and the
//! convective term c of J q̈ + c = 0, derived on the graph like a contact's and emitted as
//! the rows of h after the contacts'.
//!
//! Every equation is a scalar product of two vectors carried by bodies (or fixed in the
//! ground): the gap r = p_A − p_B, a line's normal n_B, a pin's axis a_A. For vectors X, Y
//! with columns X_j = ∂X/∂q_j, rates Ẋ and velocity-product accelerations Ẍ°,
//!
//! ```text
//! h = X·Y,   J_j = X_j·Y + X·Y_j,   c = Ẍ°·Y + 2 Ẋ·Ẏ + X·Ÿ°
//! ```
//!
//! and a component of r along a ground axis is the special case Y = e_k. Points are moved by
//! the recursion of eq. (9) along their path to the ground (`point_motion`); a direction v
//! carried by a body turning at ω has columns u_j × v (revolute j), rate ω × v and
//! v̈° = α° × v + ω × (ω × v).

mod gap;

use crate::contact::relative::{Labels, PointMotion, point_motion};
use crate::expr::{Graph, Id};
use crate::kinematics::{BodyKinematics, Symbols, V3, vec3};
use crate::model::{Field, JointKind, LoopKind, LoopPoint, Model, normal_pair};
use gap::closure_gap;

/// One scalar equation of a loop: h, J, c.
#[derive(Debug, Clone)]
pub struct Row {
    /// h(q).
    pub h: Id,
    /// J = ∂h/∂q.
    pub jacobian: Vec<Id>,
    /// c of J q̈ + c = 0.
    pub bias: Id,
}

/// The terms of one loop cut.
#[derive(Debug, Clone)]
pub struct LoopTerms {
    /// Its equations, in the order of [`crate::model::Loop::equations`].
    pub rows: Vec<Row>,
    /// A and B, ground coordinates (what the outputs draw).
    pub points: [V3; 2],
}

/// A vector carried by a body: its value, columns, rate and velocity-product acceleration,
/// all in ground axes.
#[derive(Clone)]
struct Carried {
    value: V3,
    columns: Vec<Option<V3>>,
    rate: V3,
    conv: V3,
}

impl Carried {
    /// A constant vector of the ground.
    fn fixed(g: &mut Graph, v: [f64; 3], n: usize) -> Self {
        let zero = vec3::zero(g);
        Carried {
            value: vec3::constant(g, v),
            columns: vec![None; n],
            rate: zero,
            conv: zero,
        }
    }

    /// The point whose motion is `m`.
    fn point(g: &mut Graph, s: &Symbols, m: &PointMotion) -> Self {
        let mut rate = vec3::zero(g);
        for (j, column) in m.columns.iter().enumerate() {
            if let Some(c) = column {
                let term = vec3::scale(g, s.qd[j], *c);
                rate = vec3::add(g, rate, term);
            }
        }
        Carried {
            value: m.position,
            columns: m.columns.clone(),
            rate,
            conv: m.convective,
        }
    }

    /// The direction `local` carried by `body` (whose point moves as `m`).
    fn direction(
        g: &mut Graph,
        model: &Model,
        kin: &[BodyKinematics],
        body: Option<usize>,
        local: [f64; 3],
        m: &PointMotion,
    ) -> Self {
        let n = model.n();
        let Some(b) = body else {
            return Self::fixed(g, local, n);
        };
        let local = vec3::constant(g, local);
        let value = kin[b].rotation.apply(g, local);
        let mut columns = vec![None; n];
        for (j, column) in m.columns.iter().enumerate() {
            if column.is_some() && model.bodies[j].joint.kind == JointKind::Revolute {
                columns[j] = Some(vec3::cross(g, kin[j].axis_ground, value));
            }
        }
        let rate = vec3::cross(g, m.omega, value);
        let a_v = vec3::cross(g, m.alpha, value);
        let w_w_v = vec3::omega_omega(g, m.omega, value);
        let conv = vec3::add(g, a_v, w_w_v);
        Carried {
            value,
            columns,
            rate,
            conv,
        }
    }

    /// self − other.
    fn minus(&self, g: &mut Graph, other: &Carried) -> Self {
        let columns = self
            .columns
            .iter()
            .zip(&other.columns)
            .map(|(a, b)| match (a, b) {
                (Some(a), Some(b)) => Some(vec3::sub(g, *a, *b)),
                (Some(a), None) => Some(*a),
                (None, Some(b)) => Some([0, 1, 2].map(|k| g.neg(b[k]))),
                (None, None) => None,
            })
            .collect();
        Carried {
            value: vec3::sub(g, self.value, other.value),
            columns,
            rate: vec3::sub(g, self.rate, other.rate),
            conv: vec3::sub(g, self.conv, other.conv),
        }
    }

    /// The row of component k (a ground axis).
    fn component(&self, g: &mut Graph, k: usize) -> Row {
        let jacobian = self
            .columns
            .iter()
            .map(|c| c.map_or_else(|| g.zero(), |c| c[k]))
            .collect();
        Row {
            h: self.value[k],
            jacobian,
            bias: self.conv[k],
        }
    }

    /// The row of self · other (the product rule above).
    fn dot(&self, g: &mut Graph, other: &Carried) -> Row {
        let h = vec3::dot(g, self.value, other.value);
        let jacobian = self
            .columns
            .iter()
            .zip(&other.columns)
            .map(|(a, b)| {
                let left = a.map(|a| vec3::dot(g, a, other.value));
                let right = b.map(|b| vec3::dot(g, self.value, b));
                match (left, right) {
                    (Some(l), Some(r)) => g.add(l, r),
                    (Some(x), None) | (None, Some(x)) => x,
                    (None, None) => g.zero(),
                }
            })
            .collect();
        let first = vec3::dot(g, self.conv, other.value);
        let cross = vec3::dot(g, self.rate, other.rate);
        let cross = g.scale(2.0, cross);
        let last = vec3::dot(g, self.value, other.conv);
        let bias = g.add(first, cross);
        let bias = g.add(bias, last);
        Row { h, jacobian, bias }
    }
}

/// Derives every loop of `model`.
pub fn loop_terms(
    g: &mut Graph,
    model: &Model,
    kin: &[BodyKinematics],
    s: &Symbols,
) -> Vec<LoopTerms> {
    (0..model.loops.len())
        .map(|l| {
            let cut = &model.loops[l];
            g.set_section(format!(
                "loop {}: the cut {} joint, h, J, c",
                cut.name,
                cut.kind.name()
            ));
            let motions = [0, 1].map(|side| side_motion(g, model, kin, s, l, side));
            let [a, b] = [0, 1].map(|side| Carried::point(g, s, &motions[side]));
            let mut gap = a.minus(g, &b);
            gap.value = closure_gap(g, &motions);
            vec3::label(g, gap.value, &format!("loop_{}_gap", cut.name));
            let [body_a, body_b] = cut.sides.map(|p: LoopPoint| p.body);
            let rows = match (cut.kind, cut.planar) {
                (LoopKind::Revolute, true) => (0..2).map(|k| gap.component(g, k)).collect(),
                (LoopKind::Spherical, _) => (0..3).map(|k| gap.component(g, k)).collect(),
                (LoopKind::Revolute, false) => {
                    let mut rows: Vec<Row> = (0..3).map(|k| gap.component(g, k)).collect();
                    let axis = Carried::direction(g, model, kin, body_a, cut.axis_a, &motions[0]);
                    for e in normal_pair(cut.axis) {
                        let e = Carried::direction(g, model, kin, body_b, e, &motions[1]);
                        rows.push(axis.dot(g, &e));
                    }
                    rows
                }
                (LoopKind::Prismatic, _) => {
                    let [d, z] = [cut.axis, [0.0, 0.0, 1.0]];
                    let normal = [
                        z[1] * d[2] - z[2] * d[1],
                        z[2] * d[0] - z[0] * d[2],
                        z[0] * d[1] - z[1] * d[0],
                    ];
                    let n = Carried::direction(g, model, kin, body_b, normal, &motions[1]);
                    let along = Carried::direction(g, model, kin, body_a, cut.axis_a, &motions[0]);
                    vec![gap.dot(g, &n), along.dot(g, &n)]
                }
                (LoopKind::PointOnLine, true) => {
                    let d = cut.axis;
                    let normal = [-d[1], d[0], 0.0];
                    let n = Carried::direction(g, model, kin, body_b, normal, &motions[1]);
                    vec![gap.dot(g, &n)]
                }
                (LoopKind::PointOnLine, false) => normal_pair(cut.axis)
                    .into_iter()
                    .map(|e| {
                        let n = Carried::direction(g, model, kin, body_b, e, &motions[1]);
                        gap.dot(g, &n)
                    })
                    .collect(),
            };
            for (row, equation) in rows.iter().zip(cut.equations()) {
                g.label(row.h, format!("loop_{}_{equation}", cut.name));
            }
            LoopTerms {
                rows,
                points: [a.value, b.value],
            }
        })
        .collect()
}

/// The motion of loop l's point on `side`, relative to the ground.
fn side_motion(
    g: &mut Graph,
    model: &Model,
    kin: &[BodyKinematics],
    s: &Symbols,
    l: usize,
    side: usize,
) -> PointMotion {
    let cut = &model.loops[l];
    let point = cut.sides[side];
    let local = s.field3(g, model, |k| Field::LoopPoint(l, side, k), point.point);
    let moving = vec![true; model.n()];
    let name = format!("loop_{}_{}", cut.name, ["a", "b"][side]);
    point_motion(
        g,
        model,
        kin,
        s,
        point.body,
        local,
        &moving,
        &Labels { name: &name },
        |_, _, _| {},
    )
}
