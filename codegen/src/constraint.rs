//! The cam constraint on symbolic expressions, eqs. (1)–(8).
//!
//! For a marker A on body b and a cam y = f3(x) in a plane with origin o and axes
//! (x̂, ŷ): f1 = x̂·(p_A − o), f2 = ŷ·(p_A − o) (1), h = f2 − f3(f1) (3),
//! J = J2 − f3'(f1) J1 (5b), c = (J2 q̇)_q q̇ − f3' (J1 q̇)_q q̇ − f3'' (J1 q̇)² (7, 8).
//! Everything is formed in the ground frame, where a planar chain's absolute angles make the
//! closed forms short: the Jacobian column of joint j is u_j × (p_A − o_j) for a revolute
//! joint and u_j for a prismatic one (u_j the joint axis, o_j the joint point, both in the
//! ground frame), with p_A − o_j summed from the tip; the convective acceleration of A comes
//! from a ground-frame recursion along the path from the ground to the marker's body. Both
//! are projected on the cam axes; f3' and f3'' are derived symbolically from the profile.

use crate::expr::{Graph, Id};
use crate::kinematics::{BodyKinematics, Symbols, V3, vec3};
use crate::model::{Contact, Field, JointKind, Model};
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

/// Converts a one-variable [`Scalar`] to the DAG, the variable standing for `var` and
/// parameter i for `params[i]` (its graph variable, or its value when it is folded).
pub fn scalar_to_expr(g: &mut Graph, s: &Scalar, var: Id, params: &[Id]) -> Id {
    let mut to = |e: &Scalar| scalar_to_expr(g, e, var, params);
    match s {
        Scalar::Const(c) => g.constant(*c),
        Scalar::Var => var,
        Scalar::Param(i) => params
            .get(*i)
            .copied()
            .unwrap_or_else(|| g.constant(f64::NAN)),
        Scalar::Neg(a) => {
            let a = to(a);
            g.neg(a)
        }
        Scalar::Add(a, b) => {
            let (a, b) = (to(a), to(b));
            g.add(a, b)
        }
        Scalar::Sub(a, b) => {
            let (a, b) = (to(a), to(b));
            g.sub(a, b)
        }
        Scalar::Mul(a, b) => {
            let (a, b) = (to(a), to(b));
            g.mul(a, b)
        }
        Scalar::Div(a, b) => {
            let (a, b) = (to(a), to(b));
            g.div(a, b)
        }
        Scalar::Powi(a, n) => {
            let a = to(a);
            g.powi(a, *n)
        }
        Scalar::Powf(a, b) => {
            let (a, b) = (to(a), to(b));
            g.powf(a, b)
        }
        Scalar::Call(f, a) => {
            let a = to(a);
            g.call(*f, a)
        }
    }
}

/// f(v), f'(v), f''(v) of a one-variable expression, derived symbolically through a
/// placeholder variable `placeholder` and then substituted by the expression `at`.
///
/// A polynomial (a cam profile such as −0.595x + 0.5x² + 0.5x³) is written by Horner's
/// rule instead, value and both derivatives: n multiplications and at most n additions for
/// degree n, where the expression as written would raise powers separately.
///
/// `params` maps the expression's parameters to the graph (see [`scalar_to_expr`]); the
/// derivatives are taken with respect to the variable only.
pub fn value_and_derivatives(
    g: &mut Graph,
    s: &Scalar,
    placeholder: &str,
    at: Id,
    params: &[Id],
) -> [Id; 3] {
    if let Some(c) = polynomial(s) {
        let d1: Vec<f64> = (1..c.len()).map(|k| k as f64 * c[k]).collect();
        let d2: Vec<f64> = (1..d1.len()).map(|k| k as f64 * d1[k]).collect();
        return [&c[..], &d1[..], &d2[..]].map(|c| horner(g, c, at));
    }
    let x = g.var(placeholder);
    let f = scalar_to_expr(g, s, x, params);
    let d1 = g.diff(f, x);
    let d2 = g.diff(d1, x);
    [f, d1, d2].map(|e| g.substitute(e, x, at))
}

/// Highest degree written by Horner's rule (beyond it the expression is kept as written).
const MAX_POLYNOMIAL_DEGREE: usize = 16;

/// The coefficients c₀, c₁, … of `s` if it is a polynomial in its variable of degree at
/// most [`MAX_POLYNOMIAL_DEGREE`] (constants, the variable, +, −, ·, division by a constant,
/// non-negative integer powers), otherwise `None`.
fn polynomial(s: &Scalar) -> Option<Vec<f64>> {
    let p = match s {
        Scalar::Const(c) => vec![*c],
        Scalar::Var => vec![0.0, 1.0],
        Scalar::Neg(a) => polynomial(a)?.iter().map(|c| -c).collect(),
        Scalar::Add(a, b) => combine(&polynomial(a)?, &polynomial(b)?, 1.0),
        Scalar::Sub(a, b) => combine(&polynomial(a)?, &polynomial(b)?, -1.0),
        Scalar::Mul(a, b) => product(&polynomial(a)?, &polynomial(b)?)?,
        Scalar::Div(a, b) => match polynomial(b)?.as_slice() {
            [d] if *d != 0.0 => polynomial(a)?.iter().map(|c| c / d).collect(),
            _ => return None,
        },
        Scalar::Powi(a, n) if (0..=MAX_POLYNOMIAL_DEGREE as i32).contains(n) => {
            let base = polynomial(a)?;
            let mut p = vec![1.0];
            for _ in 0..*n {
                p = product(&p, &base)?;
            }
            p
        }
        _ => return None,
    };
    p.iter().all(|c| c.is_finite()).then_some(p)
}

fn combine(a: &[f64], b: &[f64], sign: f64) -> Vec<f64> {
    (0..a.len().max(b.len()))
        .map(|k| a.get(k).copied().unwrap_or(0.0) + sign * b.get(k).copied().unwrap_or(0.0))
        .collect()
}

fn product(a: &[f64], b: &[f64]) -> Option<Vec<f64>> {
    let degree = (a.len() - 1) + (b.len() - 1);
    if degree > MAX_POLYNOMIAL_DEGREE {
        return None;
    }
    let mut p = vec![0.0; degree + 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            p[i + j] += x * y;
        }
    }
    Some(p)
}

/// c₀ + x (c₁ + x (c₂ + …)) (zero terms fold away; an empty list is 0).
fn horner(g: &mut Graph, c: &[f64], x: Id) -> Id {
    let mut acc = g.zero();
    for &ck in c.iter().rev() {
        let times = g.mul(acc, x);
        let k = g.constant(ck);
        acc = g.add(times, k);
    }
    acc
}

/// Derives the terms of every contact of `model`.
pub fn contact_terms(
    g: &mut Graph,
    model: &Model,
    kin: &[BodyKinematics],
    s: &Symbols,
) -> Vec<ContactTerms> {
    (0..model.contacts.len())
        .map(|c| one_contact(g, model, kin, s, c))
        .collect()
}

fn one_contact(
    g: &mut Graph,
    model: &Model,
    kin: &[BodyKinematics],
    s: &Symbols,
    index: usize,
) -> ContactTerms {
    let contact: &Contact = &model.contacts[index];
    let qd = &s.qd;
    g.set_section(format!(
        "contact {}: position on the cam, J1, J2, convective terms, h, J, c",
        contact.name
    ));
    let marker = &model.markers[contact.marker];
    // The joints between the ground and the marker's body, tip first.
    let mut path = Vec::new();
    let mut at = Some(marker.body);
    while let Some(j) = at {
        path.push(j);
        at = model.bodies[j].parent;
    }
    // Angular velocity and the velocity-product part of the angular acceleration of every
    // body on the path, ground frame (from the ground out).
    let n = model.n();
    let zero3 = vec3::zero(g);
    let (mut omega, mut alpha) = (vec![zero3; n], vec![zero3; n]);
    let (mut w, mut a) = (zero3, zero3);
    let mut coriolis = zero3;
    for &j in path.iter().rev() {
        let k = &kin[j];
        match model.bodies[j].joint.kind {
            JointKind::Revolute => {
                let rate = vec3::scale(g, qd[j], k.axis_ground);
                let w_e = vec3::cross(g, w, rate);
                a = vec3::add(g, a, w_e);
                w = vec3::add(g, w, rate);
            }
            JointKind::Prismatic => {
                // 2 ω × e q̇ of the sliding joint point, as (2 q̇ ω) × e: scalars first.
                let two = g.constant(2.0);
                let two_qd = g.mul(two, qd[j]);
                let tw = vec3::scale(g, two_qd, w);
                let cor = vec3::cross(g, tw, k.axis_ground);
                coriolis = vec3::add(g, coriolis, cor);
            }
        }
        let coordinate = &model.bodies[j].joint.coordinate;
        vec3::label(g, w, &format!("{}_omega_{coordinate}", contact.name));
        vec3::label(g, a, &format!("{}_alpha_{coordinate}", contact.name));
        omega[j] = w;
        alpha[j] = a;
    }
    vec3::label(g, coriolis, &format!("{}_coriolis", contact.name));
    // From the tip down: p_A − o_j for the Jacobian columns, and the convective acceleration
    // α × s + ω × (ω × s) of each segment s. Across a prismatic joint the two bodies turn
    // together, so their segments are summed in the common frame before being rotated
    // (`pending`, in the frame of `body`): (l2 + q3 + l3) once instead of two segments.
    let mut pending = s.field3(
        g,
        model,
        |k| Field::Marker(contact.marker, k),
        marker.position,
    );
    let mut done = zero3;
    let mut accel = coriolis;
    let (mut j1, mut j2) = (vec![g.zero(); n], vec![g.zero(); n]);
    let (x_axis, y_axis) = (
        vec3::constant(g, contact.x_axis),
        vec3::constant(g, contact.y_axis),
    );
    for &j in &path {
        let k = &kin[j];
        let column = match model.bodies[j].joint.kind {
            JointKind::Revolute => {
                let seg = k.rotation.apply(g, pending);
                let (name, coordinate) = (&contact.name, &model.bodies[j].joint.coordinate);
                vec3::label(g, seg, &format!("{name}_segment_{coordinate}"));
                let a_s = vec3::cross(g, alpha[j], seg);
                vec3::label(g, a_s, &format!("{name}_tangential_{coordinate}"));
                let w_w_s = vec3::omega_omega(g, omega[j], seg);
                vec3::label(g, w_w_s, &format!("{name}_centripetal_{coordinate}"));
                let w_s = vec3::dot(g, omega[j], seg);
                g.label(w_s, format!("{name}_omega_dot_segment_{coordinate}"));
                accel = vec3::add(g, accel, a_s);
                accel = vec3::add(g, accel, w_w_s);
                done = vec3::add(g, seg, done);
                pending = k.offset;
                vec3::cross(g, k.axis_ground, done)
            }
            JointKind::Prismatic => {
                // No rotation at this joint: the segment continues in the same frame.
                pending = vec3::add(g, k.offset, pending);
                k.axis_ground
            }
        };
        j1[j] = vec3::dot(g, x_axis, column);
        j2[j] = vec3::dot(g, y_axis, column);
        let (name, coordinate) = (&contact.name, &model.bodies[j].joint.coordinate);
        vec3::label(g, done, &format!("{name}_arm_{coordinate}"));
        g.label(j1[j], format!("{name}_j1_{coordinate}"));
        g.label(j2[j], format!("{name}_j2_{coordinate}"));
    }
    // The root's segment is fixed in the ground.
    let position = vec3::add(g, pending, done);
    let origin = s.field3(g, model, |k| Field::Origin(index, k), contact.origin);
    let rel = vec3::sub(g, position, origin);
    let f1 = vec3::dot(g, x_axis, rel);
    let f2 = vec3::dot(g, y_axis, rel);
    let conv1 = vec3::dot(g, x_axis, accel);
    let conv2 = vec3::dot(g, y_axis, accel);
    let profile = s.expression(model, Field::Profile(index), &contact.profile);
    let placeholder = format!("__cam_{}", contact.name);
    let [f3, slope, curvature] = value_and_derivatives(g, profile, &placeholder, f1, &s.params);
    let h = g.sub(f2, f3);
    let jacobian: Vec<Id> = j1
        .iter()
        .zip(&j2)
        .map(|(&j1, &j2)| {
            let s = g.mul(slope, j1);
            g.sub(j2, s)
        })
        .collect();
    let j1_qd = dot_list(g, &j1, qd);
    let bias = {
        let t1 = g.mul(slope, conv1);
        let sq = g.powi(j1_qd, 2);
        let t2 = g.mul(curvature, sq);
        let b = g.sub(conv2, t1);
        g.sub(b, t2)
    };
    let name = &contact.name;
    g.label(f1, format!("{name}_x"));
    g.label(f2, format!("{name}_y"));
    g.label(slope, format!("{name}_slope"));
    g.label(curvature, format!("{name}_curvature"));
    g.label(j1_qd, format!("{name}_x_rate"));
    vec3::label(g, position, &format!("{name}_pos"));
    vec3::label(g, accel, &format!("{name}_convective"));
    g.label(conv1, format!("{name}_conv1"));
    g.label(conv2, format!("{name}_conv2"));
    ContactTerms {
        position,
        f1,
        f2,
        j1,
        j2,
        conv1,
        conv2,
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::parse_expression;

    fn coefficients(source: &str) -> Option<Vec<f64>> {
        polynomial(&parse_expression(source, "x").expect("parses"))
    }

    #[test]
    fn polynomials_are_recognised_and_other_profiles_are_not() {
        assert_eq!(
            coefficients("-0.595*x + 0.5*x*x + 0.5*x.powi(3)"),
            Some(vec![0.0, -0.595, 0.5, 0.5])
        );
        assert_eq!(
            coefficients("(1.0 - x).powi(2) / 4.0"),
            Some(vec![0.25, -0.5, 0.25])
        );
        assert_eq!(coefficients("2.0"), Some(vec![2.0]));
        for other in [
            "x.sin()",
            "1.0 / x",
            "x.powi(-1)",
            "x.powf(2.0)",
            "x.powi(40)",
        ] {
            assert_eq!(coefficients(other), None, "{other}");
        }
    }

    #[test]
    fn horner_form_gives_the_profile_and_its_derivatives() {
        let s = parse_expression("0.3 - 0.595*x + 0.5*x*x + 0.5*x.powi(3)", "x").expect("parses");
        let mut g = Graph::new();
        let x = g.var("x");
        let [f, d1, d2] = value_and_derivatives(&mut g, &s, "__p", x, &[]);
        // Fewer operations than the power-by-power form: 3 multiplications and 3 additions
        // for the value.
        assert_eq!(g.op_count(&[f]).total(), 6);
        for v in [-1.7, -0.2, 0.0, 0.9, 2.5] {
            let values = g.eval(&[f, d1, d2], &[v]);
            let exact = [
                0.3 - 0.595 * v + 0.5 * v * v + 0.5 * v.powi(3),
                -0.595 + v + 1.5 * v * v,
                1.0 + 3.0 * v,
            ];
            for (a, b) in values.iter().zip(exact) {
                // Horner and the power form differ by a few roundings of O(10) values.
                assert!(
                    (a - b).abs() <= 1e-14 * (1.0 + b.abs()),
                    "x = {v}: {a} vs {b}"
                );
            }
        }
    }
}
