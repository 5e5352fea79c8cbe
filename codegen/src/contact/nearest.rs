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
//!
//! In a face cam's groove ([`Rim::Groove`]) the profile is the groove's centre line and the
//! roller's centre stays on it: h = D, with J and c as above; the roller touches the inner
//! flank c(s*) − ρ n, whose curvature is κ/(1 + κρ) (docs/method.md §13.7).

use super::circle;
use super::curve::{
    self, dot2, follower_side, labelled_frame, perp, solved_point, sub2, trial_point,
};
use super::relative::Relative;
use super::{ContactTerms, Formulas};
use crate::design::{CamDesign, Motion};
use crate::expr::{Graph, Guess, Implicit};
use crate::kinematics::{Symbols, vec3};
use crate::model::{Field, Model, Profile};
use camchain_runtime::contact::Pitch;
use camchain_runtime::kinds::Outline;

/// What follows the profile.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Rim {
    /// A knife edge: the follower point on the profile.
    Knife,
    /// A roller (or a curved face) of this radius, its centre the radius off the profile.
    Roller(f64),
    /// A roller of this radius (0 for a knife edge) in a face cam's groove, its centre on
    /// the groove's centre line (the profile).
    Groove(f64),
}

/// How a design's follower point moves, for Newton's cold start: a knife's edge or a
/// roller's centre on a disc or face cam guided along a line (the profile's parameter is the
/// design's u = −σθ, `camchain_model::design::profile_expressions`); `None` for a flat face
/// or a barrel, and for now for an oscillating follower: away from contact (the reference
/// tests' states) its start can lie on the far side of the range's ends from the nearest
/// point, and Newton then ends 2π from the reference's parameter (polynomial_rocker).
fn pitch_of(design: &CamDesign) -> Option<Pitch> {
    match (design.senses.shape.outline(), &design.geometry.motion) {
        (Outline::Point | Outline::Circle, Motion::Translating { offset }) => {
            Some(Pitch::Translating { offset: *offset })
        }
        (Outline::Line, _) | (_, Motion::Axial { .. } | Motion::Oscillating { .. }) => None,
    }
}

/// The terms of contact `index` followed as `rim` says.
pub fn nearest(
    g: &mut Graph,
    model: &Model,
    s: &Symbols,
    index: usize,
    rel: Relative,
    rim: Rim,
) -> ContactTerms {
    let radius = match rim {
        Rim::Roller(r) => Some(r),
        Rim::Knife | Rim::Groove(_) => None,
    };
    if let (Rim::Knife | Rim::Roller(_), Some(circle)) = (rim, circle::circular(model, index)) {
        return circle::on_circle(g, model, s, index, rel, radius, circle);
    }
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
    let guess = match contact.profile.curve() {
        Profile::Explicit { .. } | Profile::Surface { .. } => Guess::Input(0),
        Profile::Barrel { .. } => Guess::Angle { x: 0, y: 1 },
        // A ball on a surface of revolution, in its meridian half-plane (r, Z): from Z.
        Profile::Revolution { .. } => Guess::Input(1),
        Profile::Polar { .. } => Guess::Angle { x: 0, y: 1 },
        // A cam designed from a law: its pitch curve inverted at the follower point (exact
        // in contact); any other parametric curve: a scan of its range.
        Profile::Parametric { .. } | Profile::Face { .. } => contact
            .design
            .as_ref()
            .and_then(pitch_of)
            .map_or(Guess::Scan, Guess::Pitch),
    };
    let what = match rim {
        Rim::Roller(_) => format!(
            "the profile point nearest the {}'s centre",
            contact.follower.kind().label()
        ),
        Rim::Knife => "the profile point under the knife edge".to_string(),
        Rim::Groove(_) => format!(
            "the groove's centre-line point nearest the {}'s centre",
            contact.follower.kind().label()
        ),
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
    let rho = match rim {
        Rim::Roller(r) => s.field(g, model, Field::Radius(index), r),
        Rim::Knife | Rim::Groove(_) => g.zero(),
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
    // Where the follower touches: the profile point, or in a groove the inner flank ρ in
    // from the centre line, curved by κ/(1 + κρ).
    let (touched, curvature) = match rim {
        Rim::Knife | Rim::Roller(_) => (at.point, f.curvature),
        Rim::Groove(r) => {
            let rho = s.field(g, model, Field::Radius(index), r);
            let inward = f.normal.map(|n| g.mul(rho, n));
            let flank = sub2(g, at.point, inward);
            let one = g.one();
            let k_rho = g.mul(f.curvature, rho);
            let stretch = g.add(one, k_rho);
            let k = g.div(f.curvature, stretch);
            g.label(k, format!("{name}_flank_kappa"));
            (flank, k)
        }
    };
    // The follower's material at the contact point moves relative to the cam at
    // Ṗ + ω_r rot90(c − P).
    let to_contact = sub2(g, touched, rel.xy);
    let swing = perp(g, to_contact);
    let material = curve::add_scaled(g, rel.velocity, rel.spin, swing);
    let sliding = dot2(g, f.tangent, material);
    let position = rel.to_ground(g, touched);
    let normal = rel.vector_to_ground(g, f.normal);
    vec3::label(g, position, &format!("{name}_contact"));
    ContactTerms {
        h,
        jacobian,
        bias,
        position,
        cam_point: touched,
        cam_height: None,
        normal,
        force_scale: g.one(),
        parameter: solution,
        curvature,
        sliding,
        relative: rel,
        radial: None,
        formulas: if let Rim::Groove(_) = rim {
            Formulas {
                kind: format!(
                    "a {} in a face cam's groove, its centre on the centre line",
                    contact.follower.kind().label()
                ),
                h: "h = D, eq. (C7) on the centre line",
                jacobian: "J = n·∂P/∂q, eq. (C8)",
                bias: "eq. (C9)",
            }
        } else if radius.is_some() {
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
