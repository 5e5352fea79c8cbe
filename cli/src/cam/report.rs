//! What `camchain cam` prints, and its CSV: the design summary, the dynamics (the force over a
//! turn, the predicted jump speed, the one-sided run) and `design.csv`.

use super::analysis::{Analysis, Extreme, Range};
use super::dynamics::{JumpSpeed, OneSided, Prediction, Turn};
use crate::summary::number;
use camchain_codegen::design::{CamDesign, Motion};
use camchain_runtime::kinds::Outline;
use camchain_runtime::motion_law::Law;
use std::f64::consts::TAU;
use std::fmt::Write as _;
use std::io::{self, Write};

/// The units of the follower's displacement and its first three time derivatives.
pub fn units(design: &CamDesign) -> [&'static str; 4] {
    match design.geometry.motion {
        Motion::Translating { .. } | Motion::Axial { .. } => ["m", "m/s", "m/s²", "m/s³"],
        Motion::Oscillating { .. } => ["rad", "rad/s", "rad/s²", "rad/s³"],
    }
}

/// A number to 12 significant digits (what the peaks are printed with, so that they can be
/// checked against closed forms to 1e-11): fixed for ordinary magnitudes, scientific else.
pub fn precise(x: f64) -> String {
    let magnitude = x.abs();
    if x == 0.0 || !x.is_finite() {
        format!("{x}")
    } else if (1e-3..1e9).contains(&magnitude) {
        let decimals = (11 - magnitude.log10().floor() as i32).max(0) as usize;
        format!("{x:.decimals$}")
    } else {
        format!("{x:.11e}")
    }
}

/// A cam angle (rad) in degrees within a turn, with `decimals` decimals.
pub fn degrees(theta: f64, decimals: usize) -> String {
    let d = theta.to_degrees().rem_euclid(360.0);
    // 359.9999999° prints as 360.000°: say 0 instead.
    let text = format!("{d:.decimals$}");
    if text.parse::<f64>().is_ok_and(|v| v >= 360.0) {
        format!("{:.decimals$}", 0.0)
    } else {
        text
    }
}

/// The turn (from 1) an unwrapped cam angle (rad) falls in.
pub fn turn_of(theta: f64) -> usize {
    (theta / TAU).floor().max(0.0) as usize + 1
}

/// A length as the summaries print numbers: `0.012500 m`.
fn metres(x: f64) -> String {
    format!("{} m", number(x))
}

/// The design part of the summary: follower, cam, segments, peaks, pressure angle,
/// curvature, undercut or face width, joints.
pub fn design_summary(
    design: &CamDesign,
    analysis: &Analysis,
    samples: usize,
    speed_source: &str,
) -> String {
    let mut text = String::new();
    let g = &design.geometry;
    let u = units(design);
    let kind = design.senses.shape;
    let follower = match kind.outline() {
        Outline::Circle => format!("{} (radius {})", kind.label(), metres(g.roller)),
        Outline::Point | Outline::Line => kind.label().to_string(),
    };
    let motion = match &g.motion {
        Motion::Translating { offset } if *offset == 0.0 => {
            "translating in-line (guide through the cam's axis)".to_string()
        }
        Motion::Translating { offset } => {
            format!(
                "translating, its guide offset {} from the cam's axis",
                metres(*offset)
            )
        }
        Motion::Axial { radius } => format!(
            "translating along the cam's axis in a barrel cam's groove, its centre at the pitch \
             radius {}",
            metres(*radius)
        ),
        Motion::Oscillating {
            pivot,
            arm,
            face_offset,
        } => {
            let swing = if design.senses.swing > 0.0 {
                "counterclockwise"
            } else {
                "clockwise"
            };
            let face = match kind.outline() {
                Outline::Line => {
                    format!(", the face {} from the pivot's line", metres(*face_offset))
                }
                Outline::Point | Outline::Circle => format!(", arm {}", metres(*arm)),
            };
            format!(
                "oscillating about the pivot ({}, {}) m{face}, swinging {swing} as it rises",
                number(pivot[0]),
                number(pivot[1])
            )
        }
    };
    let _ = writeln!(text, "  follower: {follower}, {motion}");
    let turning = if design.senses.turning > 0.0 {
        "counterclockwise"
    } else {
        "clockwise"
    };
    let prime = match kind.outline() {
        Outline::Point | Outline::Circle => g.base_radius + g.roller,
        Outline::Line => g.base_radius,
    };
    match g.motion {
        Motion::Axial { radius } => {
            let _ = writeln!(
                text,
                "  cam: a barrel turning {turning}; the groove's centre {} along the axis at \
                 the program's start, its flanks {} to either side; developed at the pitch \
                 radius {} for the pressure angle and the radii of curvature",
                metres(g.base_radius),
                metres(g.roller),
                metres(radius)
            );
        }
        Motion::Translating { .. } | Motion::Oscillating { .. } => {
            let _ = writeln!(
                text,
                "  cam: turns {turning}; base circle radius {}, prime circle radius {}",
                metres(g.base_radius),
                metres(prime)
            );
        }
    }
    let _ = writeln!(text, "  segments (cam angle in degrees, lift in {}):", u[0]);
    let _ = writeln!(
        text,
        "    {:>2}  {:<20}{:>10}{:>10}{:>14}{:>14}",
        "#", "law", "from", "to", "lift from", "lift to"
    );
    let program = &design.program;
    let mut before = 0.0;
    for (i, (segment, start)) in program.segments().iter().zip(program.starts()).enumerate() {
        let end = start + segment.angle;
        let _ = writeln!(
            text,
            "    {i:>2}  {:<20}{:>10.3}{:>10.3}{:>14}{:>14}",
            segment.law.name(),
            start.to_degrees(),
            end.to_degrees(),
            number(before),
            number(segment.lift)
        );
        before = segment.lift;
    }
    let _ = writeln!(
        text,
        "  at ω = {} rad/s ({speed_source}); peaks from {samples} samples and the segment \
         joints, refined by golden-section search:",
        analysis.speed
    );
    for (k, (name, range)) in ["velocity", "acceleration", "jerk"]
        .iter()
        .zip(&analysis.peaks)
        .enumerate()
    {
        let label = format!("{name} [{}]", u[k + 1]);
        let _ = writeln!(
            text,
            "    {label:<22}max {} at {}°   min {} at {}°",
            precise(range.max.value),
            degrees(range.max.theta, 6),
            precise(range.min.value),
            degrees(range.min.theta, 6)
        );
    }
    let p = &analysis.pressure;
    let largest = p.max.value.abs().max(p.min.value.abs());
    let verdict = if largest > design.max_pressure_angle {
        "EXCEEDED"
    } else {
        "within it"
    };
    let _ = writeln!(
        text,
        "  pressure angle: max {:.3}° at {}°, min {:.3}° at {}°; limit {:.1}°: {verdict}",
        p.max.value.to_degrees(),
        degrees(p.max.theta, 3),
        p.min.value.to_degrees(),
        degrees(p.min.theta, 3),
        design.max_pressure_angle.to_degrees()
    );
    let convex = match analysis.convex {
        Some(e) => format!(
            "smallest where convex {} at {}°",
            metres(e.value),
            degrees(e.theta, 3)
        ),
        None => "convex nowhere".to_string(),
    };
    let concave = match analysis.concave {
        Some(e) => format!(
            "smallest where concave {} at {}°",
            metres(e.value),
            degrees(e.theta, 3)
        ),
        None => "concave nowhere".to_string(),
    };
    let barrel = matches!(g.motion, Motion::Axial { .. });
    let curve = match (barrel, design.groove) {
        (true, _) => "the groove's lower flank's radius of curvature (developed)",
        (false, true) => "the groove's inner flank's radius of curvature",
        (false, false) => "profile's radius of curvature",
    };
    let _ = writeln!(text, "  {curve}: {convex}; {concave}");
    if let Some(undercut) = &analysis.undercut {
        let _ = writeln!(
            text,
            "  undercut margin: {} (the pitch curve's smallest convex radius {} at {}° less the \
             roller's {})",
            metres(undercut.margin),
            metres(undercut.pitch.value),
            degrees(undercut.pitch.theta, 3),
            metres(g.roller)
        );
    }
    if design.groove {
        // The upper (outer) flank is convex where the pitch curve is hollow seen from the
        // lower (inner) one.
        let (theta, pitch) = design.least(camchain_codegen::design::DESIGN_SAMPLES, |p| {
            if p.pitch_radius < 0.0 {
                -p.pitch_radius
            } else {
                f64::INFINITY
            }
        });
        let flank = if barrel { "upper" } else { "outer" };
        if pitch.is_finite() {
            let _ = writeln!(
                text,
                "  the groove's {flank} flank: undercut margin {} (the pitch curve's smallest \
                 concave radius {} at {}° less the roller's {})",
                metres(pitch - g.roller),
                metres(pitch),
                degrees(theta, 3),
                metres(g.roller)
            );
        } else {
            let _ = writeln!(
                text,
                "  the groove's {flank} flank: the pitch curve is concave nowhere, so it cannot \
                 be undercut"
            );
        }
    }
    if let Some(face) = &analysis.face {
        let Range { max, min } = face.offset;
        let _ = writeln!(
            text,
            "  face width needed: {} (the contact point goes from {} at {}° to {} at {}° along \
             the face, from {})",
            metres(max.value - min.value),
            number(min.value),
            degrees(min.theta, 3),
            number(max.value),
            degrees(max.theta, 3),
            match g.motion {
                Motion::Translating { .. } | Motion::Axial { .. } => "the guide's line",
                Motion::Oscillating { .. } => "the foot of the pivot",
            }
        );
    }
    text.push_str(&joints(design, analysis, &u));
    text
}

/// The joints where the velocity, acceleration or jerk jumps, at ω.
fn joints(design: &CamDesign, analysis: &Analysis, u: &[&str; 4]) -> String {
    let mut text = String::new();
    let relevant: Vec<_> = analysis.jumps.iter().collect();
    if relevant.is_empty() {
        let _ = writeln!(
            text,
            "  joints: the velocity, acceleration and jerk are continuous at every joint"
        );
        return text;
    }
    let _ = writeln!(text, "  joints where the motion jumps:");
    let segments = design.program.segments();
    let names = ["", "velocity", "acceleration", "jerk"];
    for jump in relevant {
        let after = segments.get(jump.segment).map_or(Law::Dwell, |s| s.law);
        let previous = if jump.segment == 0 {
            segments.len().saturating_sub(1)
        } else {
            jump.segment - 1
        };
        let before = segments.get(previous).map_or(Law::Dwell, |s| s.law);
        let at_speed = jump.size * analysis.speed.powi(jump.order as i32);
        let _ = writeln!(
            text,
            "    {}° ({} → {}, segment {}): {} jumps by {} {} ({} per rad^{})",
            degrees(jump.angle, 3),
            before.name(),
            after.name(),
            jump.segment,
            names.get(jump.order).copied().unwrap_or("derivative"),
            number(at_speed),
            u.get(jump.order).copied().unwrap_or(""),
            number(jump.size),
            jump.order
        );
    }
    text
}

/// An extreme of the force: "3.21 N at 239.9°".
fn force_at(e: &Extreme) -> String {
    format!("{} N at {}°", number(e.value), degrees(e.theta, 3))
}

/// The least and largest of a turn's force at the design angles.
pub fn force_range(turn: &Turn) -> Option<(Extreme, Extreme)> {
    let n = turn.force.len().saturating_sub(1).max(1);
    let points = turn.force.iter().enumerate().filter(|(_, f)| f.is_finite());
    let extreme = |pick: fn(f64, f64) -> bool| {
        points
            .clone()
            .fold(None::<(usize, f64)>, |best, (k, &f)| match best {
                Some((_, b)) if !pick(f, b) => best,
                _ => Some((k, f)),
            })
            .map(|(k, f)| Extreme {
                theta: TAU * k as f64 / n as f64,
                value: f,
            })
    };
    Some((extreme(|f, b| f < b)?, extreme(|f, b| f > b)?))
}

/// The dynamics part of the summary: the force over the nominal turn (the middle one of
/// `turns`, run at ω/2, ω, 2ω, or only ω), the predicted jump speed, the one-sided run and the
/// runs' wall times; `parameter` names the speed's parameter, `follower_unit` the follower's
/// velocity unit.
pub fn dynamics_summary(
    engine: &str,
    dof: usize,
    turns: &[&Turn],
    prediction: Option<&Prediction>,
    parameter: &str,
    one_sided: &Result<OneSided, String>,
    follower_unit: &str,
) -> String {
    let Some(nominal) = turns.get(turns.len() / 2) else {
        return String::new();
    };
    let mut text = String::new();
    let freedom = match dof {
        0 => "no degree of freedom in bilateral contact: the follower is driven by the cam".into(),
        1 => "1 degree of freedom in bilateral contact".to_string(),
        n => format!("{n} degrees of freedom in bilateral contact"),
    };
    let _ = writeln!(text, "  dynamics ({engine}; {freedom}):");
    if let Some((least, most)) = force_range(nominal) {
        let _ = writeln!(
            text,
            "    contact force at ω (bilateral, one turn, {parameter} = {}): least {}, largest {}",
            nominal.parameter,
            force_at(&least),
            force_at(&most)
        );
    }
    match prediction {
        None => {
            let _ = writeln!(
                text,
                "    jump speed: not predicted: N = A + Bω + Cω² holds for a rigidly driven \
                 follower only (every coordinate prescribed or solved from the contact), and \
                 this mechanism has {dof} degree(s) of freedom"
            );
        }
        Some(p) => {
            let speeds = format!(
                "from bilateral runs at {}, {} and {} rad/s",
                p.speeds[0], p.speeds[1], p.speeds[2]
            );
            let line = match p.jump {
                JumpSpeed::At { speed, theta } => format!(
                    "predicted jump speed {} rad/s: the least contact force over a turn reaches \
                     zero there, first at cam angle {}° (N = A + Bω + Cω² {speeds})",
                    precise(speed),
                    degrees(theta, 3)
                ),
                JumpSpeed::AtRest { theta, force } => format!(
                    "jump speed: none: the contact force is {} N at rest at cam angle {}°: the \
                     follower is not held on the cam even at low speed ({speeds})",
                    number(force),
                    degrees(theta, 3)
                ),
                JumpSpeed::Never => format!(
                    "jump speed: none: the contact force stays positive at every speed ({speeds})"
                ),
            };
            let _ = writeln!(text, "    {line}");
        }
    }
    match one_sided {
        Err(why) => {
            let _ = writeln!(text, "    one-sided run: {why}");
        }
        Ok(run) => text.push_str(&one_sided_summary(run, follower_unit)),
    }
    let each: Vec<String> = turns
        .iter()
        .map(|t| {
            format!(
                "{} rad/s {} ({} steps)",
                t.speed,
                wall_time(t.wall),
                t.stats.steps
            )
        })
        .collect();
    let mut work = format!("    wall time: bilateral turns at {}", each.join(", "));
    if let Ok(run) = one_sided {
        let _ = write!(
            work,
            "; one-sided run {} ({} steps, {} rejected)",
            wall_time(run.wall),
            run.trajectory.stats.steps,
            run.trajectory.stats.rejected
        );
    }
    let _ = writeln!(text, "{work} (the runs in parallel)");
    text
}

/// "12.3 ms" or "1.23 s".
fn wall_time(wall: std::time::Duration) -> String {
    let seconds = wall.as_secs_f64();
    if seconds < 1.0 {
        format!("{:.1} ms", seconds * 1e3)
    } else {
        format!("{seconds:.2} s")
    }
}

/// Most flights listed one by one.
const LISTED_FLIGHTS: usize = 6;

/// The one-sided run's lines: where the follower lifts off and lands (the follower's
/// velocity in `unit`), or its smallest contact force.
fn one_sided_summary(run: &OneSided, unit: &str) -> String {
    let mut text = String::new();
    let integrator = run
        .integrator
        .map_or_else(String::new, |name| format!(", {name}"));
    let head = format!(
        "    one-sided run (restitution {}, {} turns at ω{integrator})",
        run.restitution, run.turns
    );
    if run.flights.is_empty() {
        match run.least {
            Some((force, t, theta)) => {
                let _ = writeln!(
                    text,
                    "{head}: stays on the cam; smallest contact force {} N at t = {} s (cam \
                     angle {}°, turn {})",
                    number(force),
                    number(t),
                    degrees(theta, 3),
                    turn_of(theta)
                );
            }
            None => {
                let _ = writeln!(text, "{head}: stays on the cam");
            }
        }
        return text;
    }
    let _ = writeln!(
        text,
        "{head}: the follower lifts off {} time{}:",
        run.flights.len(),
        if run.flights.len() == 1 { "" } else { "s" }
    );
    for flight in run.flights.iter().take(LISTED_FLIGHTS) {
        let speed = flight.speed.map_or_else(String::new, |v| {
            format!(", follower velocity {} {unit}", number(v))
        });
        let landing = match &flight.landing {
            Some(l) => format!(
                "; lands at t = {:.9} s (cam angle {}°, turn {}) at {} m/s, {}",
                l.t,
                degrees(l.theta, 3),
                turn_of(l.theta),
                number(l.approach),
                if l.stays {
                    "stays on the cam".to_string()
                } else {
                    format!("rebounds at {} m/s", number(l.rebound))
                }
            ),
            None => "; still in flight at the end".to_string(),
        };
        let _ = writeln!(
            text,
            "      lifts off at t = {:.9} s (cam angle {}°, turn {}{speed}){landing}",
            flight.t,
            degrees(flight.theta, 3),
            turn_of(flight.theta)
        );
    }
    if run.flights.len() > LISTED_FLIGHTS {
        let _ = writeln!(
            text,
            "      … and {} more lift-offs",
            run.flights.len() - LISTED_FLIGHTS
        );
    }
    text
}

/// The header of `design.csv`.
pub const CSV_HEADER: &str = "cam_angle_deg,s,v,a,j,pressure_angle_deg,radius_of_curvature,\
                              profile_x,profile_y,pitch_x,pitch_y,normal_force";

/// `design.csv`: one row per sample angle; numbers in Rust's shortest round-trip form.
pub fn write_csv(out: &mut dyn Write, analysis: &Analysis, force: &[f64]) -> io::Result<()> {
    writeln!(out, "{CSV_HEADER}")?;
    let w = analysis.speed;
    for (k, p) in analysis.points.iter().enumerate() {
        let values = [
            p.theta.to_degrees(),
            p.lift[0],
            p.lift[1] * w,
            p.lift[2] * w * w,
            p.lift[3] * w * w * w,
            p.pressure_angle.to_degrees(),
            p.radius_of_curvature,
            p.contact[0],
            p.contact[1],
            p.pitch[0],
            p.pitch[1],
            force.get(k).copied().unwrap_or(f64::NAN),
        ];
        let row: Vec<String> = values.iter().map(|v| format!("{v:?}")).collect();
        writeln!(out, "{}", row.join(","))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn peaks_print_twelve_digits() {
        assert_eq!(precise(0.572957795130823), "0.572957795131");
        assert_eq!(precise(-171.887338539), "-171.887338539");
        assert_eq!(precise(1.5e-5), "1.50000000000e-5");
        assert_eq!(degrees(-1e-12, 3), "0.000");
        assert_eq!(degrees(std::f64::consts::PI, 1), "180.0");
        assert_eq!(turn_of(7.0), 2);
    }
}
