//! Face cams (`face:`): a groove cut in the cam plane, its centre line r = g(θ) given as an
//! expression of `theta` or designed from the follower's motion law exactly as a disc cam
//! (`law:`), each misuse located at its field (docs/model-format.md, "Face cams").

use super::designs::{Traced, law_profile};
use super::parameters::expression;
use super::{Checked, Context, Follower, Locator, Profile};
use crate::design::CamDesign;
use crate::model::{Contact, Field};
use crate::samples::profile_samples;
use crate::schema::raw;
use camchain_runtime::kinds::FollowerKind;

/// Samples of the turn at which the groove's flanks are checked.
const GROOVE_SAMPLES: usize = 3600;

/// The profile of a face cam (contact `i` named `name`, path `path`) followed by
/// `follower`, with its design when the groove is designed from a law.
pub(super) fn face_profile(
    cx: &Context,
    path: &str,
    face: &raw::Face,
    (i, name): (usize, &str),
    follower: &Follower,
) -> Checked<(Profile, Option<CamDesign>)> {
    let field = format!("{path}.face");
    in_a_groove(cx, path, follower, "a face cam's groove")?;
    let (centre, design) = match (&face.groove, &face.law) {
        (Some(source), None) => {
            let at = format!("{field}.groove");
            let r = expression(cx, &at, source, &["theta"], Field::Profile(i))?;
            let centre = Profile::Polar {
                source: source.clone(),
                r,
            };
            (centre, None)
        }
        (None, Some(law)) => {
            let at = format!("{field}.law");
            let (centre, design) =
                law_profile(cx, (path, &at), law, (i, name), follower, Traced::Pitch)?;
            (centre, Some(design))
        }
        (Some(_), Some(_)) => {
            return Err(cx.at.error(
                &format!("{field}.law"),
                "give the groove's centre line either as `groove: \"g(theta)\"` or as a `law`, \
                 not both",
            ));
        }
        (None, None) => {
            return Err(cx.at.error(
                &field,
                "a face cam needs its groove: `groove: \"g(theta)\"` (the centre line r = \
                 g(θ)) or `law: (base_radius: …, motion: …, segments: […])` (designed from \
                 the follower's motion, as a disc cam)",
            ));
        }
    };
    Ok((
        Profile::Face {
            centre: Box::new(centre),
        },
        design,
    ))
}

/// A groove's backlash (`face: (…, backlash: b)` or `barrel: (…, backlash: b)`, m): finite
/// and not negative; 0 when not given and for every other cam.
pub(super) fn backlash(cx: &Context, path: &str, c: &raw::Contact) -> Checked<f64> {
    let (field, value) = match (&c.face, &c.barrel) {
        (Some(face), _) => ("face", face.backlash),
        (None, Some(barrel)) => ("barrel", barrel.backlash),
        (None, None) => return Ok(0.0),
    };
    match value {
        Some(b) if !(b.is_finite() && b >= 0.0) => Err(cx.at.error(
            &format!("{path}.{field}.backlash"),
            format!(
                "the backlash is how much wider than the roller the groove is: a length of 0 m \
                 or more, got {b}"
            ),
        )),
        Some(b) => Ok(b),
        None => Ok(0.0),
    }
}

/// Only a roller (its centre the marker) or a knife edge runs in a groove (`groove` names
/// it in the message); a flat or curved face is refused at the follower.
pub(super) fn in_a_groove(
    cx: &Context,
    path: &str,
    follower: &Follower,
    groove: &str,
) -> Checked<()> {
    match follower.kind() {
        FollowerKind::Knife | FollowerKind::Roller => Ok(()),
        FollowerKind::Flat | FollowerKind::Mushroom => Err(cx.at.error(
            &format!("{path}.follower"),
            format!(
                "a {} cannot run in {groove}: give a roller (`follower: Roller(radius: …)`, its \
                 centre the marker) or a knife edge",
                follower.kind().label()
            ),
        )),
    }
}

/// A groove holds a roller of radius ρ on both flanks only where its centre line bends
/// less sharply than the roller: |κ| ρ < 1 at every one of 3600 points of the turn (the
/// inner flank, the centre line moved towards the cam's axis by ρ, is undercut where the
/// line is convex with a radius below ρ; the outer one where it is hollow). A polar centre
/// line also keeps its inner flank off the axis (r > ρ) and closes on itself.
pub(super) fn groove_fits(at: &Locator, path: &str, contact: &Contact) -> Checked<()> {
    let Profile::Face { centre } = &contact.profile else {
        return Ok(());
    };
    let field = match contact.design {
        Some(_) => format!("{path}.face.law"),
        None => format!("{path}.face.groove"),
    };
    // The flanks lie the roller's radius plus half the backlash from the centre line.
    let rho = contact.follower.radius().copied().unwrap_or(0.0) + 0.5 * contact.backlash;
    let label = match contact.backlash > 0.0 {
        true => "groove's half-width (the roller's radius and half the backlash)",
        false => contact.follower.kind().label(),
    };
    let range = contact.range.unwrap_or((0.0, std::f64::consts::TAU));
    let samples = profile_samples(centre, range, GROOVE_SAMPLES);
    if let Profile::Polar { r, .. } = centre.as_ref() {
        super::fields::closes(at, &field, r)?;
    }
    for sample in &samples {
        if !(sample.curvature.is_finite() && (sample.radius.is_finite() || sample.radius.is_nan()))
        {
            return Err(at.error(
                &field,
                format!(
                    "the groove's centre line is not defined at θ = {:.4} rad (its radius or \
                     curvature is not a finite number)",
                    sample.at
                ),
            ));
        }
        if sample.radius <= rho {
            return Err(at.error(
                &field,
                format!(
                    "the groove's inner flank reaches the cam's axis: its centre line's radius \
                     is {:.6} m at θ = {:.4} rad, not more than the {label} {rho} m",
                    sample.radius, sample.at,
                ),
            ));
        }
        if sample.curvature.abs() * rho >= 1.0 {
            let (flank, shape) = if sample.curvature < 0.0 {
                ("inner", "convex")
            } else {
                ("outer", "hollow")
            };
            return Err(at.error(
                &format!("{path}.follower.radius"),
                format!(
                    "contact `{}`: the {label} ({rho} m) undercuts the groove's {flank} flank: \
                     at θ = {:.4} rad the centre line is {shape} with a radius of curvature of \
                     {:.6} m, smaller than that",
                    contact.name,
                    sample.at,
                    1.0 / sample.curvature.abs(),
                ),
            ));
        }
    }
    Ok(())
}
