//! The figures of `camchain cam`, drawn with the command line's chart helpers
//! ([`crate::plots`]):
//!
//! - `svaj`: the follower's displacement, velocity, acceleration and jerk at ω against the
//!   cam angle, the peaks marked;
//! - `pressure_curvature`: the pressure angle with its limit, and the profile's radius of
//!   curvature, the extremes marked and labelled;
//! - `profile`: the cam in its frame with its pitch curve, base circle and prime circle, at
//!   equal scales;
//! - `force`: the contact force against the cam angle, bilateral (the design's) and one-sided
//!   (the simulated follower), with the predicted jump speed; and the least force over a
//!   turn against the speed.

use super::analysis::{Analysis, Extreme};
use super::dynamics::{JumpSpeed, OneSided, Prediction, Turn};
use super::report::{degrees, turn_of, units};
use crate::kinematics::CamPicture;
use crate::plots::{Figure, Frame, LinePanel, MechanismPanel, Panel, Series};
use crate::summary::number;
use camchain_codegen::design::{self, CamDesign};
use camchain_runtime::kinds::Outline;
use plotters::style::RGBColor;
use std::f64::consts::TAU;

/// Width of every figure (pixels).
const WIDTH: u32 = 1000;
/// Height of a row of line plots (pixels).
const LINE_ROW: u32 = 300;
/// Height of the profile's panel (pixels).
const PROFILE_ROW: u32 = 820;
/// The curves' colour.
const BLUE: RGBColor = RGBColor(31, 119, 180);
/// Maxima, the jump speed, the follower at θ = 0.
const RED: RGBColor = RGBColor(214, 39, 40);
/// Minima and the nominal speed.
const GREEN: RGBColor = RGBColor(44, 160, 44);
/// The prime circle.
const ORANGE: RGBColor = RGBColor(255, 127, 14);
/// The smallest concave radius.
const PURPLE: RGBColor = RGBColor(148, 103, 189);
/// Limits and the base circle.
const GREY: RGBColor = RGBColor(120, 120, 120);
/// The cam angle's axis.
const ANGLE_AXIS: &str = "cam angle θ [deg]";

/// The finite range of values.
fn data_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        })
}

/// A range with 8 % of margin each side (room for the marks), widened when flat or empty.
fn padded(range: (f64, f64)) -> (f64, f64) {
    crate::figures::padded_by(range, 0.08)
}

/// A small diamond around (x, y) on axes of the given spans, labelled: how a point is
/// marked with the line charts.
fn mark(x: f64, y: f64, spans: (f64, f64), color: RGBColor, label: String) -> Series {
    let (dx, dy) = (spans.0 / 110.0, spans.1 / 30.0);
    Series {
        label: Some(label),
        color,
        points: vec![
            (x - dx, y),
            (x, y + dy),
            (x + dx, y),
            (x, y - dy),
            (x - dx, y),
        ],
    }
}

/// A curve of the design's points against the cam angle in degrees.
fn against_angle(analysis: &Analysis, value: impl Fn(usize) -> f64) -> Vec<(f64, f64)> {
    analysis
        .points
        .iter()
        .enumerate()
        .map(|(k, p)| (p.theta.to_degrees(), value(k)))
        .collect()
}

/// A line panel against the cam angle over one turn.
fn angle_panel(title: String, y_label: String, y_range: (f64, f64), series: Vec<Series>) -> Panel {
    Panel::Lines(LinePanel {
        title,
        x_label: ANGLE_AXIS.into(),
        y_label,
        x_range: (0.0, 360.0),
        y_range,
        series,
        zero_line: true,
        markers: Vec::new(),
    })
}

/// A figure of one panel per row.
fn column(title: String, rows: Vec<(u32, Panel)>) -> Figure {
    Figure::column(title, WIDTH, rows)
}

/// Displacement, velocity, acceleration and jerk at ω against the cam angle.
pub fn svaj(name: &str, design: &CamDesign, analysis: &Analysis) -> Figure {
    let u = units(design);
    let w = analysis.speed;
    let quantities = [
        ("displacement s (lift above the base circle)", "s"),
        ("velocity v = ω ds/dθ", "v"),
        ("acceleration a = ω² d²s/dθ²", "a"),
        ("jerk j = ω³ d³s/dθ³", "j"),
    ];
    let mut rows = Vec::new();
    for (order, (title, symbol)) in quantities.iter().enumerate() {
        let scale = w.powi(order as i32);
        let points = against_angle(analysis, |k| analysis.points[k].lift[order] * scale);
        let y_range = padded(data_range(points.iter().map(|p| p.1)));
        let mut series = vec![Series {
            label: None,
            color: BLUE,
            points,
        }];
        if order > 0 {
            let peaks = &analysis.peaks[order - 1];
            let spans = (360.0, y_range.1 - y_range.0);
            for (e, color, what) in [(peaks.max, RED, "max"), (peaks.min, GREEN, "min")] {
                series.push(mark(
                    e.theta.to_degrees(),
                    e.value,
                    spans,
                    color,
                    format!(
                        "{what} {} {} at {}°",
                        number(e.value),
                        u[order],
                        degrees(e.theta, 2)
                    ),
                ));
            }
        }
        rows.push((
            LINE_ROW,
            angle_panel(
                title.to_string(),
                format!("{symbol} [{}]", u[order]),
                y_range,
                series,
            ),
        ));
    }
    column(format!("{name}: follower motion at ω = {w} rad/s"), rows)
}

/// Splits a curve where it leaves `(lo, hi)` (a radius of curvature through infinity at an
/// inflection), so that no line joins the two sides.
fn split_outside(points: &[(f64, f64)], (lo, hi): (f64, f64)) -> Vec<Vec<(f64, f64)>> {
    let mut pieces: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
    for &(x, y) in points {
        if y.is_finite() && y >= lo && y <= hi {
            if let Some(piece) = pieces.last_mut() {
                piece.push((x, y));
            }
        } else if pieces.last().is_some_and(|p| !p.is_empty()) {
            pieces.push(Vec::new());
        }
    }
    pieces.retain(|p| p.len() > 1);
    pieces
}

/// The pressure angle with its limit, and the profile's radius of curvature.
pub fn pressure_curvature(name: &str, design: &CamDesign, analysis: &Analysis) -> Figure {
    let pressure = against_angle(analysis, |k| analysis.points[k].pressure_angle.to_degrees());
    let limit = design.max_pressure_angle.to_degrees();
    let (lo, hi) = data_range(pressure.iter().map(|p| p.1));
    let y_range = padded((lo.min(-limit), hi.max(limit)));
    let spans = (360.0, y_range.1 - y_range.0);
    let mut series = vec![
        Series {
            label: Some("pressure angle".into()),
            color: BLUE,
            points: pressure,
        },
        Series {
            label: Some(format!("limit ±{limit:.1}°")),
            color: GREY,
            points: vec![(0.0, limit), (360.0, limit)],
        },
        Series {
            label: None,
            color: GREY,
            points: vec![(0.0, -limit), (360.0, -limit)],
        },
    ];
    let p = &analysis.pressure;
    for (e, color, what) in [(p.max, RED, "max"), (p.min, GREEN, "min")] {
        series.push(mark(
            e.theta.to_degrees(),
            e.value.to_degrees(),
            spans,
            color,
            format!(
                "{what} {:.2}° at {}°",
                e.value.to_degrees(),
                degrees(e.theta, 1)
            ),
        ));
    }
    let pressure_panel = angle_panel(
        "pressure angle (contact normal against the follower's motion)".into(),
        "pressure angle [deg]".into(),
        y_range,
        series,
    );
    // The radius is drawn within a few cam sizes: it runs off to infinity at inflections.
    let reach = analysis
        .points
        .iter()
        .map(|p| p.contact[0].hypot(p.contact[1]))
        .fold(0.0, f64::max);
    let bound = 3.0 * reach.max(1e-6);
    let radius = against_angle(analysis, |k| analysis.points[k].radius_of_curvature);
    let (lo, hi) = data_range(radius.iter().map(|p| p.1).filter(|r| r.abs() <= bound));
    let y_range = padded((lo.min(0.0), hi.max(0.0)));
    let spans = (360.0, y_range.1 - y_range.0);
    let mut series: Vec<Series> = split_outside(&radius, y_range)
        .into_iter()
        .enumerate()
        .map(|(i, points)| Series {
            label: (i == 0).then(|| "profile's radius of curvature (negative: concave)".into()),
            color: BLUE,
            points,
        })
        .collect();
    let marks: [(Option<Extreme>, f64, RGBColor, &str); 2] = [
        (analysis.convex, 1.0, RED, "smallest convex"),
        (analysis.concave, -1.0, PURPLE, "smallest concave"),
    ];
    for (extreme, sign, color, what) in marks {
        if let Some(e) = extreme {
            series.push(mark(
                e.theta.to_degrees(),
                sign * e.value,
                spans,
                color,
                format!("{what} {} m at {}°", number(e.value), degrees(e.theta, 1)),
            ));
        }
    }
    let radius_panel = angle_panel(
        format!(
            "radius of curvature of the profile (drawn within ±{} m)",
            number(bound)
        ),
        "radius of curvature [m]".into(),
        y_range,
        series,
    );
    column(
        format!("{name}: pressure angle and curvature"),
        vec![
            (LINE_ROW + 60, pressure_panel),
            (LINE_ROW + 60, radius_panel),
        ],
    )
}

/// A circle about the origin.
fn circle(radius: f64) -> Vec<(f64, f64)> {
    (0..=360)
        .map(|k| TAU * f64::from(k) / 360.0)
        .map(|a| (radius * a.cos(), radius * a.sin()))
        .collect()
}

/// A picture with only a line (drawn in its frame's colour).
fn line(points: Vec<(f64, f64)>) -> CamPicture {
    CamPicture {
        outline: Vec::new(),
        closed: false,
        material: Vec::new(),
        base_circle: Vec::new(),
        centre: (f64::NAN, f64::NAN),
        roller: points,
        face: Vec::new(),
        outer_flank: Vec::new(),
    }
}

/// A frame of the profile panel: a legend entry and its lines.
fn frame(label: String, color: RGBColor, cams: Vec<CamPicture>) -> Frame {
    Frame {
        label,
        color,
        links: Vec::new(),
        joints: Vec::new(),
        bases: Vec::new(),
        tips: Vec::new(),
        coms: Vec::new(),
        cams,
    }
}

/// The cam in its frame: profile (filled), pitch curve, base and prime circles, the follower
/// at cam angle 0; equal scales.
pub fn profile(name: &str, design: &CamDesign, analysis: &Analysis) -> Figure {
    if let design::Motion::Axial { radius } = design.geometry.motion {
        return groove(name, design, analysis, radius);
    }
    let g = &design.geometry;
    let outline: Vec<(f64, f64)> = analysis
        .points
        .iter()
        .map(|p| (p.contact[0], p.contact[1]))
        .collect();
    let pitch: Vec<(f64, f64)> = analysis
        .points
        .iter()
        .map(|p| (p.pitch[0], p.pitch[1]))
        .collect();
    let base = circle(g.base_radius);
    let mut frames = vec![frame(
        "base circle".into(),
        GREY,
        vec![CamPicture {
            outline: outline.clone(),
            closed: true,
            material: Vec::new(),
            base_circle: base.clone(),
            centre: (0.0, 0.0),
            roller: Vec::new(),
            face: Vec::new(),
            outer_flank: Vec::new(),
        }],
    )];
    let mut visible: Vec<(f64, f64)> = outline.iter().chain(&base).copied().collect();
    let outline = design.senses.shape.outline();
    if outline == Outline::Circle {
        let prime = circle(g.base_radius + g.roller);
        frames.push(frame("pitch curve".into(), BLUE, vec![line(pitch.clone())]));
        if design.groove {
            // A face cam's groove: its outer flank, the pitch curve moved out by ρ.
            let outer: Vec<(f64, f64)> = analysis
                .points
                .iter()
                .map(|p| {
                    (
                        2.0 * p.pitch[0] - p.contact[0],
                        2.0 * p.pitch[1] - p.contact[1],
                    )
                })
                .collect();
            visible.extend(outer.iter().copied());
            frames.push(frame("outer flank".into(), GREY, vec![line(outer)]));
        }
        frames.push(frame(
            "prime circle".into(),
            ORANGE,
            vec![line(prime.clone())],
        ));
        let (cx, cy) = pitch.first().copied().unwrap_or((0.0, 0.0));
        let rim: Vec<(f64, f64)> = circle(g.roller)
            .into_iter()
            .map(|(x, y)| (cx + x, cy + y))
            .collect();
        frames.push(frame(
            format!("{} at θ = 0", design.senses.shape.label()),
            RED,
            vec![line(rim.clone())],
        ));
        visible.extend(prime);
        visible.extend(pitch.iter().copied());
        visible.extend(rim);
    }
    if outline == Outline::Line {
        // The face at θ = 0 (the cam frame is the design frame there), as wide as needed.
        let start = analysis.points.first();
        if let (Some(p), Some(face)) = (start, &analysis.face) {
            let placed = design::place(g, design.senses, &p.lift[0], &p.lift[1]);
            let along = [-placed.normal[1], placed.normal[0]];
            let offset = super::analysis::face_offset(design, p);
            let ends = [face.offset.min.value, face.offset.max.value].map(|o| {
                let d = o - offset;
                (
                    placed.contact[0] + d * along[0],
                    placed.contact[1] + d * along[1],
                )
            });
            frames.push(frame(
                "face at θ = 0".into(),
                RED,
                vec![line(ends.to_vec())],
            ));
            visible.extend(ends);
        }
    }
    if outline == Outline::Point {
        let (cx, cy) = pitch.first().copied().unwrap_or((0.0, 0.0));
        frames.push(frame(
            format!("{} at θ = 0", design.senses.shape.name()),
            RED,
            vec![line(
                circle(0.01 * g.base_radius)
                    .into_iter()
                    .map(|(x, y)| (cx + x, cy + y))
                    .collect(),
            )],
        ));
    }
    let (x0, x1) = data_range(visible.iter().map(|p| p.0));
    let (y0, y1) = data_range(visible.iter().map(|p| p.1));
    let turning = if design.senses.turning > 0.0 {
        "counterclockwise"
    } else {
        "clockwise"
    };
    let circles = match outline {
        Outline::Circle => format!(
            "base circle {:.6} m, prime circle {:.6} m",
            g.base_radius,
            g.base_radius + g.roller
        ),
        Outline::Point | Outline::Line => format!("base circle {:.6} m", g.base_radius),
    };
    column(
        format!("{name}: cam profile in the cam frame"),
        vec![(
            PROFILE_ROW,
            Panel::Mechanism(MechanismPanel {
                title: format!("{circles}; the cam turns {turning} (shown at θ = 0)"),
                x_label: "x [m]".into(),
                y_label: "y [m]".into(),
                bounds: ((x0, x1), (y0, y1)),
                cam: None,
                frames,
                legend: true,
            }),
        )],
    )
}

/// A barrel cam's groove developed at its pitch radius R: the pitch curve (the roller
/// centre's path), the lower flank the roller rides on and the upper one, ρ either side along
/// the developed curve's normal, with the roller where it sits at θ = 0.
fn groove(name: &str, design: &CamDesign, analysis: &Analysis, radius: f64) -> Figure {
    let rho = design.geometry.roller;
    let at = |f: &dyn Fn(&design::DesignPoint) -> [f64; 2]| -> Vec<(f64, f64)> {
        analysis.points.iter().map(f).map(|[x, y]| (x, y)).collect()
    };
    let pitch = at(&|p| p.pitch);
    let lower = at(&|p| p.contact);
    // The upper flank: the pitch point moved ρ the other way (the lower flank's offset
    // mirrored through the pitch curve).
    let upper = at(&|p| {
        [
            2.0 * p.pitch[0] - p.contact[0],
            2.0 * p.pitch[1] - p.contact[1],
        ]
    });
    let (cx, cy) = pitch.first().copied().unwrap_or((0.0, 0.0));
    let rim: Vec<(f64, f64)> = circle(rho)
        .into_iter()
        .map(|(x, y)| (cx + x, cy + y))
        .collect();
    let visible: Vec<(f64, f64)> = lower.iter().chain(&upper).chain(&rim).copied().collect();
    let (x0, x1) = data_range(visible.iter().map(|p| p.0));
    let (y0, y1) = data_range(visible.iter().map(|p| p.1));
    let frames = vec![
        frame("lower flank".into(), GREY, vec![line(lower)]),
        frame("upper flank".into(), GREY, vec![line(upper)]),
        frame("pitch curve".into(), BLUE, vec![line(pitch)]),
        frame(
            format!("{} at θ = 0", design.senses.shape.label()),
            RED,
            vec![line(rim)],
        ),
    ];
    column(
        format!("{name}: barrel cam's groove developed at the pitch radius {radius:.6} m"),
        vec![(
            PROFILE_ROW,
            Panel::Mechanism(MechanismPanel {
                title: format!(
                    "one turn of the cam, arc length −σRθ; the roller's radius {rho:.6} m"
                ),
                x_label: "arc length round the pitch cylinder [m]".into(),
                y_label: "height along the cam's axis [m]".into(),
                bounds: ((x0, x1), (y0, y1)),
                cam: None,
                frames,
                legend: true,
            }),
        )],
    )
}

/// `(cam angle, value)` split into one curve per turn, the angle in degrees within its turn
/// (0 to 360: an output at the end of a turn closes that turn's curve).
fn per_turn(points: impl Iterator<Item = (f64, f64)>) -> Vec<Vec<(f64, f64)>> {
    let mut curves: Vec<Vec<(f64, f64)>> = Vec::new();
    for (theta, value) in points {
        let turns = theta / TAU;
        // The turn an angle belongs to, from 0; the end of turn k (an exact multiple, to
        // rounding) still belongs to it, angle 0 to the first.
        let turn = ((turns - 1e-9).ceil() - 1.0).max(0.0) as usize;
        let within = ((turns - turn as f64) * 360.0).clamp(0.0, 360.0);
        while curves.len() <= turn {
            curves.push(Vec::new());
        }
        curves[turn].push((within, value));
    }
    curves.retain(|c| !c.is_empty());
    curves
}

/// What the force figure shows.
pub struct ForceView<'a> {
    /// The model's name.
    pub name: &'a str,
    /// The design's analysis (its angles).
    pub analysis: &'a Analysis,
    /// The bilateral turn at ω.
    pub nominal: &'a Turn,
    /// The prediction, when the mechanism has no degree of freedom.
    pub prediction: Option<&'a Prediction>,
    /// The one-sided run, when it ran.
    pub one_sided: Option<&'a OneSided>,
    /// The one-sided run's (t, cam angle, force) samples.
    pub one_sided_force: Vec<(f64, f64, f64)>,
}

/// The contact force against the cam angle, and the least force against the speed.
pub fn force(view: &ForceView) -> Figure {
    let w = view.analysis.speed;
    let design_force = against_angle(view.analysis, |k| {
        view.nominal.force.get(k).copied().unwrap_or(f64::NAN)
    });
    let mut all: Vec<f64> = design_force.iter().map(|p| p.1).collect();
    all.extend(view.one_sided_force.iter().map(|p| p.2));
    let y_range = padded(data_range(all.into_iter().chain([0.0])));
    let mut series = vec![Series {
        label: Some("bilateral: the follower held on the cam (design)".into()),
        color: BLUE,
        points: design_force,
    }];
    let curves = per_turn(view.one_sided_force.iter().map(|p| (p.1, p.2)));
    let last = curves.len().saturating_sub(1).max(1) as f64;
    let count = curves.len();
    for (j, points) in curves.into_iter().enumerate() {
        let label = match (j, count) {
            (0, 1) => Some("one-sided run".to_string()),
            (0, _) => Some("one-sided run, first turn".to_string()),
            (j, n) if j + 1 == n => Some(format!("one-sided run, turn {n}")),
            _ => None,
        };
        series.push(Series {
            label,
            color: one_sided_color(j as f64 / last),
            points,
        });
    }
    let mut markers = Vec::new();
    if let Some(run) = view.one_sided {
        // The first lift-off at each place (later turns repeat the first, usually).
        let mut seen: Vec<f64> = Vec::new();
        for flight in &run.flights {
            let at = flight.theta.to_degrees().rem_euclid(360.0);
            if seen.iter().any(|s| (s - at).abs() < 1.0) || seen.len() == 4 {
                continue;
            }
            seen.push(at);
            markers.push((
                at,
                format!(
                    "lift-off at {}° (turn {})",
                    degrees(flight.theta, 1),
                    turn_of(flight.theta)
                ),
            ));
        }
    }
    let jump = match view.prediction.map(|p| p.jump) {
        Some(JumpSpeed::At { speed, theta }) => format!(
            "; predicted jump speed {} rad/s (at {}°)",
            number(speed),
            degrees(theta, 1)
        ),
        Some(JumpSpeed::AtRest { .. }) => "; not held even at rest".into(),
        Some(JumpSpeed::Never) => "; no jump speed".into(),
        None => String::new(),
    };
    let mut rows = vec![(
        LINE_ROW + 100,
        Panel::Lines(LinePanel {
            title: format!("contact force at ω = {w} rad/s{jump}"),
            x_label: ANGLE_AXIS.into(),
            y_label: "normal force [N]".into(),
            x_range: (0.0, 360.0),
            y_range,
            series,
            zero_line: true,
            markers,
        }),
    )];
    if let Some(prediction) = view.prediction {
        rows.push((LINE_ROW, least_force_panel(prediction, w)));
    }
    column(
        format!("{}: contact force, design against dynamics", view.name),
        rows,
    )
}

/// One-sided turns from orange to dark red.
fn one_sided_color(f: f64) -> RGBColor {
    let mix = |a: u8, b: u8| {
        (f64::from(a) + f.clamp(0.0, 1.0) * (f64::from(b) - f64::from(a))).round() as u8
    };
    RGBColor(mix(255, 140), mix(127, 20), mix(14, 20))
}

/// The least force over a turn against the speed, N = A + Bω + Cω², with ω and the jump
/// speed marked.
fn least_force_panel(prediction: &Prediction, w: f64) -> Panel {
    let top = match prediction.jump {
        JumpSpeed::At { speed, .. } => (1.25 * speed).max(2.0 * w),
        _ => 2.0 * w,
    };
    let points: Vec<(f64, f64)> = (0..=400)
        .map(|k| top * f64::from(k) / 400.0)
        .map(|s| (s, prediction.least_force(s).1))
        .collect();
    let y_range = padded(data_range(points.iter().map(|p| p.1).chain([0.0])));
    let vertical = |x: f64| vec![(x, y_range.0), (x, y_range.1)];
    let mut series = vec![
        Series {
            label: None,
            color: BLUE,
            points,
        },
        Series {
            label: Some(format!("ω = {w} rad/s")),
            color: GREEN,
            points: vertical(w),
        },
    ];
    if let JumpSpeed::At { speed, .. } = prediction.jump {
        series.push(Series {
            label: Some(format!("jump speed {} rad/s", number(speed))),
            color: RED,
            points: vertical(speed),
        });
    }
    Panel::Lines(LinePanel {
        title: "least contact force over a turn against the cam speed (A + Bω + Cω²)".into(),
        x_label: "cam speed [rad/s]".into(),
        y_label: "least normal force [N]".into(),
        x_range: (0.0, top),
        y_range,
        series,
        zero_line: true,
        markers: Vec::new(),
    })
}
