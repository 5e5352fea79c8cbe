//! A roller, a curved face or a knife edge on a circular profile (an eccentric disc given as
//! r(θ) about the cam's axis): the nearest point in closed form, so that the right-hand side
//! solves nothing for the contact.
//!
//! A polar profile whose points over a turn all lie on one circle (centre C, radius R: the
//! circle through three of the profile's own points, checked at [`CHECK_SAMPLES`] angles to
//! [`CIRCLE_TOLERANCE`] at build time) is touched where the line from C through the follower
//! point P meets it. With u = (P − C)/|P − C| (docs/method.md §9.2 at the constant curvature
//! −1/R):
//!
//! ```text
//! n = u,  t = J u,  D = |P − C| − R,  h = D − ρ
//! J = n·∂P/∂q,   c = n·P̈° + (t·Ṗ)² / |P − C|
//! ```
//!
//! which are the terms [`super::nearest`] derives at the Newton solution, to rounding. The
//! profile's parameter at the contact (an output of the contact geometry only, no term of h,
//! J or c reads it) stays the nearest-point root, now of the contact point C + R u itself,
//! started from that point's polar angle: exact, Newton's first step confirms it.

use super::curve::{dot2, perp, sub2, trial_point};
use super::relative::Relative;
use super::{ContactTerms, Formulas};
use crate::expr::{Graph, Guess, Implicit};
use crate::kinematics::{Symbols, vec3};
use crate::model::{Field, Model, Profile};
use std::f64::consts::TAU;

/// Angles of a turn at which a polar profile must lie on its circle.
pub const CHECK_SAMPLES: usize = 720;

/// How far a sample may be off the circle, relative to the circle's reach |C| + R: a few
/// hundred units of rounding of r(θ) (eccentric_roller's disc: 1.4e-17 m off at most over
/// 720 angles, 2.8e-16 of its reach), far below any profile that is not a circle
/// (r = R + 1e-12 cos 2θ is off by 2e-11 of it).
pub const CIRCLE_TOLERANCE: f64 = 1e-13;

/// A circle of the cam frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Circle {
    /// Its centre C (m).
    pub centre: [f64; 2],
    /// Its radius R (m).
    pub radius: f64,
}

/// The circle that contact `index`'s profile is, if it is one: a polar profile over the whole
/// turn (its range, (0, 2π) unless the file narrows it) that no run-time parameter changes,
/// every sample on the circle.
pub fn circular(model: &Model, index: usize) -> Option<Circle> {
    let contact = model.contacts.get(index)?;
    let Profile::Polar { r, .. } = &contact.profile else {
        return None;
    };
    let range = contact.range?;
    if range.1 - range.0 < TAU || Symbols::any_runtime(model, [Field::Profile(index)]) {
        return None;
    }
    let point = |theta: f64| {
        let radius = r.eval(theta);
        [radius * theta.cos(), radius * theta.sin()]
    };
    let circle = through([0.0, TAU / 3.0, 2.0 * TAU / 3.0].map(point))?;
    let reach = circle.centre[0].hypot(circle.centre[1]) + circle.radius;
    let on_circle = (0..CHECK_SAMPLES).all(|k| {
        let p = point(TAU * (k as f64 + 0.5) / CHECK_SAMPLES as f64);
        let off = (p[0] - circle.centre[0]).hypot(p[1] - circle.centre[1]) - circle.radius;
        off.abs() <= CIRCLE_TOLERANCE * reach
    });
    on_circle.then_some(circle)
}

/// The circle through three points (`None` when they are on a line or not finite).
fn through([a, b, c]: [[f64; 2]; 3]) -> Option<Circle> {
    // In a's frame: the centre u solves 2 u·b′ = |b′|², 2 u·c′ = |c′|².
    let (b, c) = ([b[0] - a[0], b[1] - a[1]], [c[0] - a[0], c[1] - a[1]]);
    let (bb, cc) = (b[0] * b[0] + b[1] * b[1], c[0] * c[0] + c[1] * c[1]);
    let det = 2.0 * (b[0] * c[1] - b[1] * c[0]);
    let u = [(c[1] * bb - b[1] * cc) / det, (b[0] * cc - c[0] * bb) / det];
    let radius = u[0].hypot(u[1]);
    let circle = Circle {
        centre: [a[0] + u[0], a[1] + u[1]],
        radius,
    };
    (det != 0.0 && circle.centre.iter().all(|v| v.is_finite()) && radius.is_finite())
        .then_some(circle)
}

/// The terms of contact `index` on its circular profile `circle`: a roller or curved face of
/// radius `radius`, or a knife edge (`None`).
pub fn on_circle(
    g: &mut Graph,
    model: &Model,
    s: &Symbols,
    index: usize,
    rel: Relative,
    radius: Option<f64>,
    circle: Circle,
) -> ContactTerms {
    let contact = &model.contacts[index];
    let name = &contact.name;
    let centre = circle.centre.map(|v| g.constant(v));
    let from_centre = sub2(g, rel.xy, centre);
    g.label(from_centre[0], format!("{name}_from_centre_x"));
    g.label(from_centre[1], format!("{name}_from_centre_y"));
    let reach = {
        let sq = dot2(g, from_centre, from_centre);
        g.sqrt(sq)
    };
    g.label(reach, format!("{name}_reach"));
    let normal = from_centre.map(|v| g.div(v, reach));
    let tangent = perp(g, normal);
    g.label(tangent[0], format!("{name}_tx"));
    g.label(tangent[1], format!("{name}_ty"));
    let big_r = g.constant(circle.radius);
    let distance = g.sub(reach, big_r);
    g.label(distance, format!("{name}_distance"));
    let rho = match radius {
        Some(r) => s.field(g, model, Field::Radius(index), r),
        None => g.zero(),
    };
    let h = g.sub(distance, rho);
    let jacobian = rel
        .columns
        .iter()
        .map(|&column| dot2(g, normal, column))
        .collect();
    let along = dot2(g, tangent, rel.velocity);
    g.label(along, format!("{name}_along"));
    // −κ (t·Ṗ)²/(1 − κ D) with κ = −1/R: (t·Ṗ)²/(R + D).
    let bias = {
        let normal_part = dot2(g, normal, rel.convective);
        let sq = g.powi(along, 2);
        let turn = g.div(sq, reach);
        g.add(normal_part, turn)
    };
    let curvature = g.constant(-1.0 / circle.radius);
    let touched = [0, 1].map(|k| {
        let t = g.mul(big_r, normal[k]);
        g.add(centre[k], t)
    });
    let range = contact.range.unwrap_or((0.0, TAU));
    let parameter = parameter_at(g, model, s, index, (touched, range));
    // The follower's material at the contact point moves relative to the cam at
    // Ṗ + ω_r rot90(c − P).
    let to_contact = sub2(g, touched, rel.xy);
    let swing = perp(g, to_contact);
    let material = super::curve::add_scaled(g, rel.velocity, rel.spin, swing);
    let sliding = dot2(g, tangent, material);
    let position = rel.to_ground(g, touched);
    let normal_ground = rel.vector_to_ground(g, normal);
    vec3::label(g, position, &format!("{name}_contact"));
    let label = contact.follower.kind().label();
    ContactTerms {
        h,
        jacobian,
        bias,
        position,
        cam_point: touched,
        cam_height: None,
        normal: normal_ground,
        force_scale: g.one(),
        parameter,
        curvature,
        sliding,
        relative: rel,
        radial: None,
        formulas: Formulas {
            kind: match radius {
                Some(_) => {
                    format!("a {label} on a circular profile, its nearest point in closed form")
                }
                None => "a knife edge on a circular profile, its nearest point in closed form"
                    .to_string(),
            },
            h: "h = |P − C| − R − ρ, eq. (C7) on a circle",
            jacobian: "J = n·∂P/∂q, eq. (C8)",
            bias: "eq. (C9) with κ = −1/R",
        },
    }
}

/// The profile's parameter at the point `touched` of the profile: the nearest-point root
/// there (the implicit variable of [`super::nearest`], its input the point itself), started
/// from the point's polar angle, which is the root.
fn parameter_at(
    g: &mut Graph,
    model: &Model,
    s: &Symbols,
    index: usize,
    (touched, range): ([crate::expr::Id; 2], (f64, f64)),
) -> crate::expr::Id {
    let contact = &model.contacts[index];
    let name = &contact.name;
    let (u, [px, py], at_u) = trial_point(g, model, s, index, name, ["px", "py"]);
    let d = sub2(g, [px, py], at_u.point);
    let residual = dot2(g, at_u.d1, d);
    let derivative = {
        let bend = dot2(g, at_u.d2, d);
        let speed2 = dot2(g, at_u.d1, at_u.d1);
        g.sub(bend, speed2)
    };
    let objective = dot2(g, d, d);
    g.implicit(
        &format!("{name}_parameter"),
        Implicit {
            description: format!("contact {name}: the profile's angle at the contact point"),
            unknown: u,
            placeholders: vec![px, py],
            input_names: vec!["x", "y"],
            inputs: touched.to_vec(),
            residual,
            derivative,
            objective,
            guess: Guess::Angle { x: 0, y: 1 },
            range,
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Model;
    use std::path::Path;

    fn model(name: &str) -> Model {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../models/{name}.ron"));
        let text = std::fs::read_to_string(&path).expect("the built-in model file exists");
        crate::schema::parse_model(&text, &path).expect("the built-in model is valid")
    }

    /// The eccentric discs are found to be their circles (R = 40 mm about (e, 0) = (10 mm,
    /// 0) of the cam frame); a polar profile that is not a circle, and the designed and
    /// explicit profiles, are not.
    #[test]
    fn an_eccentric_disc_is_found_to_be_its_circle() {
        for name in ["eccentric_roller", "eccentric_mushroom"] {
            let circle = circular(&model(name), 0).expect("a circle");
            let off = (circle.centre[0] - 0.01).hypot(circle.centre[1]);
            assert!(off < 1e-16, "{name}: centre {:?}", circle.centre);
            assert!(
                (circle.radius - 0.04).abs() < 1e-16,
                "{name}: {}",
                circle.radius
            );
        }
        for name in ["cycloidal_roller", "paper_concave", "rocker_roller"] {
            let m = model(name);
            assert_eq!(circular(&m, 0), None, "{name}");
        }
    }

    #[test]
    fn three_points_on_a_line_make_no_circle() {
        assert_eq!(through([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]), None);
        let c = through([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0]]).expect("the unit circle");
        assert!(c.centre[0].abs() < 1e-16 && c.centre[1].abs() < 1e-16);
        assert!((c.radius - 1.0).abs() < 1e-16);
    }
}
