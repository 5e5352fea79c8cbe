//! Contact parameters: the point of a profile that a roller or a flat face touches.
//!
//! A knife edge on an explicit profile y = f(x) has its contact point in closed form (the
//! edge itself, eq. 1). A roller touches the profile at the point nearest its centre, a flat
//! face at the profile's extreme point along the face's normal: the profile's parameter s of
//! that point is the root of a residual ψ(s) = 0 at which ψ'(s) < 0 (the minimum of an
//! objective: the squared distance to the centre, or minus the extent along the normal).
//! Generated code and the build's interpreter find it with [`solve`] on the residual the
//! code generator derived symbolically; the contact equations then use the envelope theorem
//! (docs/method.md §9), so no derivative of s is ever needed.

use crate::kinds::{FollowerKind, Outline};

/// Newton iterations from one start before it counts as failed.
pub const MAX_ITERATIONS: usize = 40;

/// Samples of the range a scan compares when Newton needs a new start.
pub const SCAN_SAMPLES: usize = 96;

/// Newton stops when a step is at most this fraction of the range: the error left after
/// that step is of the order of its square (about 1e-18 of the range), below rounding.
pub const STEP_TOLERANCE: f64 = 1e-9;

/// Newton's steps are limited to this fraction of the range, so that a start far from the
/// root does not jump across the profile.
pub const MAX_STEP_FRACTION: f64 = 0.125;

/// The root of `residual` (which returns ψ(s) and ψ'(s)) with ψ' < 0, by Newton's method
/// from `guess`; when that fails (a non-finite value, ψ' ≥ 0 at the root, no convergence)
/// or `guess` is not finite, from the best of [`SCAN_SAMPLES`] points of `range` by
/// `objective`. NaN when both fail: the caller's constraint is then not finite and the
/// simulation stops with the time and state.
pub fn solve(
    guess: f64,
    range: (f64, f64),
    residual: impl Fn(f64) -> [f64; 2],
    objective: impl Fn(f64) -> f64,
) -> f64 {
    let length = (range.1 - range.0).abs().max(f64::MIN_POSITIVE);
    if guess.is_finite() {
        if let Some(s) = newton(guess, length, &residual) {
            return s;
        }
    }
    let start = scan(range, &objective);
    newton(start, length, &residual).unwrap_or(f64::NAN)
}

/// `slot` when it holds a finite value (a contact parameter solved at a nearby state),
/// otherwise `cold()`: generated code starts Newton from the last solution it kept.
#[inline]
pub fn warm_or(slot: f64, cold: impl FnOnce() -> f64) -> f64 {
    if slot.is_finite() { slot } else { cold() }
}

/// How the follower point of a cam designed from a motion law moves in the design frame
/// (`camchain_model::design`): what [`pitch_parameter`] inverts. The follower point is a
/// knife's edge or a roller's centre; the design frame is the cam frame at cam angle 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Pitch {
    /// Along the design frame's y axis on the line x = `offset` (m), above the cam's axis.
    Translating {
        /// The guide's offset from the cam's centre (m).
        offset: f64,
    },
    /// On the circle of radius `arm` (m) about `pivot` (design frame, m); `swing` (±1) is
    /// the sense in which the arm is turned from the pivot's line towards the cam's centre.
    Oscillating {
        /// The arm's pivot (m).
        pivot: [f64; 2],
        /// From the pivot to the follower point (m).
        arm: f64,
        /// +1 when the arm lies counterclockwise of the line from the pivot to the cam's
        /// centre, −1 clockwise.
        swing: f64,
    },
}

/// The parameter u of a designed cam's profile (and pitch curve) whose pitch point is the
/// follower point (x, y) of the cam frame, wrapped into `range`: Newton's cold start for a
/// designed cam, in place of a scan of the profile.
///
/// The design turns the follower's point P (design frame) into the cam frame by R(u), so
/// that the polar angle of (x, y) is u plus that of P. P itself is where the follower's path
/// (a guide's line, an arm's circle) is at the distance |(x, y)| from the cam's centre, since
/// a rotation keeps distances. Exact (to rounding) wherever the follower point is on the
/// pitch curve, as it is in contact; a start near the root elsewhere (a follower in
/// flight, a design whose dimensions a run-time parameter changed). NaN where the path
/// never comes to that distance: [`solve`] then scans.
pub fn pitch_parameter(x: f64, y: f64, pitch: Pitch, range: (f64, f64)) -> f64 {
    let r2 = x * x + y * y;
    let design = match pitch {
        Pitch::Translating { offset } => [offset, (r2 - offset * offset).sqrt()],
        Pitch::Oscillating { pivot, arm, swing } => {
            let d = pivot[0].hypot(pivot[1]);
            // The angle α between the arm and the inward line −A/d: |A + a u|² = r².
            let cos = (d * d + arm * arm - r2) / (2.0 * d * arm);
            let sin = swing.signum() * (1.0 - cos * cos).sqrt();
            let inward = [-pivot[0] / d, -pivot[1] / d];
            [
                pivot[0] + arm * (cos * inward[0] - sin * inward[1]),
                pivot[1] + arm * (sin * inward[0] + cos * inward[1]),
            ]
        }
    };
    let u = y.atan2(x) - design[1].atan2(design[0]);
    let length = range.1 - range.0;
    if length > 0.0 && length.is_finite() {
        range.0 + (u - range.0).rem_euclid(length)
    } else {
        u
    }
}

/// Newton's method with steps limited to [`MAX_STEP_FRACTION`] of `length`.
fn newton(mut s: f64, length: f64, residual: &impl Fn(f64) -> [f64; 2]) -> Option<f64> {
    let max_step = MAX_STEP_FRACTION * length;
    for _ in 0..MAX_ITERATIONS {
        let [value, slope] = residual(s);
        let step = value / slope;
        if !step.is_finite() {
            return None;
        }
        s -= step.clamp(-max_step, max_step);
        if step.abs() <= STEP_TOLERANCE * length {
            // The last step was taken at a point where ψ' had this sign; a root with
            // ψ' > 0 is the wrong extremum (the farthest point, the other side of the cam).
            return (slope < 0.0).then_some(s);
        }
    }
    None
}

/// The sample of `range` with the smallest finite objective (its first point if none is).
fn scan(range: (f64, f64), objective: &impl Fn(f64) -> f64) -> f64 {
    let (a, b) = range;
    let mut best = (f64::INFINITY, a);
    for k in 0..SCAN_SAMPLES {
        let s = a + (b - a) * (k as f64 + 0.5) / SCAN_SAMPLES as f64;
        let value = objective(s);
        if value < best.0 {
            best = (value, s);
        }
    }
    best.1
}

/// The follower as the profile must admit it (for [`followable`]): its kind, whose outline
/// decides the rule, and the radius of a circular outline.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shape {
    /// The follower's kind.
    pub kind: FollowerKind,
    /// The radius (m) of an [`Outline::Circle`] (a roller's); ignored for other outlines.
    pub radius: f64,
}

/// Where a problem [`followable`] finds is reported in the model file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Place {
    /// The roller's radius.
    Radius,
    /// The follower (a flat face on a profile it cannot rest on).
    Follower,
    /// The profile's expression.
    Profile,
}

/// One sample of a profile: its variable, its polar radius (NaN for the other forms) and
/// its curvature, positive where it is hollow seen from the follower (1/m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProfileSample {
    /// The profile's variable (x, θ or s).
    pub at: f64,
    /// r(θ) of a polar profile, NaN otherwise.
    pub radius: f64,
    /// The curvature (1/m).
    pub curvature: f64,
}

/// Samples of a profile's range where the build and the generated checks look for hollows.
pub const PROFILE_CHECK_SAMPLES: usize = 4096;

/// Below this curvature (1/m) a profile counts as straight for a flat face (a radius of
/// curvature beyond 1e6 m).
pub const FLAT_CURVATURE: f64 = 1e-6;

/// The follower `shape` can follow a profile whose samples are `samples` (`variable` names
/// the profile's variable in messages): a polar radius that stays positive, a finite
/// curvature, a roller smaller than every hollow (else it undercuts), a flat face only on a
/// strictly convex profile. The build checks the model file with it; generated code repeats
/// it when a radius or a profile depends on run-time parameters. The error says where to
/// report it and what is wrong, with the place on the profile and the numbers.
pub fn followable(
    contact: &str,
    variable: &str,
    shape: Shape,
    samples: &[ProfileSample],
) -> Result<(), (Place, String)> {
    followable_unnamed(variable, shape, samples)
        .map_err(|(place, message)| (place, format!("contact `{contact}`: {message}")))
}

/// [`followable`] without the contact's name in the message.
fn followable_unnamed(
    variable: &str,
    shape: Shape,
    samples: &[ProfileSample],
) -> Result<(), (Place, String)> {
    if let Some(bad) = samples.iter().find(|s| s.radius <= 0.0) {
        return Err((
            Place::Profile,
            format!(
                "the polar radius must be positive over the cam, but r({variable} = {:.6}) = \
                 {:e} m",
                bad.at, bad.radius
            ),
        ));
    }
    if let Some(bad) = samples.iter().find(|s| !s.curvature.is_finite()) {
        return Err((
            Place::Profile,
            format!(
                "the profile has no finite curvature at {variable} = {:.6} (a corner or a point \
                 where it stops): a follower cannot ride over it",
                bad.at
            ),
        ));
    }
    // The most hollow place of the profile (largest curvature towards the follower).
    let Some(hollow) = samples
        .iter()
        .copied()
        .max_by(|a, b| a.curvature.total_cmp(&b.curvature))
    else {
        return Ok(());
    };
    let radius_of_curvature = 1.0 / hollow.curvature;
    let (radius, label) = (shape.radius, shape.kind.label());
    match shape.kind.outline() {
        Outline::Circle if hollow.curvature > 0.0 && radius >= radius_of_curvature => Err((
            Place::Radius,
            format!(
                "the {label} (radius {radius} m) is larger than the profile's hollow at \
                 {variable} = {:.6}, whose radius of curvature is {radius_of_curvature:.6e} m: \
                 the {label} cannot reach the bottom of it (undercutting); use a {label} smaller \
                 than {radius_of_curvature:.6e} m or a flatter profile",
                hollow.at
            ),
        )),
        // The face rests on one point only where the profile is strictly convex: a straight
        // stretch would carry it along a whole segment.
        Outline::Line if hollow.curvature > -FLAT_CURVATURE => Err((
            Place::Follower,
            format!(
                "a {label} needs a strictly convex profile, but at {variable} = {:.6} the \
                 profile is {} (curvature {:.6e} 1/m): the face would bridge it",
                hollow.at,
                if hollow.curvature > 0.0 {
                    "hollow"
                } else {
                    "straight"
                },
                hollow.curvature
            ),
        )),
        Outline::Point | Outline::Circle | Outline::Line => Ok(()),
    }
}

/// A groove's centre line (samples `samples`, its polar radius and curvature, positive where
/// it is hollow seen from the roller) holds a roller whose flanks lie `half_width` from it
/// (the roller's radius, plus half the groove's backlash; `label` names that width in
/// messages): the line is defined everywhere, a polar line keeps the inner flank off the
/// cam's axis (r > w), and it bends less sharply than the half width on either side,
/// |κ| w < 1 (else the roller undercuts the inner flank where the line is convex, the
/// outer one where it is hollow). The build checks a face cam's groove with it; generated
/// code repeats it when the groove or the roller depends on run-time parameters.
pub fn groove_fits(
    contact: &str,
    (label, half_width): (&str, f64),
    samples: &[ProfileSample],
) -> Result<(), (Place, String)> {
    for sample in samples {
        if !(sample.curvature.is_finite() && (sample.radius.is_finite() || sample.radius.is_nan()))
        {
            return Err((
                Place::Profile,
                format!(
                    "the groove's centre line is not defined at θ = {:.4} rad (its radius or \
                     curvature is not a finite number)",
                    sample.at
                ),
            ));
        }
        if sample.radius <= half_width {
            return Err((
                Place::Profile,
                format!(
                    "the groove's inner flank reaches the cam's axis: its centre line's radius \
                     is {:.6} m at θ = {:.4} rad, not more than the {label} {half_width} m",
                    sample.radius, sample.at,
                ),
            ));
        }
        if sample.curvature.abs() * half_width >= 1.0 {
            let (flank, shape) = if sample.curvature < 0.0 {
                ("inner", "convex")
            } else {
                ("outer", "hollow")
            };
            return Err((
                Place::Radius,
                format!(
                    "contact `{contact}`: the {label} ({half_width} m) undercuts the groove's \
                     {flank} flank: at θ = {:.4} rad the centre line is {shape} with a radius of \
                     curvature of {:.6} m, smaller than that",
                    sample.at,
                    1.0 / sample.curvature.abs(),
                ),
            ));
        }
    }
    Ok(())
}

/// Angles of a turn at which a barrel's developed groove is checked.
pub const BARREL_CHECK_SAMPLES: usize = 3600;

/// A barrel cam's groove holds a roller whose flanks lie `half_width` from the pitch curve
/// (the roller's radius, plus half the backlash; `label` names it): the pitch curve developed
/// at the pitch radius R, (Rθ, g(θ)), bends with the radius (R² + g′²)^{3/2}/(R |g″|), which
/// must exceed the half width on both sides. `samples` hold the developed curve's curvature
/// R g″/(R² + g′²)^{3/2} at angles θ (the lower flank is undercut where it is negative, the
/// upper one where it is positive); a curvature that is not a number is not checked (the
/// build refuses such a groove where it evaluates it). The build checks a barrel's groove
/// given as an expression with it; generated code repeats it when the groove or the roller
/// depends on run-time parameters.
pub fn developed_groove_fits(
    contact: &str,
    (label, half_width): (&str, f64),
    samples: &[ProfileSample],
) -> Result<(), (Place, String)> {
    if half_width <= 0.0 {
        return Ok(());
    }
    match samples
        .iter()
        .find(|s| s.curvature.abs() * half_width >= 1.0)
    {
        Some(s) => {
            let flank = if s.curvature < 0.0 { "lower" } else { "upper" };
            Err((
                Place::Radius,
                format!(
                    "contact `{contact}`: the {label} ({half_width} m) undercuts the groove's \
                     {flank} flank: at θ = {:.3}° the groove's pitch curve, developed at the \
                     pitch radius, bends with a radius of {:.6} m, smaller than that",
                    s.at.to_degrees(),
                    1.0 / s.curvature.abs()
                ),
            ))
        }
        None => Ok(()),
    }
}

/// A barrel's groove lies on its cylinder of length `length` (from the cam frame's origin
/// along its axis): its flanks, `half_width` below and above the pitch surface, stay within
/// [0, length] at the angles θ of `heights` (θ, g(θ)), up to rounding (1e-12 of the length).
/// The build checks it with the file's values; generated code repeats it when a run-time
/// parameter moves the groove or changes the roller.
pub fn groove_on_cylinder(
    length: f64,
    half_width: f64,
    heights: &[(f64, f64)],
) -> Result<(), String> {
    let (mut lowest, mut highest) = ((0.0, f64::INFINITY), (0.0, f64::NEG_INFINITY));
    for &(theta, z) in heights {
        if z - half_width < lowest.1 {
            lowest = (theta, z - half_width);
        }
        if z + half_width > highest.1 {
            highest = (theta, z + half_width);
        }
    }
    // A flank exactly at an end is on the cylinder: rounding of a few ulps is let pass.
    let slack = 1e-12 * length;
    let beyond = if highest.1 > length + slack {
        Some(("upper", highest, "its length"))
    } else if lowest.1 < -slack {
        Some(("lower", lowest, "its start (z = 0)"))
    } else {
        None
    };
    match beyond {
        None => Ok(()),
        Some((side, (theta, value), edge)) => Err(format!(
            "the groove leaves the cylinder: its {side} flank reaches z = {value:.6} m at θ = \
             {:.3}°, beyond {edge}; the cylinder is {length} m long (lengthen it, or move the \
             groove with `base`)",
            theta.to_degrees()
        )),
    }
}

/// [`developed_groove_fits`] and, for a cylinder of `length` (located at `length_at`),
/// [`groove_on_cylinder`] at [`BARREL_CHECK_SAMPLES`] angles of a turn, `at` giving the pitch
/// height g(θ) and the developed curvature there; the first located by `places`.
pub fn developed_groove_fits_located(
    places: [crate::parameters::Location; 3],
    contact: &str,
    (label, half_width): (&str, f64),
    length: Option<(f64, crate::parameters::Location)>,
    at: impl Fn(f64) -> [f64; 2],
) -> Result<(), crate::ParameterError> {
    let samples: Vec<ProfileSample> = (0..BARREL_CHECK_SAMPLES)
        .map(|k| {
            let theta = std::f64::consts::TAU * k as f64 / BARREL_CHECK_SAMPLES as f64;
            let [height, curvature] = at(theta);
            ProfileSample {
                at: theta,
                radius: height,
                curvature,
            }
        })
        .collect();
    developed_groove_fits(contact, (label, half_width), &samples)
        .map_err(|e| located(places, e))?;
    let Some((length, length_at)) = length else {
        return Ok(());
    };
    let heights: Vec<(f64, f64)> = samples.iter().map(|s| (s.at, s.radius)).collect();
    groove_on_cylinder(length, half_width, &heights)
        .map_err(|message| located([length_at; 3], (Place::Profile, message)))
}

/// `samples` + 1 points of `range` evaluated by `at` (the polar radius and the curvature
/// there).
fn samples_of(range: (f64, f64), at: impl Fn(f64) -> [f64; 2]) -> Vec<ProfileSample> {
    (0..=PROFILE_CHECK_SAMPLES)
        .map(|k| {
            let s = range.0 + (range.1 - range.0) * k as f64 / PROFILE_CHECK_SAMPLES as f64;
            let [radius, curvature] = at(s);
            ProfileSample {
                at: s,
                radius,
                curvature,
            }
        })
        .collect()
}

/// A problem found at `place`, located by `places` ([`Place::Radius`], [`Place::Follower`],
/// [`Place::Profile`] in that order).
fn located(
    places: [crate::parameters::Location; 3],
    (place, message): (Place, String),
) -> crate::ParameterError {
    let at = match place {
        Place::Radius => places[0],
        Place::Follower => places[1],
        Place::Profile => places[2],
    };
    crate::ParameterError {
        file: at.file.to_string(),
        line: at.line,
        column: at.column,
        field: at.field.to_string(),
        message,
    }
}

/// [`followable`] on [`PROFILE_CHECK_SAMPLES`] + 1 points of `range` evaluated by `at` (the
/// polar radius and the curvature there), located by `places` ([`Place::Radius`],
/// [`Place::Follower`], [`Place::Profile`] in that order): what generated `check` functions
/// call.
pub fn followable_located(
    places: [crate::parameters::Location; 3],
    contact: &str,
    variable: &str,
    shape: Shape,
    range: (f64, f64),
    at: impl Fn(f64) -> [f64; 2],
) -> Result<(), crate::ParameterError> {
    followable(contact, variable, shape, &samples_of(range, at)).map_err(|e| located(places, e))
}

/// [`groove_fits`] on the samples of [`followable_located`], for a groove whose flanks lie
/// `half_width` (the roller's radius plus half the backlash) from its centre line.
pub fn groove_fits_located(
    places: [crate::parameters::Location; 3],
    contact: &str,
    (label, half_width): (&str, f64),
    range: (f64, f64),
    at: impl Fn(f64) -> [f64; 2],
) -> Result<(), crate::ParameterError> {
    groove_fits(contact, (label, half_width), &samples_of(range, at))
        .map_err(|e| located(places, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The nearest point of the unit circle (x, y) = (cos s, sin s) to p: ψ = c'·(p − c),
    /// objective |p − c|².
    fn nearest_on_circle(p: [f64; 2], guess: f64) -> f64 {
        solve(
            guess,
            (0.0, std::f64::consts::TAU),
            |s| {
                let (sn, cs) = s.sin_cos();
                let d = [p[0] - cs, p[1] - sn];
                let value = -sn * d[0] + cs * d[1];
                // ψ' = c''·d − |c'|² with c'' = −c.
                [value, -cs * d[0] - sn * d[1] - 1.0]
            },
            |s| {
                let (sn, cs) = s.sin_cos();
                (p[0] - cs).powi(2) + (p[1] - sn).powi(2)
            },
        )
    }

    #[test]
    fn finds_the_nearest_point_from_a_near_guess_or_by_scanning() {
        let p = [2.0 * 0.3f64.cos(), 2.0 * 0.3f64.sin()];
        // The nearest point of the circle to p is along p: s = 0.3 exactly.
        for guess in [0.25, 0.3, 0.9, f64::NAN] {
            let s = nearest_on_circle(p, guess);
            assert!((s - 0.3).abs() < 1e-15, "guess {guess}: {s}");
        }
    }

    #[test]
    fn a_guess_at_the_farthest_point_falls_back_to_the_scan() {
        // From the antipode, Newton converges to the maximum of the distance (ψ' > 0):
        // refused, and the scan finds the minimum.
        let p = [2.0, 0.0];
        let s = nearest_on_circle(p, std::f64::consts::PI);
        assert!(
            s.rem_euclid(std::f64::consts::TAU)
                .min(std::f64::consts::TAU - s.rem_euclid(std::f64::consts::TAU))
                < 1e-15,
            "{s}"
        );
    }

    #[test]
    fn no_root_gives_nan() {
        let s = solve(0.0, (0.0, 1.0), |s| [1.0 + s * s, 2.0 * s], |s| s);
        assert!(s.is_nan());
    }

    #[test]
    fn warm_start_prefers_a_finite_slot() {
        assert_eq!(warm_or(0.5, || 1.0), 0.5);
        assert_eq!(warm_or(f64::NAN, || 1.0), 1.0);
    }
}
