//! A roller of radius ρ, or a knife edge (ρ = 0), on any profile: the follower point P stays
//! at the distance ρ from the profile, on its follower side (a roller's centre on the offset,
//! or pitch, curve). The contact parameter s* is the profile point nearest P, the root of
//! ψ(s) = c′(s)·(P − c(s)) with ψ′ < 0, found by Newton's method in the generated code
//! ([`Implicit`]). With n, t the profile's unit normal and tangent at s* and κ its
//! curvature (docs/method.md §9.2):
//!
//! ```text
//! D = n·(P − c(s*)),   h = D − ρ
//! J = n·∂P/∂q                             (the envelope theorem: ∂h/∂s* = 0)
//! c = n·P̈° − κ (t·Ṗ)² / (1 − κ D)
//! ```
//!
//! (κ D < 1 wherever the roller does not undercut the profile.)

use super::curve::{
    self, dot2, follower_side, labelled_frame, perp, solved_point, sub2, trial_point,
};
use super::relative::Relative;
use super::{ContactTerms, Formulas};
use crate::expr::{Graph, Guess, Implicit};
use crate::kinematics::{Symbols, vec3};
use crate::model::{Field, Model, Profile};

/// The terms of contact `index`: a roller of radius `radius`, or a knife edge (`None`).
pub fn nearest(
    g: &mut Graph,
    model: &Model,
    s: &Symbols,
    index: usize,
    rel: Relative,
    radius: Option<f64>,
) -> ContactTerms {
    let contact = &model.contacts[index];
    let name = &contact.name;
    let side = follower_side(&contact.profile);
    // ψ(u; p) on placeholders, then the solution.
    let (u, [px, py], at_u) = trial_point(g, model, s, index, name, ["px", "py"]);
    let d = sub2(g, [px, py], at_u.point);
    g.label(d[0], "offset_x");
    g.label(d[1], "offset_y");
    let residual = dot2(g, at_u.d1, d);
    let derivative = {
        let bend = dot2(g, at_u.d2, d);
        let speed2 = dot2(g, at_u.d1, at_u.d1);
        g.sub(bend, speed2)
    };
    let objective = dot2(g, d, d);
    let guess = match contact.profile {
        Profile::Explicit { .. } | Profile::Surface { .. } => Guess::Input(0),
        Profile::Barrel { .. } => Guess::Angle { x: 0, y: 1 },
        Profile::Revolution { .. } => Guess::Scan,
        Profile::Polar { .. } => Guess::Angle { x: 0, y: 1 },
        Profile::Parametric { .. } => Guess::Scan,
    };
    let what = match radius {
        Some(_) => format!(
            "the profile point nearest the {}'s centre",
            contact.follower.kind().label()
        ),
        None => "the profile point under the knife edge".to_string(),
    };
    let solution = g.implicit(
        &format!("{name}_parameter"),
        Implicit {
            description: format!("contact {name}: {what}"),
            unknown: u,
            placeholders: vec![px, py],
            input_names: vec!["x", "y"],
            inputs: rel.xy.to_vec(),
            residual,
            derivative,
            objective,
            guess,
            range: contact.range.unwrap_or((0.0, std::f64::consts::TAU)),
        },
    );
    let (at, offset) = solved_point(g, model, s, index, name, (solution, rel.xy));
    let f = labelled_frame(g, &at, side, name);
    let distance = dot2(g, f.normal, offset);
    g.label(distance, format!("{name}_distance"));
    let rho = match radius {
        Some(r) => s.field(g, model, Field::Radius(index), r),
        None => g.zero(),
    };
    let h = g.sub(distance, rho);
    let jacobian = rel
        .columns
        .iter()
        .map(|&column| dot2(g, f.normal, column))
        .collect();
    let along = dot2(g, f.tangent, rel.velocity);
    g.label(along, format!("{name}_along"));
    let bias = {
        let normal_part = dot2(g, f.normal, rel.convective);
        let one = g.one();
        let kd = g.mul(f.curvature, distance);
        let lever = g.sub(one, kd);
        let sq = g.powi(along, 2);
        let k_sq = g.mul(f.curvature, sq);
        let turn = g.div(k_sq, lever);
        g.sub(normal_part, turn)
    };
    g.label(f.curvature, format!("{name}_kappa"));
    // The follower's material at the contact point moves relative to the cam at
    // Ṗ + ω_r rot90(c − P).
    let to_contact = sub2(g, at.point, rel.xy);
    let swing = perp(g, to_contact);
    let material = curve::add_scaled(g, rel.velocity, rel.spin, swing);
    let sliding = dot2(g, f.tangent, material);
    let position = rel.to_ground(g, at.point);
    let normal = rel.vector_to_ground(g, f.normal);
    vec3::label(g, position, &format!("{name}_contact"));
    ContactTerms {
        h,
        jacobian,
        bias,
        position,
        cam_point: at.point,
        cam_height: None,
        normal,
        force_scale: g.one(),
        parameter: solution,
        curvature: f.curvature,
        sliding,
        relative: rel,
        formulas: if radius.is_some() {
            Formulas {
                kind: format!(
                    "a {} on the profile's nearest point",
                    contact.follower.kind().label()
                ),
                h: "h = D − ρ, eq. (C7)",
                jacobian: "J = n·∂P/∂q, eq. (C8)",
                bias: "eq. (C9)",
            }
        } else {
            Formulas {
                kind: "a knife edge on the profile's nearest point".to_string(),
                h: "h = D, eq. (C7) with ρ = 0",
                jacobian: "J = n·∂P/∂q, eq. (C8)",
                bias: "eq. (C9)",
            }
        },
    }
}
