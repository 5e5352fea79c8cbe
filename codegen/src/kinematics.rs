//! Forward recursion (ground → tip) on symbolic expressions, Fisette–Samin style (eq. 9).
//!
//! Velocities and accelerations of each body are expressed in the body's own frame, so a
//! joint only brings in the sine and cosine of its own angle; absolute rotations are kept as
//! "rotation about a fixed axis by an angle" as long as consecutive axes are parallel, so a
//! planar chain composes `q1 + q2 + q4` into one angle whose sine and cosine are computed
//! once (the Robotran treatment of sums of angles). Accelerations are [`Lin`] forms: the
//! coefficients of every q̈_j plus a velocity-dependent remainder and a gravity remainder
//! (gravity enters as the ground's acceleration −g), so the backward recursion can read off
//! M, F and the gravity part of Q separately.

use crate::expr::{Graph, Id};
use crate::model::{JointKind, Model};

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
}

impl Symbols {
    /// Creates the variables of `model` in `g`.
    pub fn new(g: &mut Graph, model: &Model) -> Self {
        let names = model.coordinate_names();
        let q = names.iter().map(|n| g.var(n)).collect();
        let qd = names.iter().map(|n| g.var(&format!("{n}_dot"))).collect();
        let t = g.var("t");
        Symbols { q, qd, t }
    }
}

/// An expression linear in the accelerations: Σ_j `qdd[j]`·q̈_j + vel + grav.
#[derive(Debug, Clone, PartialEq)]
pub struct Lin {
    /// Coefficient of each q̈_j.
    pub qdd: Vec<Id>,
    /// Remainder that depends on q̇ (Coriolis, centripetal).
    pub vel: Id,
    /// Remainder proportional to gravity.
    pub grav: Id,
}

impl Lin {
    /// The zero form over n accelerations.
    pub fn zero(g: &mut Graph, n: usize) -> Self {
        let z = g.zero();
        Lin {
            qdd: vec![z; n],
            vel: z,
            grav: z,
        }
    }

    /// a + b
    pub fn add(g: &mut Graph, a: &Lin, b: &Lin) -> Lin {
        Lin {
            qdd: a
                .qdd
                .iter()
                .zip(&b.qdd)
                .map(|(&x, &y)| g.add(x, y))
                .collect(),
            vel: g.add(a.vel, b.vel),
            grav: g.add(a.grav, b.grav),
        }
    }

    /// s · a for a scalar expression s.
    pub fn scale(g: &mut Graph, s: Id, a: &Lin) -> Lin {
        Lin {
            qdd: a.qdd.iter().map(|&x| g.mul(s, x)).collect(),
            vel: g.mul(s, a.vel),
            grav: g.mul(s, a.grav),
        }
    }

    /// a + v where v goes to the velocity remainder.
    pub fn add_vel(g: &mut Graph, a: &Lin, v: Id) -> Lin {
        let mut r = a.clone();
        r.vel = g.add(a.vel, v);
        r
    }

    /// a + s·q̈_j
    pub fn add_qdd(g: &mut Graph, a: &Lin, j: usize, s: Id) -> Lin {
        let mut r = a.clone();
        r.qdd[j] = g.add(a.qdd[j], s);
        r
    }
}

/// A 3-vector of [`Lin`] forms.
pub type L3 = [Lin; 3];

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

/// Helpers for 3-vectors of [`Lin`] forms.
pub mod lin3 {
    use super::*;

    /// A vector of pure velocity remainders.
    pub fn from_vel(g: &mut Graph, n: usize, v: V3) -> L3 {
        v.map(|c| {
            let z = Lin::zero(g, n);
            Lin::add_vel(g, &z, c)
        })
    }

    /// a + b
    pub fn add(g: &mut Graph, a: &L3, b: &L3) -> L3 {
        [
            Lin::add(g, &a[0], &b[0]),
            Lin::add(g, &a[1], &b[1]),
            Lin::add(g, &a[2], &b[2]),
        ]
    }

    /// a + v (v into the velocity remainder)
    pub fn add_vel(g: &mut Graph, a: &L3, v: V3) -> L3 {
        [
            Lin::add_vel(g, &a[0], v[0]),
            Lin::add_vel(g, &a[1], v[1]),
            Lin::add_vel(g, &a[2], v[2]),
        ]
    }

    /// a + axis·q̈_j
    pub fn add_qdd(g: &mut Graph, a: &L3, j: usize, axis: V3) -> L3 {
        [
            Lin::add_qdd(g, &a[0], j, axis[0]),
            Lin::add_qdd(g, &a[1], j, axis[1]),
            Lin::add_qdd(g, &a[2], j, axis[2]),
        ]
    }

    /// s · a
    pub fn scale(g: &mut Graph, s: Id, a: &L3) -> L3 {
        [
            Lin::scale(g, s, &a[0]),
            Lin::scale(g, s, &a[1]),
            Lin::scale(g, s, &a[2]),
        ]
    }

    /// a × v for a Lin vector a and an expression vector v.
    pub fn cross_v(g: &mut Graph, a: &L3, v: V3) -> L3 {
        let mut c = |i: usize, j: usize| {
            let p = Lin::scale(g, v[j], &a[i]);
            let neg_vi = g.neg(v[i]);
            let m = Lin::scale(g, neg_vi, &a[j]);
            Lin::add(g, &p, &m)
        };
        [c(1, 2), c(2, 0), c(0, 1)]
    }

    /// v × a for an expression vector v and a Lin vector a.
    pub fn v_cross(g: &mut Graph, v: V3, a: &L3) -> L3 {
        let x = cross_v(g, a, v);
        let minus_one = g.constant(-1.0);
        scale(g, minus_one, &x)
    }

    /// Constant matrix · Lin vector.
    pub fn mat_mul(g: &mut Graph, m: &[[f64; 3]; 3], a: &L3) -> L3 {
        let mut row = |r: [f64; 3]| {
            let mut acc = Lin::zero(g, a[0].qdd.len());
            for k in 0..3 {
                let c = g.constant(r[k]);
                let t = Lin::scale(g, c, &a[k]);
                acc = Lin::add(g, &acc, &t);
            }
            acc
        };
        [row(m[0]), row(m[1]), row(m[2])]
    }

    /// Rotation · Lin vector.
    pub fn rotate(g: &mut Graph, r: &[V3; 3], a: &L3) -> L3 {
        let mut row = |row: V3| {
            let mut acc = Lin::zero(g, a[0].qdd.len());
            for k in 0..3 {
                let t = Lin::scale(g, row[k], &a[k]);
                acc = Lin::add(g, &acc, &t);
            }
            acc
        };
        [row(r[0]), row(r[1]), row(r[2])]
    }

    /// e · a for an expression vector e.
    pub fn dot_v(g: &mut Graph, e: V3, a: &L3) -> Lin {
        let mut acc = Lin::zero(g, a[0].qdd.len());
        for k in 0..3 {
            let t = Lin::scale(g, e[k], &a[k]);
            acc = Lin::add(g, &acc, &t);
        }
        acc
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

    /// R · a for a Lin vector.
    pub fn apply_lin(&self, g: &mut Graph, a: &L3) -> L3 {
        if *self == Rotation::Identity {
            return a.clone();
        }
        let m = self.matrix(g);
        lin3::rotate(g, &m, a)
    }

    /// Rᵀ · a for a Lin vector.
    pub fn apply_transpose_lin(&self, g: &mut Graph, a: &L3) -> L3 {
        if *self == Rotation::Identity {
            return a.clone();
        }
        let m = self.transpose_rows(g);
        lin3::rotate(g, &m, a)
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
    /// Angular velocity, body frame.
    pub omega: V3,
    /// Velocity of the origin, body frame.
    pub velocity: V3,
    /// Angular acceleration, body frame.
    pub alpha: L3,
    /// Acceleration of the origin (including −g), body frame.
    pub accel: L3,
}

/// Forward recursion over all bodies (parents first), eq. (9).
pub fn forward(g: &mut Graph, model: &Model, s: &Symbols) -> Vec<BodyKinematics> {
    let n = model.n();
    let mut out: Vec<BodyKinematics> = Vec::with_capacity(n);
    let ground = ground_kinematics(g, model);
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

/// The ground as a "body" at rest whose acceleration is −g (gravity enters every body's
/// acceleration through the recursion and lands in the gravity remainder).
fn ground_kinematics(g: &mut Graph, model: &Model) -> BodyKinematics {
    let n = model.n();
    let zero = vec3::zero(g);
    let minus_g = vec3::constant(g, model.gravity.map(|x| -x));
    let accel = minus_g.map(|c| {
        let mut l = Lin::zero(g, n);
        l.grav = c;
        l
    });
    BodyKinematics {
        relative: Rotation::Identity,
        offset: zero,
        axis: zero,
        rotation: Rotation::Identity,
        origin: zero,
        omega: zero,
        velocity: zero,
        alpha: lin3::from_vel(g, n, zero),
        accel,
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
    let anchor = vec3::constant(g, joint.anchor);
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
    // Velocity of the joint point, parent frame: v_p + ω_p × r.
    let w_r = vec3::cross(g, p.omega, offset);
    let v_joint = vec3::add(g, p.velocity, w_r);
    // Acceleration of the joint point, parent frame: a_p + α_p × r + ω_p × (ω_p × r).
    let alpha_r = lin3::cross_v(g, &p.alpha, offset);
    let w_w_r = vec3::cross(g, p.omega, w_r);
    let a_joint = lin3::add(g, &p.accel, &alpha_r);
    let a_joint = lin3::add_vel(g, &a_joint, w_w_r);
    // Parent quantities seen in the body frame.
    let omega_p = relative.apply_transpose(g, p.omega);
    let alpha_p = relative.apply_transpose_lin(g, &p.alpha);
    let v_p = relative.apply_transpose(g, v_joint);
    let a_p = relative.apply_transpose_lin(g, &a_joint);
    let axis_rate = vec3::scale(g, qd, axis);
    let (omega, velocity, alpha, accel) = match joint.kind {
        JointKind::Revolute => {
            // ω = ω_p + e q̇;  α = α_p + e q̈ + ω_p × e q̇.
            let omega = vec3::add(g, omega_p, axis_rate);
            let coriolis = vec3::cross(g, omega_p, axis_rate);
            let alpha = lin3::add_qdd(g, &alpha_p, i, axis);
            let alpha = lin3::add_vel(g, &alpha, coriolis);
            (omega, v_p, alpha, a_p)
        }
        JointKind::Prismatic => {
            // v = v_p + e q̇;  a = a_p + e q̈ + 2 ω_p × e q̇.
            let velocity = vec3::add(g, v_p, axis_rate);
            let two = g.constant(2.0);
            let w_e = vec3::cross(g, omega_p, axis_rate);
            let coriolis = vec3::scale(g, two, w_e);
            let accel = lin3::add_qdd(g, &a_p, i, axis);
            let accel = lin3::add_vel(g, &accel, coriolis);
            (omega_p, velocity, alpha_p, accel)
        }
    };
    let rotation = p.rotation.compose(g, &relative);
    let moved = p.rotation.apply(g, offset);
    let origin = vec3::add(g, p.origin, moved);
    BodyKinematics {
        relative,
        offset,
        axis,
        rotation,
        origin,
        omega,
        velocity,
        alpha,
        accel,
    }
}

fn label_body(g: &mut Graph, k: &BodyKinematics, name: &str) {
    vec3::label(g, k.omega, &format!("omega_{name}"));
    vec3::label(g, k.velocity, &format!("vel_{name}"));
    vec3::label(g, k.origin, &format!("pos_{name}"));
}

/// A point fixed on a body: position (ground), and its acceleration as a Lin form
/// projected on a ground direction.
pub fn point_position(g: &mut Graph, k: &BodyKinematics, local: [f64; 3]) -> V3 {
    let m = vec3::constant(g, local);
    let moved = k.rotation.apply(g, m);
    vec3::add(g, k.origin, moved)
}

/// Acceleration of a body-fixed point, body frame: a_O + α × m + ω × (ω × m).
pub fn point_accel(g: &mut Graph, k: &BodyKinematics, local: [f64; 3]) -> L3 {
    let m = vec3::constant(g, local);
    let alpha_m = lin3::cross_v(g, &k.alpha, m);
    let w_m = vec3::cross(g, k.omega, m);
    let w_w_m = vec3::cross(g, k.omega, w_m);
    let a = lin3::add(g, &k.accel, &alpha_m);
    lin3::add_vel(g, &a, w_w_m)
}

/// Velocity of a body-fixed point, body frame: v_O + ω × m.
pub fn point_velocity(g: &mut Graph, k: &BodyKinematics, local: [f64; 3]) -> V3 {
    let m = vec3::constant(g, local);
    let w_m = vec3::cross(g, k.omega, m);
    vec3::add(g, k.velocity, w_m)
}
