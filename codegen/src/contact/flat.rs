//! A flat face on any convex profile: the face, a line of the follower through its marker F
//! with unit normal m pointing from the cam into the follower, rests on the profile's extreme
//! point along −m… that is the point c(s*) of largest m·c: the root of ψ(s) = m·c′(s) with
//! ψ′ = m·c″ < 0, found by Newton's method in the generated code. The follower turns
//! relative to the cam only about the cam's axis, at the rate ω_r, so ṁ = ω_r m⊥
//! (m⊥ = m turned a quarter turn). With everything in the cam frame (docs/method.md §9.3):
//!
//! ```text
//! h = m·(F − c(s*))
//! J_k = m·∂F/∂q_k + ∂ω_r/∂q̇_k · m⊥·(F − c(s*))
//! c = m·F̈° + 2 ω_r m⊥·Ḟ − ω_r² m·(F − c) + ω_r² (m⊥·c′)² / (m·c″)
//! ```
//!
//! the last term from the support point's motion ṡ = −ω_r (m⊥·c′)/(m·c″).

use super::curve::{
    add_scaled, dot2, follower_side, labelled_frame, perp, solved_point, sub2, trial_point,
};
use super::relative::Relative;
use super::{ContactTerms, Formulas};
use crate::expr::{Graph, Guess, Implicit};
use crate::kinematics::{BodyKinematics, Symbols, vec3};
use crate::model::{Model, Profile};

/// The terms of contact `index`, a flat face whose unit normal `face` (follower body frame)
/// points from the face towards the cam.
pub fn flat(
    g: &mut Graph,
    model: &Model,
    kin: &[BodyKinematics],
    s: &Symbols,
    index: usize,
    rel: Relative,
    face: [f64; 3],
) -> ContactTerms {
    let contact = &model.contacts[index];
    let name = &contact.name;
    let into_follower = vec3::constant(g, face.map(|c| -c));
    let m_ground = rel.follower_vector(g, kin, into_follower);
    let m = rel.in_cam_frame(g, m_ground);
    g.label(m[0], format!("{name}_face_x"));
    g.label(m[1], format!("{name}_face_y"));
    // ψ(u; m) = m·c′(u) on placeholders, then the support point.
    let (u, [mx, my], at_u) = trial_point(g, model, s, index, name, ["mx", "my"]);
    let residual = dot2(g, [mx, my], at_u.d1);
    let derivative = dot2(g, [mx, my], at_u.d2);
    let extent = dot2(g, [mx, my], at_u.point);
    let objective = g.neg(extent);
    let guess = match contact.profile {
        Profile::Polar { .. } => Guess::Angle { x: 0, y: 1 },
        Profile::Explicit { .. }
        | Profile::Parametric { .. }
        | Profile::Surface { .. }
        | Profile::Barrel { .. }
        | Profile::Revolution { .. }
        | Profile::Face { .. } => Guess::Scan,
    };
    let solution = g.implicit(
        &format!("{name}_parameter"),
        Implicit {
            description: format!("contact {name}: the profile point the flat face rests on"),
            unknown: u,
            placeholders: vec![mx, my],
            input_names: vec!["mx", "my"],
            inputs: m.to_vec(),
            residual,
            derivative,
            objective,
            guess,
            range: contact.range.unwrap_or((0.0, std::f64::consts::TAU)),
        },
    );
    let (at, offset) = solved_point(g, model, s, index, name, (solution, rel.xy));
    let h = dot2(g, m, offset);
    let m_perp = perp(g, m);
    let lever = dot2(g, m_perp, offset);
    g.label(lever, format!("{name}_lever"));
    let jacobian = rel
        .columns
        .iter()
        .zip(&rel.spin_columns)
        .map(|(&column, &spin)| {
            let slide = dot2(g, m, column);
            let turn = g.mul(spin, lever);
            g.add(slide, turn)
        })
        .collect();
    let w = rel.spin;
    let bias = {
        let normal_part = dot2(g, m, rel.convective);
        let across = dot2(g, m_perp, rel.velocity);
        let two_w = g.scale(2.0, w);
        let coriolis = g.mul(two_w, across);
        let w2 = g.powi(w, 2);
        let gap = g.mul(w2, h);
        let tilt = dot2(g, m_perp, at.d1);
        let tilt2 = g.powi(tilt, 2);
        let bend = dot2(g, m, at.d2);
        let roll = g.div(tilt2, bend);
        let support = g.mul(w2, roll);
        let a = g.add(normal_part, coriolis);
        let b = g.sub(a, gap);
        g.add(b, support)
    };
    let side = follower_side(&contact.profile);
    let f = labelled_frame(g, &at, side, name);
    g.label(f.curvature, format!("{name}_kappa"));
    let to_contact = sub2(g, at.point, rel.xy);
    let swing = perp(g, to_contact);
    let material = add_scaled(g, rel.velocity, w, swing);
    // Along the profile's tangent (increasing s), as for the other kinds.
    let sliding = dot2(g, f.tangent, material);
    let position = rel.to_ground(g, at.point);
    vec3::label(g, position, &format!("{name}_contact"));
    ContactTerms {
        h,
        jacobian,
        bias,
        position,
        cam_point: at.point,
        cam_height: None,
        normal: m_ground,
        force_scale: g.one(),
        parameter: solution,
        curvature: f.curvature,
        sliding,
        relative: rel,
        radial: None,
        formulas: Formulas {
            kind: "a flat face on the profile's support point".to_string(),
            h: "h = m·(F − c(s*)), eq. (C11)",
            jacobian: "J = m·∂F/∂q + (∂ω_r/∂q̇) m⊥·(F − c(s*)), eq. (C12)",
            bias: "eq. (C13)",
        },
    }
}
