//! Warnings for a model that is valid but almost surely not what its author meant: angles
//! that look like degrees, huge initial speeds. They do not stop a build or a run; the build
//! prints them as cargo warnings and the command line before it simulates, each located in
//! the model file like an error.

use crate::design::{CamDesign, DESIGN_SAMPLES};
use crate::model::{JointKind, Model};
use std::f64::consts::TAU;

/// Initial speeds above this (rad/s or m/s) are reported: 1000 rad/s is about 9500 rpm.
pub const HUGE_SPEED: f64 = 1000.0;

/// A suspicious value: the dotted field path (as in errors) and what looks wrong.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Warning {
    /// Dotted path of the field, e.g. `initial.q["q1"]`.
    pub field: String,
    /// What looks wrong and what to check.
    pub message: String,
}

/// Every warning for `model`, in file order.
pub fn warnings(model: &Model) -> Vec<Warning> {
    let mut out = Vec::new();
    for (i, body) in model.bodies.iter().enumerate() {
        let joint = &body.joint;
        let name = &joint.coordinate;
        let revolute = joint.kind == JointKind::Revolute;
        let given = |flags: &[bool]| flags.get(i).copied().unwrap_or(false);
        if revolute && given(&model.initial.given_q) && model.initial.q[i].abs() > TAU {
            out.push(Warning {
                field: format!("initial.q[{name:?}]"),
                message: degrees(&format!("the initial angle of {name}"), model.initial.q[i]),
            });
        }
        if let (true, Some(spring)) = (revolute, &joint.spring) {
            if spring.rest.abs() > TAU {
                out.push(Warning {
                    field: format!("bodies[{i}].joint.spring.rest"),
                    message: degrees(&format!("the spring's rest angle of {name}"), spring.rest),
                });
            }
        }
        if let (true, Some(drive)) = (revolute, &joint.prescribed) {
            if let Some(swing) = oscillating_swing(|t| drive.expr.eval(t), model.simulation.t_end) {
                if swing > 2.0 * TAU {
                    out.push(Warning {
                        field: format!("bodies[{i}].joint.prescribed"),
                        message: format!(
                            "the drive of {name} swings over {swing:.4} rad ({:.1} turns) and \
                             back: angles are in radians (degrees?)",
                            swing / TAU
                        ),
                    });
                }
            }
        }
        if given(&model.initial.given_qd) && model.initial.qd[i].abs() > HUGE_SPEED {
            let unit = if revolute { "rad/s" } else { "m/s" };
            out.push(Warning {
                field: format!("initial.qd[{name:?}]"),
                message: format!(
                    "the initial speed of {name}, {} {unit}, is huge (above {HUGE_SPEED} \
                     {unit}): a unit mistake?",
                    model.initial.qd[i]
                ),
            });
        }
    }
    for (i, contact) in model.contacts.iter().enumerate() {
        if let Some(design) = &contact.design {
            out.extend(design_warnings(i, &contact.name, design));
        }
    }
    out
}

/// A designed cam's warnings: the acceleration jumping where two segments join (an infinite
/// jerk), and the pressure angle above its limit.
pub fn design_warnings(index: usize, name: &str, design: &CamDesign) -> Vec<Warning> {
    let mut out = Vec::new();
    for jump in design.program.jumps(1e-9) {
        if jump.order != 2 {
            continue;
        }
        let at_speed = match design.speed {
            Some(omega) => format!(" ({:.4e} at {omega} rad/s)", jump.size * omega * omega),
            None => String::new(),
        };
        out.push(Warning {
            field: format!("contacts[{index}].law.segments[{}]", jump.segment),
            message: format!(
                "contact `{name}`: the follower's acceleration jumps by {:.4e} per rad²{at_speed} \
                 where this segment starts (cam angle {:.3}°): an infinite jerk; laws that start \
                 and end at zero acceleration (cycloidal, 3-4-5, 4-5-6-7, modified trapezoid, \
                 modified sine) avoid it",
                jump.size,
                jump.angle.to_degrees()
            ),
        });
    }
    let (theta, negative) = design.least(DESIGN_SAMPLES, |p| -p.pressure_angle.abs());
    let largest = -negative;
    if largest > design.max_pressure_angle {
        out.push(Warning {
            field: format!("contacts[{index}].law"),
            message: format!(
                "contact `{name}`: the pressure angle reaches {:.2}° at cam angle {:.3}°, above \
                 the limit of {:.1}° (`max_pressure_angle`): the follower is pushed sideways \
                 more than along its motion; a larger base circle lowers it",
                largest.to_degrees(),
                theta.to_degrees(),
                design.max_pressure_angle.to_degrees()
            ),
        });
    }
    out
}

fn degrees(what: &str, value: f64) -> String {
    format!(
        "{what} is {value} rad, more than a full turn: angles are in radians (degrees? \
         {value}° would be {:.6} rad)",
        value.to_radians()
    )
}

/// The range a drive covers over [0, t_end] when it comes back (its end is nearer its start
/// than half the range: an oscillation, not a rotation, which legitimately turns many
/// times); `None` for a rotation or an expression that is not finite.
fn oscillating_swing(q: impl Fn(f64) -> f64, t_end: f64) -> Option<f64> {
    const SAMPLES: usize = 400;
    let values: Vec<f64> = (0..=SAMPLES)
        .map(|k| q(t_end * k as f64 / SAMPLES as f64))
        .collect();
    if values.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let (lo, hi) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let range = hi - lo;
    let net = (values[SAMPLES] - values[0]).abs();
    (net < 0.5 * range).then_some(range)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_oscillation_is_told_from_a_rotation() {
        let swing = oscillating_swing(|t| 90.0 * (2.0 * std::f64::consts::PI * t).sin(), 2.0);
        assert!((swing.expect("oscillates") - 180.0).abs() < 1e-9);
        assert_eq!(
            oscillating_swing(|t| 50.0 * t, 10.0),
            None,
            "a camshaft turning"
        );
        assert_eq!(
            oscillating_swing(|t| (t - 1.0).ln(), 2.0),
            None,
            "not finite at 0"
        );
    }
}
