//! Cams designed from the follower's motion law (`law:`): the segments made into a motion
//! program, the follower's dimensions, and the checks that the designed cam can be made and
//! followed, each located at the field it concerns. The profile itself is synthesised by
//! [`crate::design`].

use super::fields::{finite, positive};
use super::{Checked, Context, Follower, Profile};
use crate::design::{self, CamDesign, DESIGN_SAMPLES, Geometry, Motion, Senses};
use crate::model::Field;
use crate::profile::{Scalar, Tabulated};
use crate::schema::raw::{self, LawName, LawSegment, Turning};
use camchain_runtime::kinds::Outline;
use camchain_runtime::motion_law::{Law, LawError, MotionProgram, Segment};

/// The default limit of the pressure angle: 30° for a translating follower, 35° for an
/// oscillating one (Norton, *Cam Design and Manufacturing Handbook*, ch. 7).
fn default_pressure_limit(motion: &raw::Motion) -> f64 {
    match motion {
        raw::Motion::Translating { .. } => 30.0,
        raw::Motion::Oscillating { .. } => 35.0,
    }
}

/// What a design's parametric curve is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Traced {
    /// The cam's profile (a disc cam's `law`): the pitch curve moved in by the roller.
    Profile,
    /// The pitch curve itself (a face cam's groove centre line, `face: (law: …)`).
    Pitch,
}

/// The profile of contact `index` (named `name`, path `path`) designed from `law` (at the
/// field `field`) for `follower`, and the design.
pub(super) fn law_profile(
    cx: &Context,
    (path, field): (&str, &str),
    law: &raw::Law,
    (index, name): (usize, &str),
    follower: &Follower,
    traced: Traced,
) -> Checked<(Profile, CamDesign)> {
    if follower.centre_direction().is_some() {
        // A design places the follower point (the marker) on its pitch curve: a circle
        // centred off the marker (a curved face's apex is the marker) has no such point.
        return Err(cx.at.error(
            &format!("{path}.follower"),
            format!(
                "a cam designed from a law needs a knife edge, a roller or a flat face: a {} \
                 is not designed for yet (give the profile instead)",
                follower.kind().label()
            ),
        ));
    }
    let program = program(cx, field, &law.segments)?;
    let senses = Senses {
        turning: sense(law.turning),
        swing: match &law.motion {
            raw::Motion::Oscillating { swing, .. } => sense(*swing),
            raw::Motion::Translating { .. } => 1.0,
        },
        shape: follower.kind(),
    };
    let (folded, resolved) = geometry(cx, field, law, index, follower)?;
    reachable(cx, field, &resolved, senses)?;
    let max_pressure_angle = pressure_limit(
        cx,
        field,
        law.max_pressure_angle,
        default_pressure_limit(&law.motion),
    )?;
    let speed = nominal_speed(cx, field, law.speed.as_ref())?;
    let tabulated = Tabulated::law(format!("{name}_law"), program.clone());
    let design = CamDesign {
        program,
        law: tabulated.clone(),
        geometry: resolved,
        senses,
        max_pressure_angle,
        speed: speed.as_ref().map(|s| s.0),
        speed_expression: speed.map(|s| s.1),
        groove: traced == Traced::Pitch,
    };
    can_be_made(cx, (path, field), name, &design)?;
    let [x, y] = match traced {
        Traced::Profile => design::profile_expressions(&folded, senses, &tabulated),
        Traced::Pitch => design::pitch_expressions(&folded, senses, &tabulated),
    };
    let values = &cx.table.values;
    let (x_resolved, y_resolved) = (x.resolve_all(values), y.resolve_all(values));
    cx.table.record(Field::Profile(index), x);
    cx.table.record(Field::ProfileY(index), y);
    let source = format!(
        "the {} designed for a {} {} follower from the motion law of `law`",
        match traced {
            Traced::Profile => "cam",
            Traced::Pitch => "groove's centre line",
        },
        match &law.motion {
            raw::Motion::Translating { .. } => "translating",
            raw::Motion::Oscillating { .. } => "oscillating",
        },
        follower.kind_name()
    );
    let profile = Profile::Parametric {
        x_source: source.clone(),
        y_source: source,
        x: x_resolved,
        y: y_resolved,
    };
    Ok((profile, design))
}

/// A design's `max_pressure_angle` (degrees in the file, `default` when absent), in rad.
pub(super) fn pressure_limit(
    cx: &Context,
    field: &str,
    given: Option<f64>,
    default: f64,
) -> Checked<f64> {
    match given {
        Some(limit) if limit > 0.0 && limit < 90.0 => Ok(limit.to_radians()),
        Some(limit) => Err(cx.at.error(
            &format!("{field}.max_pressure_angle"),
            format!("the pressure angle's limit is in degrees, between 0 and 90, not {limit}"),
        )),
        None => Ok(default.to_radians()),
    }
}

/// A design's nominal `speed` (rad/s): its value and its expression of the parameters.
pub(super) fn nominal_speed(
    cx: &Context,
    field: &str,
    given: Option<&raw::Number>,
) -> Checked<Option<(f64, Scalar)>> {
    let Some(n) = given else {
        return Ok(None);
    };
    let at = format!("{field}.speed");
    let (_, value) = cx.dimension(&at, n)?;
    positive(cx.at, &at, "the cam's nominal speed", value)?;
    let expression = match n {
        raw::Number::Value(v) => Scalar::Const(*v),
        raw::Number::Expr(source) => cx.table.parsed(&at, source)?,
    };
    Ok(Some((value, expression)))
}

/// +1 counterclockwise, −1 clockwise.
pub(super) fn sense(turning: Turning) -> f64 {
    match turning {
        Turning::Counterclockwise => 1.0,
        Turning::Clockwise => -1.0,
    }
}

/// The runtime's law of a file's name.
fn law_of(name: LawName) -> Law {
    match name {
        LawName::Cycloidal => Law::Cycloidal,
        LawName::SimpleHarmonic => Law::SimpleHarmonic,
        LawName::Polynomial345 => Law::Polynomial345,
        LawName::Polynomial4567 => Law::Polynomial4567,
        LawName::ModifiedTrapezoid => Law::ModifiedTrapezoid,
        LawName::ModifiedSine => Law::ModifiedSine,
    }
}

/// The segments as a motion program: angles in degrees (constant, positive), rises that go
/// up and returns that come down, a turn in all, back to the base circle, no jump of the
/// velocity where two segments join.
pub(super) fn program(
    cx: &Context,
    field: &str,
    segments: &[LawSegment],
) -> Checked<MotionProgram> {
    let mut out = Vec::with_capacity(segments.len());
    let mut before = 0.0;
    for (k, segment) in segments.iter().enumerate() {
        let at = format!("{field}.segments[{k}]");
        let (law, degrees, lift) = match segment {
            LawSegment::Dwell { degrees } => (Law::Dwell, degrees, None),
            LawSegment::Rise { law, lift, degrees } => (law_of(*law), degrees, Some((lift, 1.0))),
            LawSegment::Return { law, lift, degrees } => {
                (law_of(*law), degrees, Some((lift, -1.0)))
            }
        };
        let angle = cx.positive_constant(&format!("{at}.degrees"), degrees, "a segment's angle")?;
        let lift = match lift {
            None => before,
            Some((n, direction)) => {
                let lift = cx.constant(&format!("{at}.lift"), n)?;
                if (lift - before) * direction <= 0.0 {
                    let (what, way) = if direction > 0.0 {
                        ("a rise", "above")
                    } else {
                        ("a return", "below")
                    };
                    return Err(cx.at.error(
                        &format!("{at}.lift"),
                        format!(
                            "{what} ends {way} the lift it starts from ({before}), but this one \
                             ends at {lift}"
                        ),
                    ));
                }
                lift
            }
        };
        out.push(Segment {
            law,
            angle: angle.to_radians(),
            lift,
        });
        before = lift;
    }
    let program = MotionProgram::new(&out).map_err(|e| {
        let place = match &e {
            LawError::BadAngle { index, .. } => format!("{field}.segments[{index}].degrees"),
            LawError::BadLift { index, .. } | LawError::DwellMoves { index, .. } => {
                format!("{field}.segments[{index}]")
            }
            LawError::DoesNotReturn { .. } => {
                format!(
                    "{field}.segments[{}].lift",
                    segments.len().saturating_sub(1)
                )
            }
            LawError::Empty | LawError::NotATurn { .. } => format!("{field}.segments"),
        };
        cx.at.error(&place, e.to_string())
    })?;
    if let Some(jump) = program.jumps(1e-9).into_iter().find(|j| j.order == 1) {
        return Err(cx.at.error(
            &format!("{field}.segments[{}]", jump.segment),
            format!(
                "the follower's velocity jumps by {:e} per rad where this segment starts (cam \
                 angle {:.4}°): an infinite acceleration, the follower would be struck",
                jump.size,
                jump.angle.to_degrees()
            ),
        ));
    }
    Ok(program)
}

/// The design's dimensions: as expressions of the run-time parameters (for the profile's
/// expressions) and as numbers.
fn geometry(
    cx: &Context,
    field: &str,
    law: &raw::Law,
    index: usize,
    follower: &Follower,
) -> Checked<(Geometry<Scalar>, Geometry<f64>)> {
    let base = cx.dimension(&format!("{field}.base_radius"), &law.base_radius)?;
    if base.1 <= 0.0 {
        return Err(cx.at.error(
            &format!("{field}.base_radius"),
            format!("the base circle's radius must be positive, not {}", base.1),
        ));
    }
    let roller = match follower.radius() {
        Some(radius) => (
            cx.table
                .symbolic
                .borrow()
                .get(&Field::Radius(index))
                .cloned()
                .unwrap_or(Scalar::Const(*radius)),
            *radius,
        ),
        None => (Scalar::Const(0.0), 0.0),
    };
    let motion_field = format!("{field}.motion");
    let (folded, resolved) = match &law.motion {
        raw::Motion::Translating { offset } => {
            let e = cx.dimension(&format!("{motion_field}.offset"), offset)?;
            (
                Motion::Translating { offset: e.0 },
                Motion::Translating { offset: e.1 },
            )
        }
        raw::Motion::Oscillating {
            pivot,
            arm,
            face_offset,
            ..
        } => {
            let px = cx.dimension(&format!("{motion_field}.pivot[0]"), &pivot.0)?;
            let py = cx.dimension(&format!("{motion_field}.pivot[1]"), &pivot.1)?;
            let a = cx.dimension(&format!("{motion_field}.arm"), arm)?;
            let f = cx.dimension(&format!("{motion_field}.face_offset"), face_offset)?;
            if a.1 <= 0.0 && follower.kind().outline() != Outline::Line {
                return Err(cx.at.error(
                    &format!("{motion_field}.arm"),
                    format!("the arm's length must be positive, not {}", a.1),
                ));
            }
            (
                Motion::Oscillating {
                    pivot: [px.0, py.0],
                    arm: a.0,
                    face_offset: f.0,
                },
                Motion::Oscillating {
                    pivot: [px.1, py.1],
                    arm: a.1,
                    face_offset: f.1,
                },
            )
        }
    };
    Ok((
        Geometry {
            base_radius: base.0,
            roller: roller.0,
            motion: folded,
        },
        Geometry {
            base_radius: base.1,
            roller: roller.1,
            motion: resolved,
        },
    ))
}

/// The follower can sit on the base circle: a translating guide's offset within the prime
/// circle (base radius plus roller), an arm that reaches it from its pivot, a flat face's
/// line that touches the base circle.
fn reachable(cx: &Context, law: &str, g: &Geometry<f64>, senses: Senses) -> Checked<()> {
    let prime = g.base_radius + g.roller;
    let field = format!("{law}.motion");
    match (&g.motion, senses.shape.outline()) {
        (Motion::Translating { offset }, Outline::Point | Outline::Circle)
            if offset.abs() >= prime =>
        {
            Err(cx.at.error(
                &format!("{field}.offset"),
                format!(
                    "the follower's guide passes {} m from the cam's centre, outside the prime \
                     circle (base radius plus roller: {prime} m): it never meets the cam",
                    offset.abs()
                ),
            ))
        }
        (Motion::Oscillating { pivot, arm, .. }, Outline::Point | Outline::Circle) => {
            let d = pivot[0].hypot(pivot[1]);
            if prime <= (d - arm).abs() || prime >= d + arm {
                return Err(cx.at.error(
                    &format!("{field}.arm"),
                    format!(
                        "an arm of {arm} m pivoted {d} m from the cam's centre cannot reach the \
                         prime circle (base radius plus roller: {prime} m): it needs \
                         |{d} − arm| < {prime} < {d} + arm"
                    ),
                ));
            }
            Ok(())
        }
        (
            Motion::Oscillating {
                pivot, face_offset, ..
            },
            Outline::Line,
        ) => {
            let d = pivot[0].hypot(pivot[1]);
            if g.base_radius + face_offset >= d || g.base_radius + face_offset <= 0.0 {
                return Err(cx.at.error(
                    &format!("{field}.pivot"),
                    format!(
                        "the pivot is {d} m from the cam's centre: the face, {face_offset} m from \
                         the pivot's line, touches the base circle only if base radius plus \
                         face offset ({}) is between 0 and {d}",
                        g.base_radius + face_offset
                    ),
                ));
            }
            Ok(())
        }
        (Motion::Translating { .. }, Outline::Point | Outline::Circle | Outline::Line) => Ok(()),
        // A barrel's follower always meets its groove.
        (Motion::Axial { .. }, _) => Ok(()),
    }
}

/// The designed cam can be made and followed: a roller smaller than the pitch curve's
/// convex radii (no undercutting), a flat face on a profile without cusps, an oscillating
/// face that never turns with the cam.
pub(super) fn can_be_made(
    cx: &Context,
    (path, law): (&str, &str),
    name: &str,
    design: &CamDesign,
) -> Checked<()> {
    let g = &design.geometry;
    let mm = |x: f64| format!("{:.3} mm", x * 1e3);
    let label = design.senses.shape.label();
    if let Motion::Axial { .. } = g.motion {
        // A barrel's groove, developed at its pitch radius: the roller must bend less
        // sharply than the pitch curve on both sides (its crests for the lower flank, its
        // troughs for the upper one).
        let (theta, margin) = design.least(DESIGN_SAMPLES, |p| p.pitch_radius.abs() - g.roller);
        if margin <= 0.0 {
            let p = design.at(theta);
            let flank = if p.pitch_radius > 0.0 {
                "lower"
            } else {
                "upper"
            };
            return Err(cx.at.error(
                &format!("{path}.follower.radius"),
                format!(
                    "contact `{name}`: the {label} ({}) undercuts the groove's {flank} flank: at \
                     cam angle {:.3}° the groove's pitch curve, developed at its pitch radius, \
                     bends with a radius of {}, smaller than the {label}'s; take a larger pitch \
                     radius, a gentler law or a smaller {label}",
                    mm(g.roller),
                    theta.to_degrees(),
                    mm(p.pitch_radius.abs())
                ),
            ));
        }
        return Ok(());
    }
    match design.senses.shape.outline() {
        Outline::Circle if g.roller > 0.0 => {
            let (theta, radius) = design.least(DESIGN_SAMPLES, |p| {
                if p.pitch_radius > 0.0 {
                    p.radius_of_curvature
                } else {
                    f64::INFINITY
                }
            });
            if radius <= 0.0 {
                let pitch = design.at(theta).pitch_radius;
                return Err(cx.at.error(
                    &format!("{path}.follower.radius"),
                    format!(
                        "contact `{name}`: the {label} ({}) undercuts the cam designed for it: at \
                         cam angle {:.3}° the pitch curve's radius of curvature is {}, smaller \
                         than the {label}'s; take a larger base circle or a smaller {label}",
                        mm(g.roller),
                        theta.to_degrees(),
                        mm(pitch)
                    ),
                ));
            }
            Ok(())
        }
        Outline::Point | Outline::Circle => Ok(()),
        Outline::Line => {
            if let Motion::Oscillating { .. } = g.motion {
                let (theta, rate) = design.least(DESIGN_SAMPLES, |p| {
                    (design.senses.swing * p.lift[1] - design.senses.turning).abs()
                });
                if rate < 1e-9 {
                    return Err(cx.at.error(
                        law,
                        format!(
                            "contact `{name}`: at cam angle {:.3}° the flat face turns with the \
                             cam (the arm's rate equals the cam's): no profile touches it",
                            theta.to_degrees()
                        ),
                    ));
                }
            }
            let (theta, radius) = design.least(DESIGN_SAMPLES, |p| p.radius_of_curvature);
            if radius <= 0.0 {
                return Err(cx.at.error(
                    &format!("{law}.base_radius"),
                    format!(
                        "contact `{name}`: the flat face's cam would have a cusp: its radius of \
                         curvature reaches {} at cam angle {:.3}°; the base circle must be at \
                         least {} larger (base radius {} or more)",
                        mm(radius),
                        theta.to_degrees(),
                        mm(-radius),
                        mm(g.base_radius - radius)
                    ),
                ));
            }
            Ok(())
        }
    }
}

impl Context<'_> {
    /// A design dimension: (its expression of the run-time parameters, its value), finite.
    pub(super) fn dimension(&self, field: &str, n: &raw::Number) -> Checked<(Scalar, f64)> {
        let (folded, value) = match n {
            raw::Number::Value(v) => (Scalar::Const(*v), *v),
            raw::Number::Expr(source) => {
                let (folded, resolved) = self.table.expression(field, source, &[])?;
                (folded, resolved.eval(0.0))
            }
        };
        Ok((folded, finite(self.at, field, value)?))
    }

    /// A number that must not depend on run-time parameters.
    pub(super) fn constant(&self, field: &str, n: &raw::Number) -> Checked<f64> {
        self.number(field, n, None)
    }

    /// A positive number that must not depend on run-time parameters.
    pub(super) fn positive_constant(
        &self,
        field: &str,
        n: &raw::Number,
        what: &str,
    ) -> Checked<f64> {
        let value = self.constant(field, n)?;
        positive(self.at, field, what, value)
    }
}
