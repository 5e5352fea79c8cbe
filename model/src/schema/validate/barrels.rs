//! Barrel cams (`barrel:`): the pitch surface z = f(θ) on a cylinder about the cam's axis,
//! given as an expression of `theta` or designed from the follower's motion law along the
//! axis, each misuse located at its field (docs/model-format.md, "Barrel cams").

use super::designs::{can_be_made, nominal_speed, pressure_limit, program, sense};
use super::faces::in_a_groove;
use super::fields::positive;
use super::parameters::expression;
use super::{Checked, Context, Follower, Profile};
use crate::design::{CamDesign, Geometry, Motion, Senses};
use crate::jet::{Jet2, eval_on, own_tables};
use crate::model::Field;
use crate::profile::{Scalar, Tabulated};
use crate::schema::raw;
use camchain_runtime::contact::{
    BARREL_CHECK_SAMPLES, ProfileSample, developed_groove_fits, groove_on_cylinder,
};
use camchain_runtime::kinds::FollowerKind;
use std::f64::consts::TAU;

/// The profile of a barrel cam (contact `i`, path `path`) followed by `follower`, with its
/// design when the groove is designed from a law (what `camchain cam` reports: the groove
/// developed at its pitch radius).
pub(super) fn barrel_profile(
    cx: &Context,
    path: &str,
    barrel: &raw::Barrel,
    i: usize,
    name: &str,
    follower: &Follower,
) -> Checked<(Profile, Option<CamDesign>)> {
    let field = format!("{path}.barrel");
    in_a_groove(cx, path, follower, "a barrel cam's groove")?;
    // The radius places the drawings and the designer's outputs; the constraint reads the
    // follower point's own distance from the axis, so it may be a run-time parameter.
    let at = format!("{field}.radius");
    let (_, radius) = cx.dimension(&at, &barrel.radius)?;
    let radius = positive(cx.at, &at, "the barrel's pitch radius", radius)?;
    let (source, f, design) = match (&barrel.groove, &barrel.law) {
        (Some(source), None) => {
            let at = format!("{field}.groove");
            let f = expression(cx, &at, source, &["theta"], Field::Profile(i))?;
            closes(cx, &at, &f)?;
            // The flanks lie the roller's radius and half the backlash from the pitch curve.
            let backlash = barrel.backlash.unwrap_or(0.0);
            let half_width = follower.radius().copied().unwrap_or(0.0) + 0.5 * backlash;
            let label = crate::model::groove_label(follower.kind(), backlash);
            groove_fits(cx, path, (name, &f), radius, (label, half_width))?;
            (source.clone(), f, None)
        }
        (None, Some(law)) => {
            let at = format!("{field}.law");
            let program = program(cx, &at, &law.segments)?;
            let (folded_base, base) = cx.dimension(&format!("{at}.base"), &law.base)?;
            let tabulated = Tabulated::law(format!("{name}_law"), program.clone());
            // The follower sits at the cam frame's angle θ = −σφ when the cam has turned by
            // φ (σ = +1 counterclockwise), so the law is read at φ = −σθ.
            let theta = if sense(law.turning) < 0.0 {
                Scalar::Var(0)
            } else {
                -Scalar::Var(0)
            };
            let s = theta.tabulated(&tabulated, 0);
            cx.table.record(Field::Profile(i), folded_base + s.clone());
            let speed = nominal_speed(cx, &at, law.speed.as_ref())?;
            let design = CamDesign {
                program,
                law: tabulated,
                geometry: Geometry {
                    base_radius: base,
                    roller: follower.radius().copied().unwrap_or(0.0),
                    motion: Motion::Axial { radius },
                },
                senses: Senses {
                    turning: sense(law.turning),
                    swing: 1.0,
                    shape: follower.kind(),
                },
                // A translating follower's usual limit (Norton, ch. 7), as for disc cams.
                max_pressure_angle: pressure_limit(cx, &at, law.max_pressure_angle, 30.0)?,
                speed: speed.as_ref().map(|s| s.0),
                speed_expression: speed.map(|s| s.1),
                groove: true,
            };
            can_be_made(cx, (path, &at), name, &design)?;
            (
                format!("{base} + s(θ), the law"),
                Scalar::Const(base) + s,
                Some(design),
            )
        }
        (Some(_), Some(_)) => {
            return Err(cx.at.error(
                &format!("{field}.law"),
                "give the groove's pitch surface either as `groove: \"f(theta)\"` or as a \
                 `law`, not both",
            ));
        }
        (None, None) => {
            return Err(cx.at.error(
                &field,
                "a barrel cam needs its groove: `groove: \"f(theta)\"` (the pitch surface z = \
                 f(θ)) or `law: (base: z0, segments: […])` (designed from the follower's \
                 motion along the axis)",
            ));
        }
    };
    let length = match &barrel.length {
        Some(length) => {
            // A number the generated check reads as it is: it may not depend on run-time
            // parameters (the groove and the roller may, and are checked against it again).
            let at = format!("{field}.length");
            let length = cx.number(&at, length, None)?;
            let length = positive(cx.at, &at, "the barrel's length", length)?;
            // The flanks lie the roller's radius and half the backlash from the pitch surface.
            let half_width =
                follower.radius().copied().unwrap_or(0.0) + 0.5 * barrel.backlash.unwrap_or(0.0);
            on_the_cylinder(cx, &at, &f, half_width, length)?;
            Some(length)
        }
        None => None,
    };
    Ok((
        Profile::Barrel {
            source,
            f,
            radius,
            length,
        },
        design,
    ))
}

/// A barrel's `tapered: true`: the half-angle atan(ρ/R) of a roller whose apex lies on the
/// cam's axis, fixed when the file is read (ρ and R must not be read at run time); 0 for a
/// straight roller and every other cam.
pub(super) fn taper(
    cx: &Context,
    path: &str,
    c: &raw::Contact,
    i: usize,
    follower: &Follower,
) -> Checked<f64> {
    let Some(barrel) = c.barrel.as_ref().filter(|b| b.tapered) else {
        return Ok(0.0);
    };
    let field = format!("{path}.barrel.tapered");
    let Some(&rho) = follower
        .radius()
        .filter(|_| follower.kind() == FollowerKind::Roller)
    else {
        return Err(cx.at.error(
            &field,
            "a tapered groove takes a roller (`follower: Roller(radius: …)`): its apex on the \
             cam's axis, its radius ρ at the pitch radius",
        ));
    };
    if cx.table.is_runtime(Field::Radius(i)) {
        return Err(cx.at.error(
            &format!("{path}.follower.radius"),
            "a tapered roller's half-angle atan(ρ/R) is fixed when the file is read: mark the \
             parameters of its radius `constant: true`",
        ));
    }
    let radius = cx.constant(&format!("{path}.barrel.radius"), &barrel.radius)?;
    Ok((rho / radius).atan())
}

/// The groove's flanks, its half-width w (the roller's radius and half the backlash) below
/// and above its pitch surface, lie on the cylinder: 0 ≤ g(θ) − w and g(θ) + w ≤ length at
/// 3600 angles of a turn (a law's extremes lie on its segments' joints, which are multiples
/// of 0.1° in practice), by the runtime's check (`contact::groove_on_cylinder`), which
/// generated code repeats when a run-time parameter moves the groove or changes the roller.
fn on_the_cylinder(
    cx: &Context,
    at: &str,
    f: &Scalar,
    half_width: f64,
    length: f64,
) -> Checked<()> {
    let heights: Vec<(f64, f64)> = (0..BARREL_CHECK_SAMPLES)
        .map(|k| {
            let theta = TAU * k as f64 / BARREL_CHECK_SAMPLES as f64;
            (theta, f.eval(theta))
        })
        .collect();
    groove_on_cylinder(length, half_width, &heights).map_err(|message| cx.at.error(at, message))
}

/// A roller fits a groove given as an expression: the pitch curve developed at the pitch
/// radius R, (Rθ, g(θ)), bends with the radius (R² + g′²)^{3/2}/(R |g″|), which must exceed
/// the groove's half-width (the roller's radius and half the backlash) on both sides: the
/// runtime's check (`camchain_runtime::contact::developed_groove_fits`, which generated code
/// repeats when a run-time parameter changes the groove or the roller) at its 3600 angles (a
/// law's design is checked by `designs::can_be_made` the same way).
fn groove_fits(
    cx: &Context,
    path: &str,
    (name, f): (&str, &Scalar),
    radius: f64,
    (label, half_width): (&str, f64),
) -> Checked<()> {
    let samples: Vec<ProfileSample> = (0..BARREL_CHECK_SAMPLES)
        .map(|k| {
            let theta = TAU * k as f64 / BARREL_CHECK_SAMPLES as f64;
            let g = eval_on(f, Jet2::variable(theta), &own_tables);
            ProfileSample {
                at: theta,
                radius: f64::NAN,
                curvature: radius * g.d2 / (radius * radius + g.d1 * g.d1).powf(1.5),
            }
        })
        .collect();
    developed_groove_fits(name, (label, half_width), &samples)
        .map_err(|(_, message)| cx.at.error(&format!("{path}.follower.radius"), message))
}

/// A barrel's pitch surface closes on itself round the cylinder: f(θ + 2π) = f(θ), checked
/// at 16 angles to 1e-9 of its height (or of 1 mm).
fn closes(cx: &Context, field: &str, f: &Scalar) -> Checked<()> {
    for k in 0..16 {
        let theta = TAU * k as f64 / 16.0;
        let (a, b) = (f.eval(theta), f.eval(theta + TAU));
        if !(a.is_finite() && b.is_finite())
            || (a - b).abs() > 1e-9 * a.abs().max(b.abs()).max(1e-3)
        {
            return Err(cx.at.error(
                field,
                format!(
                    "a barrel cam's groove must close round the cylinder, f(theta + 2π) = \
                     f(theta), but f({theta:.6}) = {a:e} m and f({:.6}) = {b:e} m",
                    theta + TAU
                ),
            ));
        }
    }
    Ok(())
}
