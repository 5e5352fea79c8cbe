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
use camchain_runtime::contact::{PROFILE_CHECK_SAMPLES, Place, groove_fits as groove_fits_checked};
use camchain_runtime::kinds::FollowerKind;

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
/// less sharply than its half-width w (ρ, plus half the backlash): |κ| w < 1 at every one of
/// 4097 points of the turn (the inner flank, the centre line moved towards the cam's axis by
/// w, is undercut where the line is convex with a radius below w; the outer one where it is
/// hollow). A polar centre line also keeps its inner flank off the axis (r > w) and closes on
/// itself. The check is the runtime's (`camchain_runtime::contact::groove_fits`), which
/// generated code repeats when the groove or the roller depends on run-time parameters.
pub(super) fn groove_fits(at: &Locator, path: &str, contact: &Contact) -> Checked<()> {
    let Profile::Face { centre } = &contact.profile else {
        return Ok(());
    };
    let field = match contact.design {
        Some(_) => format!("{path}.face.law"),
        None => format!("{path}.face.groove"),
    };
    let range = contact.range.unwrap_or((0.0, std::f64::consts::TAU));
    if let Profile::Polar { r, .. } = centre.as_ref() {
        super::fields::closes(at, &field, r)?;
    }
    let samples = profile_samples(centre, range, PROFILE_CHECK_SAMPLES);
    groove_fits_checked(
        &contact.name,
        (contact.groove_label(), contact.groove_half_width()),
        &samples,
    )
    .map_err(|(place, message)| match place {
        Place::Radius => at.error(&format!("{path}.follower.radius"), message),
        Place::Follower | Place::Profile => at.error(&field, message),
    })
}
