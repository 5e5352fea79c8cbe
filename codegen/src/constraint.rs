//! The cam constraint on symbolic expressions, eqs. (1)–(8).
//!
//! For a marker A on body b and a cam y = f3(x) in a plane with origin o and axes
//! (x̂, ŷ): f1 = x̂·(p_A − o), f2 = ŷ·(p_A − o) (1), h = f2 − f3(f1) (3),
//! J = J2 − f3'(f1) J1 (5b), c = (J2 q̇)_q q̇ − f3' (J1 q̇)_q q̇ − f3'' (J1 q̇)² (7, 8).
//! J1, J2 and the convective terms are read off the point's acceleration from the forward
//! recursion (coefficients of q̈ and the velocity remainder), projected on the cam axes;
//! f3' and f3'' are derived symbolically from the profile.

use crate::expr::{Graph, Id};
use crate::kinematics::{BodyKinematics, V3, point_accel, point_position, vec3};
use crate::model::{Contact, Model};
use crate::profile::Scalar;

/// Symbolic terms of one contact.
#[derive(Debug, Clone)]
pub struct ContactTerms {
    /// The contact point in ground coordinates.
    pub position: V3,
    /// f1(q), cam x of the point (1).
    pub f1: Id,
    /// f2(q), cam y of the point (1).
    pub f2: Id,
    /// ∂f1/∂q.
    pub j1: Vec<Id>,
    /// ∂f2/∂q.
    pub j2: Vec<Id>,
    /// (J1 q̇)_q q̇.
    pub conv1: Id,
    /// (J2 q̇)_q q̇.
    pub conv2: Id,
    /// f3'(f1).
    pub slope: Id,
    /// f3''(f1).
    pub curvature: Id,
    /// h = f2 − f3(f1) (3).
    pub h: Id,
    /// J = J2 − f3' J1 (5b).
    pub jacobian: Vec<Id>,
    /// c of J q̈ + c = 0 (7, 8).
    pub bias: Id,
}

/// Converts a one-variable [`Scalar`] to the DAG, the variable standing for `var`.
pub fn scalar_to_expr(g: &mut Graph, s: &Scalar, var: Id) -> Id {
    match s {
        Scalar::Const(c) => g.constant(*c),
        Scalar::Var => var,
        Scalar::Neg(a) => {
            let a = scalar_to_expr(g, a, var);
            g.neg(a)
        }
        Scalar::Add(a, b) => {
            let (a, b) = (scalar_to_expr(g, a, var), scalar_to_expr(g, b, var));
            g.add(a, b)
        }
        Scalar::Sub(a, b) => {
            let (a, b) = (scalar_to_expr(g, a, var), scalar_to_expr(g, b, var));
            g.sub(a, b)
        }
        Scalar::Mul(a, b) => {
            let (a, b) = (scalar_to_expr(g, a, var), scalar_to_expr(g, b, var));
            g.mul(a, b)
        }
        Scalar::Div(a, b) => {
            let (a, b) = (scalar_to_expr(g, a, var), scalar_to_expr(g, b, var));
            g.div(a, b)
        }
        Scalar::Powi(a, n) => {
            let a = scalar_to_expr(g, a, var);
            g.powi(a, *n)
        }
        Scalar::Powf(a, b) => {
            let (a, b) = (scalar_to_expr(g, a, var), scalar_to_expr(g, b, var));
            g.powf(a, b)
        }
        Scalar::Call(f, a) => {
            let a = scalar_to_expr(g, a, var);
            g.call(*f, a)
        }
    }
}

/// f(v), f'(v), f''(v) of a one-variable expression, derived symbolically through a
/// placeholder variable `placeholder` and then substituted by the expression `at`.
pub fn value_and_derivatives(g: &mut Graph, s: &Scalar, placeholder: &str, at: Id) -> [Id; 3] {
    let x = g.var(placeholder);
    let f = scalar_to_expr(g, s, x);
    let d1 = g.diff(f, x);
    let d2 = g.diff(d1, x);
    [f, d1, d2].map(|e| g.substitute(e, x, at))
}

/// Derives the terms of every contact of `model`.
pub fn contact_terms(
    g: &mut Graph,
    model: &Model,
    kin: &[BodyKinematics],
    qd: &[Id],
) -> Vec<ContactTerms> {
    model
        .contacts
        .iter()
        .map(|c| one_contact(g, model, kin, qd, c))
        .collect()
}

fn one_contact(
    g: &mut Graph,
    model: &Model,
    kin: &[BodyKinematics],
    qd: &[Id],
    contact: &Contact,
) -> ContactTerms {
    g.set_section(format!(
        "contact {}: position on the cam, J1, J2, convective terms, h, J, c",
        contact.name
    ));
    let marker = &model.markers[contact.marker];
    let body = &kin[marker.body];
    let position = point_position(g, body, marker.position);
    let origin = vec3::constant(g, contact.origin);
    let rel = vec3::sub(g, position, origin);
    let (x_axis, y_axis) = (
        vec3::constant(g, contact.x_axis),
        vec3::constant(g, contact.y_axis),
    );
    let f1 = vec3::dot(g, x_axis, rel);
    let f2 = vec3::dot(g, y_axis, rel);
    // Cam axes seen in the body frame, to project the body-frame acceleration.
    let xb = body.rotation.apply_transpose(g, x_axis);
    let yb = body.rotation.apply_transpose(g, y_axis);
    let accel = point_accel(g, body, marker.position);
    let a1 = crate::kinematics::lin3::dot_v(g, xb, &accel);
    let a2 = crate::kinematics::lin3::dot_v(g, yb, &accel);
    let [f3, slope, curvature] =
        value_and_derivatives(g, &contact.profile, &format!("__cam_{}", contact.name), f1);
    let h = g.sub(f2, f3);
    let jacobian: Vec<Id> = a1
        .qdd
        .iter()
        .zip(&a2.qdd)
        .map(|(&j1, &j2)| {
            let s = g.mul(slope, j1);
            g.sub(j2, s)
        })
        .collect();
    let j1_qd = dot_list(g, &a1.qdd, qd);
    let bias = {
        let t1 = g.mul(slope, a1.vel);
        let sq = g.powi(j1_qd, 2);
        let t2 = g.mul(curvature, sq);
        let b = g.sub(a2.vel, t1);
        g.sub(b, t2)
    };
    let name = &contact.name;
    g.label(f1, format!("{name}_x"));
    g.label(f2, format!("{name}_y"));
    g.label(slope, format!("{name}_slope"));
    g.label(curvature, format!("{name}_curvature"));
    g.label(j1_qd, format!("{name}_x_rate"));
    ContactTerms {
        position,
        f1,
        f2,
        j1: a1.qdd,
        j2: a2.qdd,
        conv1: a1.vel,
        conv2: a2.vel,
        slope,
        curvature,
        h,
        jacobian,
        bias,
    }
}

/// Σ a_i b_i
pub fn dot_list(g: &mut Graph, a: &[Id], b: &[Id]) -> Id {
    let terms: Vec<Id> = a.iter().zip(b).map(|(&x, &y)| g.mul(x, y)).collect();
    g.sum(terms)
}
