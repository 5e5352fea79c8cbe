//! What a cam designer reads off a design at its nominal speed: the follower's peaks, the
//! pressure angle, the profile's curvature, the roller's undercut margin or the flat face's
//! width, and the joints where the motion is not smooth.
//!
//! Every extreme is found by `CamDesign::least`: the grid of `samples` angles plus every
//! segment joint (and its two sides), then golden-section refinement between the neighbours
//! of the best sample. So a peak inside a segment is found to rounding (where a smooth
//! function is flat, an error δ in the angle costs only ~δ² in the value), and a peak at a
//! joint is taken on the side where it is reached.

use camchain_codegen::design::{self, CamDesign, DesignPoint, Motion};
use camchain_runtime::kinds::Outline;
use camchain_runtime::motion_law::Jump;

/// A value and the cam angle where it occurs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Extreme {
    /// The cam angle (rad, in [0, 2π]).
    pub theta: f64,
    /// The value there.
    pub value: f64,
}

/// The largest and the smallest value of a quantity over a turn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    /// The largest value.
    pub max: Extreme,
    /// The smallest value.
    pub min: Extreme,
}

/// The width a flat face needs: where the contact point goes along it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FaceWidth {
    /// The contact point's offset along the face from the follower's reference point (the
    /// guide's line for a translating face, the foot of the pivot for an oscillating one),
    /// both ways (m).
    pub offset: Range,
}

/// The undercut margin of a roller.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Undercut {
    /// The smallest radius of curvature of the pitch curve where it is convex.
    pub pitch: Extreme,
    /// That radius less the roller's: how far the design is from undercutting (m).
    pub margin: f64,
}

/// A design analysed at a speed.
#[derive(Debug, Clone)]
pub struct Analysis {
    /// The cam speed ω (rad/s).
    pub speed: f64,
    /// The design at `samples` + 1 evenly spaced angles over a turn (0 and 2π both).
    pub points: Vec<DesignPoint>,
    /// The follower's velocity, acceleration and jerk at ω (units of the lift per s^k).
    pub peaks: [Range; 3],
    /// The pressure angle (rad).
    pub pressure: Range,
    /// The smallest radius of curvature where the profile is convex (m).
    pub convex: Option<Extreme>,
    /// The smallest radius of curvature where the profile is concave (m, as a positive
    /// number), if it is concave anywhere.
    pub concave: Option<Extreme>,
    /// A roller's undercut margin.
    pub undercut: Option<Undercut>,
    /// A flat face's width.
    pub face: Option<FaceWidth>,
    /// The joints where the velocity, acceleration or jerk jumps (per rad^order).
    pub jumps: Vec<Jump>,
}

/// Relative size below which a change at a joint is rounding, not a jump (of the largest
/// value of that derivative over the turn; the closed forms meet at joints to ~1e-15).
pub const JUMP_TOLERANCE: f64 = 1e-9;

/// The largest and smallest of `f` over a turn, refined.
fn range(design: &CamDesign, samples: usize, f: impl Fn(&DesignPoint) -> f64) -> Range {
    let (low_at, low) = design.least(samples, &f);
    let (high_at, high) = design.least(samples, |p| -f(p));
    Range {
        max: Extreme {
            theta: high_at,
            value: -high,
        },
        min: Extreme {
            theta: low_at,
            value: low,
        },
    }
}

impl Analysis {
    /// Analyses `design` at the speed `speed` (rad/s) on a grid of `samples` angles.
    pub fn new(design: &CamDesign, speed: f64, samples: usize) -> Self {
        let samples = samples.max(1);
        let peaks = [1, 2, 3].map(|order| {
            let scale = speed.powi(order);
            let r = range(design, samples, |p| p.lift[order as usize]);
            let at = |e: Extreme| Extreme {
                theta: e.theta,
                value: e.value * scale,
            };
            Range {
                max: at(r.max),
                min: at(r.min),
            }
        });
        let pressure = range(design, samples, |p| p.pressure_angle);
        // Curvature 1/ρ is continuous where ρ passes through infinity (an inflection):
        // its largest value is the smallest convex radius, its smallest (if negative) the
        // smallest concave one.
        let curvature = range(design, samples, |p| 1.0 / p.radius_of_curvature);
        let convex = (curvature.max.value > 0.0).then(|| Extreme {
            theta: curvature.max.theta,
            value: 1.0 / curvature.max.value,
        });
        let concave = (curvature.min.value < 0.0).then(|| Extreme {
            theta: curvature.min.theta,
            value: -1.0 / curvature.min.value,
        });
        let undercut = match design.senses.shape.outline() {
            Outline::Circle => {
                let (theta, k) = design.least(samples, |p| -1.0 / p.pitch_radius);
                (k < 0.0).then(|| Undercut {
                    pitch: Extreme {
                        theta,
                        value: -1.0 / k,
                    },
                    margin: -1.0 / k - design.geometry.roller,
                })
            }
            Outline::Point | Outline::Line => None,
        };
        let face = match design.senses.shape.outline() {
            Outline::Line => Some(FaceWidth {
                offset: range(design, samples, |p| face_offset(design, p)),
            }),
            Outline::Point | Outline::Circle => None,
        };
        Analysis {
            speed,
            points: design.turn(samples),
            peaks,
            pressure,
            convex,
            concave,
            undercut,
            face,
            jumps: design.program.jumps(JUMP_TOLERANCE),
        }
    }
}

/// A flat face's contact point along the face, from the guide's line (translating) or the
/// foot of the pivot on the face (oscillating), in the design frame (m).
pub fn face_offset(design: &CamDesign, p: &DesignPoint) -> f64 {
    let g = &design.geometry;
    let placed = design::place(g, design.senses, &p.lift[0], &p.lift[1]);
    let reference = match &g.motion {
        Motion::Translating { offset } => [*offset, 0.0],
        Motion::Oscillating { pivot, .. } => *pivot,
        Motion::Axial { .. } => [0.0, 0.0],
    };
    // Along J n, n the face's normal.
    let along = [-placed.normal[1], placed.normal[0]];
    (placed.contact[0] - reference[0]) * along[0] + (placed.contact[1] - reference[1]) * along[1]
}

#[cfg(test)]
mod tests {
    use super::*;
    use camchain_codegen::design::{Geometry, Senses};
    use camchain_codegen::profile::Tabulated;
    use camchain_runtime::FollowerKind;
    use camchain_runtime::motion_law::{Law, MotionProgram, Segment};
    use std::f64::consts::PI;

    fn cycloidal(shape: FollowerKind, roller: f64) -> CamDesign {
        let third = 2.0 * PI / 3.0;
        let program = MotionProgram::new(&[
            Segment {
                law: Law::Cycloidal,
                angle: third,
                lift: 0.01,
            },
            Segment {
                law: Law::Dwell,
                angle: third,
                lift: 0.01,
            },
            Segment {
                law: Law::Cycloidal,
                angle: third,
                lift: 0.0,
            },
        ])
        .expect("a program");
        CamDesign {
            law: Tabulated::law("law", program.clone()),
            program,
            geometry: Geometry {
                base_radius: 0.04,
                roller,
                motion: Motion::Translating { offset: 0.0 },
            },
            senses: Senses {
                turning: 1.0,
                swing: 1.0,
                shape,
            },
            max_pressure_angle: 0.5,
            speed: Some(10.0),
            speed_expression: None,
            groove: false,
        }
    }

    #[test]
    fn peaks_are_the_textbook_ones_and_a_flat_face_has_a_width() {
        let design = cycloidal(FollowerKind::Roller, 0.01);
        let a = Analysis::new(&design, 10.0, 360);
        let (h, beta, w) = (0.01, 2.0 * PI / 3.0, 10.0);
        // Closed forms 2hω/β and 2πhω²/β², refined to rounding.
        assert!((a.peaks[0].max.value - 2.0 * h * w / beta).abs() < 1e-14);
        assert!((a.peaks[0].min.value + 2.0 * h * w / beta).abs() < 1e-14);
        assert!((a.peaks[1].max.value - 2.0 * PI * h * w * w / beta.powi(2)).abs() < 1e-12);
        // The in-line roller's pressure angle is symmetric, the cam convex on the dwells.
        assert!((a.pressure.max.value + a.pressure.min.value).abs() < 1e-9);
        assert!(a.convex.is_some() && a.undercut.is_some());
        let flat = Analysis::new(&cycloidal(FollowerKind::Flat, 0.0), 10.0, 360);
        // A translating flat face: the contact is s′ off the axis: ±2h/β at most.
        let width = flat.face.expect("a face").offset;
        assert!((width.max.value - 2.0 * h / beta).abs() < 1e-12);
        assert!((width.min.value + 2.0 * h / beta).abs() < 1e-12);
    }
}
