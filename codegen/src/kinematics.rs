//! Forward recursion (ground → tip) on symbolic expressions, Fisette–Samin style (eq. 9).
//!
//! Velocities and accelerations of each body are expressed in the body's own frame, so a
//! joint only brings in the sine and cosine of its own angle; absolute rotations are kept as
//! "rotation about a fixed axis by an angle" as long as consecutive axes are parallel, so a
//! planar chain composes `q1 + q2 + q4` into one angle whose sine and cosine are computed
//! once (the Robotran treatment of sums of angles). Accelerations carry only their
//! velocity-product part (the q̈ coefficients are not needed: M comes from composite inertias,
//! the contact Jacobian from the joint axes in the ground frame), and the gravity vector is
//! carried separately, seen in each body's frame, so that F and the gravity part of Q are
//! separate recursions and each only costs O(n).

use crate::expr::scalar::scalar_to_expr;
use crate::expr::{Graph, Id};
use crate::model::{Field, JointKind, Model};
use crate::profile::Scalar;

/// A 3-vector of expressions.
pub type V3 = [Id; 3];

/// Symbols of the generalised coordinates, velocities and time.
#[derive(Debug, Clone)]
pub struct Symbols {
    /// q_i, named after the coordinates.
    pub q: Vec<Id>,
    /// q̇_i, named `<coordinate>_dot`.
    pub qd: Vec<Id>,
    /// Time t.
    pub t: Id,
    /// One entry per model parameter: the variable of a run-time parameter, or the value of
    /// a constant one (which the validated expressions never mention).
    pub params: Vec<Id>,
}

impl Symbols {
    /// Creates the variables of `model` in `g`: coordinates, velocities, time, and the
    /// run-time parameters (after them, so that a model without any gets the same graph).
    pub fn new(g: &mut Graph, model: &Model) -> Self {
        let names = model.coordinate_names();
        let q = names.iter().map(|n| g.var(n)).collect();
        let qd = names.iter().map(|n| g.var(&format!("{n}_dot"))).collect();
        let t = g.var("t");
        if model.runtime_parameters().next().is_some() {
            g.set_section("run-time parameters (values stored when they are set)");
        }
        let params = model
            .parameters
            .iter()
            .map(|p| {
                if p.constant {
                    g.constant(p.value)
                } else {
                    g.var(&p.name)
                }
            })
            .collect();
        Symbols { q, qd, t, params }
    }

    /// True when `id` is the variable of a run-time parameter.
    pub fn is_parameter(&self, g: &Graph, id: Id) -> bool {
        matches!(g.node(id), crate::expr::Node::Var(_)) && self.params.contains(&id)
    }

    /// A numeric field: its expression of run-time parameters if the model has one,
    /// otherwise the constant `value` (exactly as before parameters existed).
    pub fn field(&self, g: &mut Graph, model: &Model, field: Field, value: f64) -> Id {
        self.field_scaled(g, model, field, value, 1.0)
    }

    /// `factor` times a numeric field (`0.5 k` of a spring's energy): folded into one
    /// constant when the field is constant.
    pub fn field_scaled(
        &self,
        g: &mut Graph,
        model: &Model,
        field: Field,
        value: f64,
        factor: f64,
    ) -> Id {
        match model.symbolic.get(&field) {
            Some(expr) => {
                let zero = g.zero();
                let e = scalar_to_expr(g, expr, zero, &self.params);
                let k = g.constant(factor);
                g.mul(k, e)
            }
            None => g.constant(factor * value),
        }
    }

    /// Three numeric fields (a point, a vector) keyed by component.
    pub fn field3(
        &self,
        g: &mut Graph,
        model: &Model,
        key: impl Fn(usize) -> Field,
        value: [f64; 3],
    ) -> V3 {
        [0, 1, 2].map(|k| self.field(g, model, key(k), value[k]))
    }

    /// An expression field (a profile, a drive): the one with run-time parameters if the
    /// model has it, otherwise `resolved`.
    pub fn expression<'m>(
        &self,
        model: &'m Model,
        field: Field,
        resolved: &'m Scalar,
    ) -> &'m Scalar {
        model.symbolic.get(&field).unwrap_or(resolved)
    }

    /// True when any of the fields is read at run time.
    pub fn any_runtime(model: &Model, fields: impl IntoIterator<Item = Field>) -> bool {
        fields.into_iter().any(|f| model.symbolic.contains_key(&f))
    }
}

/// Helpers for constant and symbolic 3-vectors.
pub mod vec3 {
    use super::*;

    /// A constant vector.
    pub fn constant(g: &mut Graph, v: [f64; 3]) -> V3 {
        [g.constant(v[0]), g.constant(v[1]), g.constant(v[2])]
    }

    /// The zero vector.
    pub fn zero(g: &mut Graph) -> V3 {
        let z = g.zero();
        [z, z, z]
    }

    /// a + b
    pub fn add(g: &mut Graph, a: V3, b: V3) -> V3 {
        [g.add(a[0], b[0]), g.add(a[1], b[1]), g.add(a[2], b[2])]
    }

    /// a − b
    pub fn sub(g: &mut Graph, a: V3, b: V3) -> V3 {
        [g.sub(a[0], b[0]), g.sub(a[1], b[1]), g.sub(a[2], b[2])]
    }

    /// s · a
    pub fn scale(g: &mut Graph, s: Id, a: V3) -> V3 {
        [g.mul(s, a[0]), g.mul(s, a[1]), g.mul(s, a[2])]
    }

    /// a · b
    pub fn dot(g: &mut Graph, a: V3, b: V3) -> Id {
        let terms = [g.mul(a[0], b[0]), g.mul(a[1], b[1]), g.mul(a[2], b[2])];
        g.sum(terms)
    }

    /// a × b
    pub fn cross(g: &mut Graph, a: V3, b: V3) -> V3 {
        let mut c = |i: usize, j: usize| {
            let p = g.mul(a[i], b[j]);
            let m = g.mul(a[j], b[i]);
            g.sub(p, m)
        };
        [c(1, 2), c(2, 0), c(0, 1)]
    }

    /// ω × (ω × r), written as ω (ω·r) − r (ω·ω): ω·ω is shared by every point of a body,
    /// and for rotation about a fixed axis perpendicular to r (planar motion) ω·r is a
    /// structural zero, leaving −|ω|² r.
    pub fn omega_omega(g: &mut Graph, w: V3, r: V3) -> V3 {
        let wr = dot(g, w, r);
        let ww = dot(g, w, w);
        let a = scale(g, wr, w);
        let b = scale(g, ww, r);
        sub(g, a, b)
    }

    /// Matrix · vector for a constant matrix (an inertia tensor).
    pub fn mat_mul(g: &mut Graph, m: &[[f64; 3]; 3], v: V3) -> V3 {
        let row = |g: &mut Graph, r: [f64; 3]| {
            let r = constant(g, r);
            dot(g, r, v)
        };
        [row(g, m[0]), row(g, m[1]), row(g, m[2])]
    }

    /// Labels the three components `name_x`, `name_y`, `name_z`.
    pub fn label(g: &mut Graph, v: V3, name: &str) {
        for (c, axis) in v.iter().zip(["x", "y", "z"]) {
            g.label(*c, format!("{name}_{axis}"));
        }
    }
}

/// A rotation: about a constant unit axis by a symbolic angle (kept in this form so that
/// rotations about parallel axes compose by adding angles), or a general matrix.
#[derive(Debug, Clone, PartialEq)]
pub enum Rotation {
    /// No rotation.
    Identity,
    /// Rotation by `angle` about the constant unit `axis`.
    Axis {
        /// Unit axis.
        axis: [f64; 3],
        /// Angle expression.
        angle: Id,
    },
    /// A general rotation matrix (rows).
    Matrix([V3; 3]),
}

impl Rotation {
    /// The matrix rows (Rodrigues' formula, with structural zeros and ones exact).
    pub fn matrix(&self, g: &mut Graph) -> [V3; 3] {
        match self {
            Rotation::Identity => {
                let (z, o) = (g.zero(), g.one());
                [[o, z, z], [z, o, z], [z, z, o]]
            }
            Rotation::Matrix(m) => *m,
            Rotation::Axis { axis, angle } => axis_matrix(g, *axis, *angle),
        }
    }

    /// self · other, adding angles when both turn about the same axis.
    pub fn compose(&self, g: &mut Graph, other: &Rotation) -> Rotation {
        match (self, other) {
            (Rotation::Identity, r) | (r, Rotation::Identity) => r.clone(),
            (Rotation::Axis { axis: a, angle: x }, Rotation::Axis { axis: b, angle: y })
                if a == b =>
            {
                Rotation::Axis {
                    axis: *a,
                    angle: g.add(*x, *y),
                }
            }
            _ => {
                let (m, n) = (self.matrix(g), other.matrix(g));
                let mut rows = [[g.zero(); 3]; 3];
                for (i, row) in rows.iter_mut().enumerate() {
                    for (j, cell) in row.iter_mut().enumerate() {
                        let col = [n[0][j], n[1][j], n[2][j]];
                        *cell = vec3::dot(g, m[i], col);
                    }
                }
                Rotation::Matrix(rows)
            }
        }
    }

    /// R · v
    pub fn apply(&self, g: &mut Graph, v: V3) -> V3 {
        if *self == Rotation::Identity {
            return v;
        }
        let m = self.matrix(g);
        [
            vec3::dot(g, m[0], v),
            vec3::dot(g, m[1], v),
            vec3::dot(g, m[2], v),
        ]
    }

    /// Rᵀ · v
    pub fn apply_transpose(&self, g: &mut Graph, v: V3) -> V3 {
        if *self == Rotation::Identity {
            return v;
        }
        let m = self.transpose_rows(g);
        [
            vec3::dot(g, m[0], v),
            vec3::dot(g, m[1], v),
            vec3::dot(g, m[2], v),
        ]
    }

    /// Rows of Rᵀ.
    pub fn transpose_rows(&self, g: &mut Graph) -> [V3; 3] {
        let m = self.matrix(g);
        [
            [m[0][0], m[1][0], m[2][0]],
            [m[0][1], m[1][1], m[2][1]],
            [m[0][2], m[1][2], m[2][2]],
        ]
    }
}

/// Rodrigues: R = c I + s [a]× + (1 − c) a aᵀ.
fn axis_matrix(g: &mut Graph, a: [f64; 3], angle: Id) -> [V3; 3] {
    let c = g.cos(angle);
    let s = g.sin(angle);
    let one = g.one();
    let omc = g.sub(one, c);
    let mut entry = |i: usize, j: usize| {
        let outer = a[i] * a[j];
        let sym = if outer == 1.0 && i == j {
            return one;
        } else {
            let t = g.constant(outer);
            g.mul(t, omc)
        };
        let diag = if i == j { c } else { g.zero() };
        // [a]× has (i, j) entry −ε_ijk a_k.
        let skew = if i == j {
            g.zero()
        } else {
            let k = 3 - i - j;
            let sign = if (j + 3 - i) % 3 == 1 { -1.0 } else { 1.0 };
            let coef = g.constant(sign * a[k]);
            g.mul(coef, s)
        };
        let d = g.add(diag, sym);
        g.add(d, skew)
    };
    [
        [entry(0, 0), entry(0, 1), entry(0, 2)],
        [entry(1, 0), entry(1, 1), entry(1, 2)],
        [entry(2, 0), entry(2, 1), entry(2, 2)],
    ]
}

/// Kinematic quantities of one body.
#[derive(Debug, Clone)]
pub struct BodyKinematics {
    /// Rotation body → parent produced by the joint.
    pub relative: Rotation,
    /// Position of the body's origin (its joint point) in the parent's frame.
    pub offset: V3,
    /// Joint axis (the same in the parent's and the body's frame).
    pub axis: V3,
    /// Absolute rotation body → ground.
    pub rotation: Rotation,
    /// Origin in ground coordinates.
    pub origin: V3,
    /// Origin minus the parent's origin, ground coordinates (the offset seen from the ground).
    pub step: V3,
    /// Joint axis in ground coordinates.
    pub axis_ground: V3,
    /// Angular velocity, body frame.
    pub omega: V3,
    /// Velocity of the origin, body frame.
    pub velocity: V3,
    /// Velocity-product part of the angular acceleration (q̈ = 0), body frame.
    pub alpha: V3,
    /// Velocity-product part of the origin's acceleration (q̈ = 0), body frame.
    pub accel: V3,
    /// The same acceleration in the parent's frame (`accel` = Rᵀ · this): the backward
    /// recursion moves a body's m·a to its parent with this vector instead of rotating
    /// `accel` back (R Rᵀ = I is an identity the expression engine cannot see).
    pub accel_in_parent: V3,
    /// −g (gravity enters as an acceleration of the ground) seen in the body frame.
    pub gravity: V3,
    /// What the body adds to its parent's acceleration to make `accel`.
    pub carried: Carried,
}

/// The terms a body adds to its parent's velocity-product acceleration a_p: at its joint
/// point (a_p + α_p × r) + ω_p × (ω_p × r), parent frame; seen in its own frame, plus
/// 2 ω_p × e q̇ on a prismatic joint. One recursion for any a_p: the kinematics' `accel`
/// starts from zero at the ground, the articulated sweeps' from −g (gravity carried with
/// the acceleration, not rotated body by body beside it).
#[derive(Debug, Clone, Copy)]
pub struct Carried {
    /// α_p × r.
    pub tangential: V3,
    /// ω_p × (ω_p × r).
    pub centripetal: V3,
    /// 2 ω_p × e q̇ (prismatic), zero (revolute).
    pub coriolis: V3,
}

impl Carried {
    /// The joint point's acceleration, parent frame, from the parent's `parent`.
    pub fn at_joint(&self, g: &mut Graph, parent: V3) -> V3 {
        let a = vec3::add(g, parent, self.tangential);
        vec3::add(g, a, self.centripetal)
    }

    /// The body's acceleration, own frame, from the joint point's `at_joint`.
    pub fn in_body(&self, g: &mut Graph, relative: &Rotation, at_joint: V3) -> V3 {
        let seen = relative.apply_transpose(g, at_joint);
        vec3::add(g, seen, self.coriolis)
    }
}

/// −g in ground coordinates (gravity enters as an acceleration of the ground).
pub fn minus_gravity(g: &mut Graph, model: &Model, s: &Symbols) -> V3 {
    let gravity = s.field3(g, model, Field::Gravity, model.gravity);
    [0, 1, 2].map(|k| g.neg(gravity[k]))
}

/// Forward recursion over all bodies (parents first), eq. (9).
pub fn forward(g: &mut Graph, model: &Model, s: &Symbols) -> Vec<BodyKinematics> {
    let mut out: Vec<BodyKinematics> = Vec::with_capacity(model.n());
    let ground = ground_kinematics(g, model, s);
    for (i, body) in model.bodies.iter().enumerate() {
        let parent = match body.parent {
            Some(p) => &out[p],
            None => &ground,
        };
        g.set_section(format!(
            "{}: joint {}, rotation, velocities and accelerations",
            body.name, body.joint.coordinate
        ));
        let k = child_kinematics(g, model, s, i, parent);
        label_body(g, &k, &body.name);
        out.push(k);
    }
    out
}

/// The ground as a "body" at rest.
fn ground_kinematics(g: &mut Graph, model: &Model, s: &Symbols) -> BodyKinematics {
    let zero = vec3::zero(g);
    let gravity = minus_gravity(g, model, s);
    BodyKinematics {
        relative: Rotation::Identity,
        offset: zero,
        axis: zero,
        rotation: Rotation::Identity,
        origin: zero,
        step: zero,
        axis_ground: zero,
        omega: zero,
        velocity: zero,
        alpha: zero,
        accel: zero,
        accel_in_parent: zero,
        gravity,
        carried: Carried {
            tangential: zero,
            centripetal: zero,
            coriolis: zero,
        },
    }
}

fn child_kinematics(
    g: &mut Graph,
    model: &Model,
    s: &Symbols,
    i: usize,
    p: &BodyKinematics,
) -> BodyKinematics {
    let joint = &model.bodies[i].joint;
    let axis = vec3::constant(g, joint.axis);
    let anchor = s.field3(g, model, |k| Field::Anchor(i, k), joint.anchor);
    let (q, qd) = (s.q[i], s.qd[i]);
    let (relative, offset) = match joint.kind {
        JointKind::Revolute => (
            Rotation::Axis {
                axis: joint.axis,
                angle: q,
            },
            anchor,
        ),
        JointKind::Prismatic => {
            let slide = vec3::scale(g, q, axis);
            (Rotation::Identity, vec3::add(g, anchor, slide))
        }
    };
    let name = &model.bodies[i].name;
    // Velocity of the joint point, parent frame: v_p + ω_p × r.
    let w_r = vec3::cross(g, p.omega, offset);
    vec3::label(g, w_r, &format!("vel_rel_{name}"));
    let v_joint = vec3::add(g, p.velocity, w_r);
    vec3::label(g, v_joint, &format!("vel_{name}_in_parent"));
    // Acceleration of the joint point, parent frame: a_p + α_p × r + ω_p × (ω_p × r).
    let alpha_r = vec3::cross(g, p.alpha, offset);
    vec3::label(g, alpha_r, &format!("tangential_{name}"));
    let w_w_r = vec3::omega_omega(g, p.omega, offset);
    vec3::label(g, w_w_r, &format!("centripetal_{name}"));
    let w_dot_r = vec3::dot(g, p.omega, offset);
    g.label(w_dot_r, format!("omega_dot_offset_{name}"));
    let mut carried = Carried {
        tangential: alpha_r,
        centripetal: w_w_r,
        coriolis: vec3::zero(g),
    };
    let a_joint = carried.at_joint(g, p.accel);
    // Parent quantities seen in the body frame.
    if relative != Rotation::Identity {
        let rows = relative.matrix(g);
        label_matrix(g, &rows, &format!("rel_rot_{name}"));
    }
    let omega_p = relative.apply_transpose(g, p.omega);
    vec3::label(g, omega_p, &format!("omega_parent_{name}"));
    let alpha_p = relative.apply_transpose(g, p.alpha);
    vec3::label(g, alpha_p, &format!("alpha_parent_{name}"));
    let v_p = relative.apply_transpose(g, v_joint);
    let a_p = carried.in_body(g, &relative, a_joint);
    let axis_rate = vec3::scale(g, qd, axis);
    let (omega, velocity, alpha, accel, accel_in_parent) = match joint.kind {
        JointKind::Revolute => {
            // ω = ω_p + e q̇;  α = α_p + ω_p × e q̇ (+ e q̈).
            let omega = vec3::add(g, omega_p, axis_rate);
            let coriolis = vec3::cross(g, omega_p, axis_rate);
            vec3::label(g, coriolis, &format!("coriolis_{name}"));
            let alpha = vec3::add(g, alpha_p, coriolis);
            (omega, v_p, alpha, a_p, a_joint)
        }
        JointKind::Prismatic => {
            // v = v_p + e q̇;  a = a_p + 2 ω_p × e q̇ (+ e q̈). No rotation: the body's
            // frame is its parent's, so the acceleration is the same vector in both.
            let velocity = vec3::add(g, v_p, axis_rate);
            let two = g.constant(2.0);
            let w_e = vec3::cross(g, omega_p, axis_rate);
            let coriolis = vec3::scale(g, two, w_e);
            vec3::label(g, coriolis, &format!("coriolis_{name}"));
            carried.coriolis = coriolis;
            let accel = vec3::add(g, a_p, coriolis);
            (omega_p, velocity, alpha_p, accel, accel)
        }
    };
    let rotation = p.rotation.compose(g, &relative);
    let gravity = gravity_in_body(g, model, s, &rotation, &relative, p);
    let step = p.rotation.apply(g, offset);
    let origin = vec3::add(g, p.origin, step);
    let axis_ground = p.rotation.apply(g, axis);
    BodyKinematics {
        relative,
        offset,
        axis,
        rotation,
        origin,
        step,
        axis_ground,
        omega,
        velocity,
        alpha,
        accel,
        accel_in_parent,
        gravity,
        carried,
    }
}

/// −g in the body frame. While the absolute rotation is one angle about a fixed axis (a
/// planar chain), −g is rotated from the ground with that angle's sine and cosine: two
/// products per body instead of rotating the parent's vector (four products and two
/// additions), and the same sine and cosine a contact point on the chain needs anyway (the
/// generated right-hand side computes them once, at the position level). Otherwise −g is
/// carried down from the parent with the joint's rotation.
fn gravity_in_body(
    g: &mut Graph,
    model: &Model,
    s: &Symbols,
    rotation: &Rotation,
    relative: &Rotation,
    p: &BodyKinematics,
) -> V3 {
    match rotation {
        Rotation::Axis { .. } => {
            let ground = minus_gravity(g, model, s);
            rotation.apply_transpose(g, ground)
        }
        _ => relative.apply_transpose(g, p.gravity),
    }
}

/// Names the body's quantities in the emitted code (Robotran style: quantity, body, axis).
/// Labels are only names: a node another quantity already named keeps its first name.
fn label_body(g: &mut Graph, k: &BodyKinematics, name: &str) {
    vec3::label(g, k.omega, &format!("omega_{name}"));
    let omega_sq = vec3::dot(g, k.omega, k.omega);
    g.label(omega_sq, format!("omega_{name}_sq"));
    vec3::label(g, k.velocity, &format!("vel_{name}"));
    vec3::label(g, k.alpha, &format!("alpha_{name}"));
    vec3::label(g, k.accel, &format!("acc_{name}"));
    vec3::label(g, k.accel_in_parent, &format!("acc_{name}_in_parent"));
    vec3::label(g, k.offset, &format!("offset_{name}"));
    vec3::label(g, k.gravity, &format!("minus_g_{name}"));
    vec3::label(g, k.origin, &format!("pos_{name}"));
    vec3::label(g, k.step, &format!("step_{name}"));
    vec3::label(g, k.axis_ground, &format!("axis_{name}"));
    if let Rotation::Matrix(rows) = &k.rotation {
        label_matrix(g, rows, &format!("rot_{name}"));
    }
}

/// Labels the entries of a rotation matrix `name_11` … `name_33`.
fn label_matrix(g: &mut Graph, rows: &[V3; 3], name: &str) {
    for (i, row) in rows.iter().enumerate() {
        for (j, &entry) in row.iter().enumerate() {
            g.label(entry, format!("{name}_{}{}", i + 1, j + 1));
        }
    }
}

/// A point fixed on a body (`local`, body frame): its position in ground coordinates.
pub fn point_position(g: &mut Graph, k: &BodyKinematics, local: V3) -> V3 {
    let m = local;
    let moved = k.rotation.apply(g, m);
    vec3::add(g, k.origin, moved)
}

/// Velocity of a body-fixed point, body frame: v_O + ω × m.
pub fn point_velocity(g: &mut Graph, k: &BodyKinematics, local: V3) -> V3 {
    let m = local;
    let w_m = vec3::cross(g, k.omega, m);
    vec3::add(g, k.velocity, w_m)
}
