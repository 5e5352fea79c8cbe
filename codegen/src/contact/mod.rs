//! Contacts as a family of constraints: a follower on one body touching a cam profile on
//! another (or on the ground), each kind supplying its constraint h, its Jacobian J, the
//! convective term c of J q̈ + c = 0, and what the outputs report ([`ContactTerms`]).
//!
//! - [`relative`]: the follower's point seen from the cam, whatever body carries it;
//! - [`curve`]: the profile as a curve c(s) (explicit, polar, parametric);
//! - the kinds: [`knife`] (a knife edge on y = f(x), the paper's eqs. 1–8, in closed form),
//!   [`nearest`] (a roller, or a knife edge, on any profile: the profile point nearest the
//!   follower point, found by Newton; on a circular profile in closed form: [`circle`]), [`flat`] (a flat face: the profile's extreme point
//!   along the face's normal), [`surface`] (a point on a cam surface z = f(x, y), or in a
//!   barrel cam's groove) and [`revolution`] (a point outside a surface of revolution).
//!
//! A new kind is one more module here returning [`ContactTerms`] (with the [`Formulas`] the
//! generated docs quote), and one more arm in [`contact_terms`]; the emitter, the runtime and
//! the outputs take it from there.

pub mod ball;
pub mod circle;
pub mod curve;
pub mod flat;
pub mod knife;
pub mod nearest;
pub mod relative;
pub mod revolution;
pub mod surface;

use crate::expr::{Graph, Id};
use crate::kinematics::{BodyKinematics, Symbols, V3};
use crate::model::{Follower, Model, Profile};
use nearest::Rim;
use relative::Relative;

/// Symbolic terms of one contact: what every kind supplies.
#[derive(Debug, Clone)]
pub struct ContactTerms {
    /// h(q): positive when the follower is clear of the cam (eq. 3 for a knife edge on
    /// y = f(x)).
    pub h: Id,
    /// J = ∂h/∂q (5b).
    pub jacobian: Vec<Id>,
    /// c of J q̈ + c = 0 (7, 8).
    pub bias: Id,
    /// The contact point on the profile, ground coordinates.
    pub position: V3,
    /// The contact point in the cam frame.
    pub cam_point: [Id; 2],
    /// Its height along the cam's axis on a cam surface (`None` for a plane profile).
    pub cam_height: Option<Id>,
    /// Unit normal, ground coordinates, from the cam into the follower.
    pub normal: V3,
    /// |∂h/∂(displacement along the normal)|: N = −λ · force_scale.
    pub force_scale: Id,
    /// The profile's parameter at the contact point.
    pub parameter: Id,
    /// The profile's curvature there, positive where it is hollow seen from the follower.
    pub curvature: Id,
    /// The sliding speed: the tangential velocity of the follower body's material at the
    /// contact point relative to the cam.
    pub sliding: Id,
    /// The follower seen from the cam (its point's cam-frame kinematics, the cam frame).
    pub relative: Relative,
    /// For a tapered roller in a barrel's groove, the unit vector from the cam's axis to the
    /// follower point, ground coordinates (`ContactGeometry::radial`); `None` otherwise.
    pub radial: Option<V3>,
    /// How this kind writes h, J and c: what the generated functions' docs say.
    pub formulas: Formulas,
}

/// A contact kind's h, J and c in the notation of `docs/method.md`, with their equation
/// numbers (the paper's, or that document's `C` equations): the docs of the generated
/// `constraint`, `constraint_jacobian` and `constraint_bias` describe the model's own kinds.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Formulas {
    /// The kind, e.g. "a knife edge on y = f(x)".
    pub kind: String,
    /// h, e.g. "h = f2 − f3(f1), eq. (3)".
    pub h: &'static str,
    /// J, e.g. "J = J2 − f3′ J1, eq. (5b)".
    pub jacobian: &'static str,
    /// c of J q̈ + c = 0, e.g. "eqs. (7, 8)".
    pub bias: &'static str,
}

/// Derives the terms of every contact of `model`.
pub fn contact_terms(
    g: &mut Graph,
    model: &Model,
    kin: &[BodyKinematics],
    s: &Symbols,
) -> Vec<ContactTerms> {
    (0..model.contacts.len())
        .map(|index| {
            let contact = &model.contacts[index];
            g.set_section(format!(
                "contact {}: the follower seen from the cam, h, J, c",
                contact.name
            ));
            let rel = relative::relative(g, model, kin, s, index);
            match (&contact.follower, &contact.profile) {
                (Follower::Knife, Profile::Surface { .. } | Profile::Barrel { .. }) => {
                    surface::point(g, model, s, index, rel, None)
                }
                (Follower::Knife, Profile::Revolution { .. }) => {
                    revolution::point(g, model, s, index, rel)
                }
                (Follower::Roller { radius }, Profile::Surface { .. }) => {
                    ball::ball(g, model, s, index, rel, *radius)
                }
                (Follower::Roller { radius }, Profile::Revolution { .. }) => {
                    ball::on_revolution(g, model, s, index, rel, *radius)
                }
                (Follower::Roller { radius }, Profile::Barrel { .. }) => {
                    surface::point(g, model, s, index, rel, Some(*radius))
                }
                (Follower::Knife, Profile::Explicit { .. }) => {
                    knife::explicit(g, model, s, index, rel)
                }
                (Follower::Knife, Profile::Face { .. }) => {
                    nearest::nearest(g, model, s, index, rel, Rim::Groove(0.0))
                }
                (Follower::Roller { radius }, Profile::Face { .. }) => {
                    nearest::nearest(g, model, s, index, rel, Rim::Groove(*radius))
                }
                (Follower::Knife, _) => nearest::nearest(g, model, s, index, rel, Rim::Knife),
                (Follower::Roller { radius }, _) => {
                    nearest::nearest(g, model, s, index, rel, Rim::Roller(*radius))
                }
                (Follower::Flat { normal }, _) => flat::flat(g, model, kin, s, index, rel, *normal),
                (Follower::Mushroom { radius, .. }, _) => {
                    nearest::nearest(g, model, s, index, rel, Rim::Roller(*radius))
                }
            }
        })
        .collect()
}
