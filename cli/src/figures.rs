//! The figures of a run, after the paper's figures 3–6.
//!
//! - `histories`: time histories of the coordinates (by default all of them, from the tip
//!   to the base; the paper's figures 3 and 5 show q4 and q3) and of each contact point's
//!   position along its cam;
//! - `snapshots`: the mechanism drawn over the cam profile at evenly spaced times (the
//!   paper's figures 4 and 6);
//! - `contact`: each contact's normal force (with the first lift-off time, if any) and
//!   constraint residual against time;
//! - `follower`: for a cam turned by a revolute joint, the follower's displacement, velocity
//!   and acceleration and the pressure angle against the cam's angle, one curve per
//!   revolution (the designer's s, v, a diagram as the dynamics produced it);
//! - `comparison`: two runs side by side (the concave and the convex cam), on common
//!   scales so that the difference between them shows at a glance.

mod surface;

pub use surface::surface;

use super::kinematics::Geometry;
use super::plots::{Figure, Frame, LinePanel, MechanismPanel, Panel, Row, Series, time_color};
use super::summary::{LiftOff, unit};
use camchain_runtime::{JointKind, ModelInfo, Sample};
use plotters::style::RGBColor;

/// Width of a one-column figure, and of each column of a comparison (pixels).
const COLUMN_WIDTH: u32 = 1000;
/// Height of a row of line plots (pixels).
const LINE_ROW: u32 = 300;
/// Height of a row of snapshots (pixels).
const SNAPSHOT_ROW: u32 = 640;
/// Number of snapshots of the mechanism.
const SNAPSHOTS: usize = 9;
/// Colours of the first and second run of a comparison.
const FIRST: RGBColor = RGBColor(31, 119, 180);
const SECOND: RGBColor = RGBColor(214, 39, 40);
const TIME_AXIS: &str = "t [s]";

/// A run as the figures see it.
pub struct RunView<'a> {
    /// The run's name.
    pub label: &'a str,
    /// The model.
    pub info: &'a ModelInfo,
    /// The samples drawn, in time order: all of a short run's, a long run's decimated
    /// (`simulate::decimated`: evenly spaced, the first, the last and the markers' kept
    /// exactly), thinned to what the figures read (t, q, q̇, q̈, normal forces, the
    /// contacts' h, contact geometry).
    pub samples: &'a [Sample],
    /// Where each contact's normal force first turns negative, from every sample of the run
    /// (the contact figure's markers).
    pub lift_offs: &'a [Option<LiftOff>],
    /// The model's geometry, for snapshots.
    pub geometry: Option<&'a Geometry>,
}

fn data_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        })
}

fn union(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    (a.0.min(b.0), a.1.max(b.1))
}

/// A range with a margin of 6 % each side; a flat or empty one is widened to stay drawable.
fn padded(range: (f64, f64)) -> (f64, f64) {
    padded_by(range, 0.06)
}

/// A range with a margin of `fraction` of its span each side; a flat or empty one is widened
/// to stay drawable.
pub(crate) fn padded_by((lo, hi): (f64, f64), fraction: f64) -> (f64, f64) {
    if !(lo.is_finite() && hi.is_finite()) {
        return (-1.0, 1.0);
    }
    let span = hi - lo;
    let pad = if span > 1e-9 * lo.abs().max(hi.abs()) && span > 0.0 {
        fraction * span
    } else {
        (0.01 * lo.abs().max(hi.abs())).max(1e-15)
    };
    (lo - pad, hi + pad)
}

fn time_range(samples: &[Sample]) -> (f64, f64) {
    match (samples.first(), samples.last()) {
        (Some(a), Some(b)) if b.t > a.t => (a.t, b.t),
        (Some(a), _) => (a.t, a.t + 1.0),
        _ => (0.0, 1.0),
    }
}

/// "q4: rotation between body3 and body4".
fn coordinate_title(run: &RunView, i: usize) -> String {
    let c = &run.info.coordinates[i];
    let what = c.kind.spec().motion;
    let between = run
        .geometry
        .filter(|g| g.n() == run.info.n())
        .map(|g| {
            let parent = g
                .parent(i)
                .map_or("the ground", |p| g.body_names[p].as_str());
            format!(" between {parent} and {}", g.body_names[i])
        })
        .unwrap_or_default();
    let driven = if c.driven { " (driven)" } else { "" };
    format!("{}: {what}{between}{driven}", c.name)
}

fn coordinate_panel(
    run: &RunView,
    i: usize,
    y_range: Option<(f64, f64)>,
    color: RGBColor,
    prefix: &str,
) -> LinePanel {
    let c = &run.info.coordinates[i];
    let points: Vec<(f64, f64)> = run.samples.iter().map(|s| (s.t, s.q[i])).collect();
    LinePanel {
        title: format!("{prefix}{}", coordinate_title(run, i)),
        x_label: TIME_AXIS.into(),
        y_label: format!("{} [{}]", c.name, unit(c.kind)),
        x_range: time_range(run.samples),
        y_range: y_range.unwrap_or_else(|| padded(data_range(points.iter().map(|p| p.1)))),
        series: vec![Series {
            label: None,
            color,
            points,
        }],
        zero_line: false,
        markers: Vec::new(),
    }
}

fn position_axis(run: &RunView, k: usize) -> String {
    let name = &run.info.contacts[k].name;
    let ground = run.geometry.is_some_and(|g| g.plane.is_ground());
    if ground && k == 0 {
        format!("{name}_x [m]")
    } else {
        format!("{name}: x in its cam's plane [m]")
    }
}

fn position_panel(
    run: &RunView,
    k: usize,
    y_range: Option<(f64, f64)>,
    color: RGBColor,
    prefix: &str,
) -> LinePanel {
    let points: Vec<(f64, f64)> = run.samples.iter().map(|s| (s.t, s.contacts[k].x)).collect();
    LinePanel {
        title: format!(
            "{prefix}{}: position of the contact point along the cam",
            run.info.contacts[k].name
        ),
        x_label: TIME_AXIS.into(),
        y_label: position_axis(run, k),
        x_range: time_range(run.samples),
        y_range: y_range.unwrap_or_else(|| padded(data_range(points.iter().map(|p| p.1)))),
        series: vec![Series {
            label: None,
            color,
            points,
        }],
        zero_line: false,
        markers: Vec::new(),
    }
}

fn single_column(title: String, panels: Vec<(u32, Panel)>) -> Figure {
    Figure::column(title, COLUMN_WIDTH, panels)
}

/// Time histories of the coordinates `coords` (indices) and of every contact's position.
pub fn histories(run: &RunView, coords: &[usize]) -> Figure {
    let mut panels: Vec<(u32, Panel)> = coords
        .iter()
        .map(|&i| {
            (
                LINE_ROW,
                Panel::Lines(coordinate_panel(run, i, None, FIRST, "")),
            )
        })
        .collect();
    panels.extend((0..run.info.n_contacts()).map(|k| {
        (
            LINE_ROW,
            Panel::Lines(position_panel(run, k, None, FIRST, "")),
        )
    }));
    single_column(format!("{}: time histories", run.label), panels)
}

/// Each contact's normal force and constraint residual against time (`None` without
/// contacts).
pub fn contact(run: &RunView) -> Option<Figure> {
    if run.info.n_contacts() == 0 {
        return None;
    }
    let mut panels = Vec::new();
    for (k, name) in run.info.contacts.iter().map(|c| &c.name).enumerate() {
        let force: Vec<(f64, f64)> = run
            .samples
            .iter()
            .map(|s| (s.t, s.normal_force[k]))
            .collect();
        let markers = run
            .lift_offs
            .get(k)
            .copied()
            .flatten()
            .map(|l| vec![(l.t, format!("lift-off at t ≈ {:.3} s", l.t))])
            .unwrap_or_default();
        let y_range = padded(union(data_range(force.iter().map(|p| p.1)), (0.0, 0.0)));
        panels.push((
            LINE_ROW,
            Panel::Lines(LinePanel {
                title: format!("{name}: normal force (positive: the cam pushes on the follower)"),
                x_label: TIME_AXIS.into(),
                y_label: format!("{name}_normal_force [N]"),
                x_range: time_range(run.samples),
                y_range,
                series: vec![Series {
                    label: None,
                    color: FIRST,
                    points: force,
                }],
                zero_line: true,
                markers,
            }),
        ));
        let residual: Vec<(f64, f64)> = run.samples.iter().map(|s| (s.t, s.h[k])).collect();
        panels.push((
            LINE_ROW,
            Panel::Lines(LinePanel {
                title: format!(
                    "{name}: constraint residual h (the gap where the follower is off the cam)"
                ),
                x_label: TIME_AXIS.into(),
                y_label: format!("{name}_h [m]"),
                x_range: time_range(run.samples),
                y_range: padded(data_range(residual.iter().map(|p| p.1))),
                series: vec![Series {
                    label: None,
                    color: FIRST,
                    points: residual,
                }],
                zero_line: true,
                markers: Vec::new(),
            }),
        ));
    }
    Some(single_column(
        format!("{}: contact forces and constraint residuals", run.label),
        panels,
    ))
}

/// How a figure reads one quantity of coordinate `i` from a sample.
type Reading = fn(&Sample, usize) -> f64;

/// Units of a coordinate's displacement, velocity and acceleration.
fn motion_units(kind: JointKind) -> [&'static str; 3] {
    kind.spec().units
}

/// `(cam angle in degrees within one turn, value)` split into one curve per revolution: a
/// new curve starts where the wrapped angle jumps by more than half a turn.
fn per_revolution(points: impl Iterator<Item = (f64, f64)>) -> Vec<Vec<(f64, f64)>> {
    let mut curves: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut previous: Option<f64> = None;
    for (angle, value) in points {
        let wrapped = angle.to_degrees().rem_euclid(360.0);
        if previous.is_none_or(|p| (wrapped - p).abs() > 180.0) {
            curves.push(Vec::new());
        }
        previous = Some(wrapped);
        if let Some(curve) = curves.last_mut() {
            curve.push((wrapped, value));
        }
    }
    curves
}

/// A panel of `value` against the cam angle, one curve per revolution coloured early → late.
fn against_cam_angle(
    run: &RunView,
    cam: usize,
    title: String,
    y_label: String,
    value: impl Fn(&Sample) -> f64,
) -> Panel {
    let curves = per_revolution(run.samples.iter().map(|s| (s.q[cam], value(s))));
    let last = curves.len().saturating_sub(1).max(1) as f64;
    let y_range = padded(data_range(curves.iter().flatten().map(|p| p.1)));
    let series = curves
        .into_iter()
        .enumerate()
        .map(|(j, points)| Series {
            label: None,
            color: time_color(j as f64 / last),
            points,
        })
        .collect();
    Panel::Lines(LinePanel {
        title,
        x_label: format!("{} within a turn [deg]", run.info.coordinates[cam].name),
        y_label,
        x_range: (0.0, 360.0),
        y_range,
        series,
        zero_line: true,
        markers: Vec::new(),
    })
}

/// For each contact whose cam turns on a revolute joint: the follower's displacement,
/// velocity and acceleration (its own joint's coordinate) and the pressure angle against the
/// cam's angle. `None` when no cam turns or the follower's joint is unknown.
pub fn follower(run: &RunView) -> Option<Figure> {
    let geometry = run.geometry?;
    let mut panels = Vec::new();
    for (k, contact) in run.info.contacts.iter().enumerate() {
        let (Some(cam), Some(f)) = (contact.cam_coordinate, geometry.follower_body(k)) else {
            continue;
        };
        let Some(c) = run.info.coordinates.get(f) else {
            continue;
        };
        let units = motion_units(c.kind);
        let name = &contact.name;
        let quantities: [(&str, String, Reading); 3] = [
            ("displacement", c.name.clone(), |s, i| s.q[i]),
            ("velocity", format!("{}_dot", c.name), |s, i| s.qd[i]),
            ("acceleration", format!("{}_ddot", c.name), |s, i| s.qdd[i]),
        ];
        for ((what, column, value), unit) in quantities.into_iter().zip(units) {
            panels.push((
                LINE_ROW,
                against_cam_angle(
                    run,
                    cam,
                    format!("{name}: follower {what} ({})", c.name),
                    format!("{column} [{unit}]"),
                    move |s| value(s, f),
                ),
            ));
        }
        panels.push((
            LINE_ROW,
            against_cam_angle(
                run,
                cam,
                format!("{name}: pressure angle (contact normal against the follower's motion)"),
                format!("{name}_pressure_angle [deg]"),
                move |s| s.contacts[k].pressure_angle().to_degrees(),
            ),
        ));
    }
    if panels.is_empty() {
        return None;
    }
    Some(single_column(
        format!(
            "{}: follower against cam angle (a curve per turn, dark → light)",
            run.label
        ),
        panels,
    ))
}

/// Indices of `count` evenly spaced samples (first and last included).
fn snapshot_indices(len: usize, count: usize) -> Vec<usize> {
    match len {
        0 => Vec::new(),
        1 => vec![0],
        _ => {
            let count = count.clamp(2, len);
            let mut indices: Vec<usize> = (0..count)
                .map(|j| ((j * (len - 1)) as f64 / (count - 1) as f64).round() as usize)
                .collect();
            indices.dedup();
            indices
        }
    }
}

/// The range of contact `k`'s cam-frame x over the run, widened by half its width (at
/// least 2 cm) each side: where an explicit profile on a moving body is drawn.
fn cam_x_range(samples: &[Sample], k: usize) -> (f64, f64) {
    let (lo, hi) = data_range(
        samples
            .iter()
            .filter_map(|s| s.contacts.get(k))
            .map(|c| c.x),
    );
    if !(lo.is_finite() && hi.is_finite()) {
        return (-0.1, 0.1);
    }
    let pad = (0.5 * (hi - lo)).max(0.02);
    (lo - pad, hi + pad)
}

fn frame(geometry: &Geometry, sample: &Sample, color: RGBColor, x_ranges: &[(f64, f64)]) -> Frame {
    let pose = geometry.pose(&sample.q);
    let project = |p: &[f64; 3]| geometry.plane.project(p);
    let origins: Vec<(f64, f64)> = pose.origins.iter().map(project).collect();
    let mut links = Vec::new();
    let mut bases = Vec::new();
    for (i, origin) in origins.iter().enumerate() {
        match geometry.parent(i) {
            Some(p) => links.push([origins[p], *origin]),
            None => bases.push(*origin),
        }
    }
    for (k, marker) in pose.markers.iter().enumerate() {
        if let Some(b) = geometry.marker_body(k) {
            links.push([origins[b], project(marker)]);
        }
    }
    let mut coms = Vec::new();
    for (i, com) in pose.coms.iter().enumerate() {
        if geometry.is_bare_leaf(i) {
            links.push([origins[i], project(com)]);
            coms.push(project(com));
        }
    }
    // The loops' cut points are pins too.
    let mut joints = origins;
    joints.extend(
        pose.markers[geometry.loop_points_from..]
            .iter()
            .map(project),
    );
    Frame {
        label: format!("t = {} s", round_time(sample.t)),
        color,
        links,
        joints,
        bases,
        tips: sample
            .contacts
            .iter()
            .map(|c| project(&c.position))
            .collect(),
        coms,
        cams: x_ranges
            .iter()
            .enumerate()
            .filter_map(|(k, range)| geometry.cam_picture(&sample.q, k, *range))
            .collect(),
    }
}

/// `x` with one decimal, and no minus sign on a value that rounds to zero.
fn one_decimal(x: f64) -> String {
    let text = format!("{x:.1}");
    if text == "-0.0" { "0.0".into() } else { text }
}

/// A time for a legend: at most 3 decimals, no trailing zeros.
fn round_time(t: f64) -> String {
    let text = format!("{t:.3}");
    text.trim_end_matches('0').trim_end_matches('.').to_string()
}

fn frames(run: &RunView, geometry: &Geometry) -> Vec<Frame> {
    let indices = snapshot_indices(run.samples.len(), SNAPSHOTS);
    let last = indices.len().saturating_sub(1).max(1) as f64;
    let x_ranges: Vec<(f64, f64)> = (0..run.info.n_contacts())
        .map(|k| cam_x_range(run.samples, k))
        .collect();
    indices
        .iter()
        .enumerate()
        .map(|(j, &i)| {
            let color = time_color(j as f64 / last);
            frame(geometry, &run.samples[i], color, &x_ranges)
        })
        .collect()
}

fn frame_bounds(frames: &[Frame]) -> ((f64, f64), (f64, f64)) {
    let points = || {
        frames.iter().flat_map(|f| {
            f.joints
                .iter()
                .chain(&f.tips)
                .chain(f.links.iter().flatten())
                .chain(f.cams.iter().flat_map(|c| {
                    c.outline
                        .iter()
                        .chain(&c.outer_flank)
                        .chain(&c.roller)
                        .chain(&c.face)
                        .chain(&c.base_circle)
                }))
        })
    };
    let xs = data_range(points().map(|p| p.0));
    let ys = data_range(points().map(|p| p.1));
    let (x, y) = (padded(xs), padded(ys));
    (x, y)
}

fn mechanism_panel(run: &RunView, geometry: &Geometry, prefix: &str) -> MechanismPanel {
    let frames = frames(run, geometry);
    let (x_label, y_label) = geometry.plane.axis_labels();
    let cam = geometry
        .profile
        .as_ref()
        .map_or_else(String::new, |(_, source)| {
            format!(" over the cam y = {source}")
        });
    MechanismPanel {
        title: format!("{prefix}positions of the mechanism{cam}"),
        x_label: x_label.into(),
        y_label: y_label.into(),
        bounds: frame_bounds(&frames),
        cam: geometry.profile.as_ref().map(|(expr, _)| expr.clone()),
        frames,
        legend: true,
    }
}

/// The mechanism over its cam at evenly spaced times; a note instead when the geometry is
/// not available.
pub fn snapshots(run: &RunView) -> Result<Figure, String> {
    let geometry = usable_geometry(run)?;
    let panel = mechanism_panel(run, geometry, "");
    if geometry.has_moving_cam() {
        return Ok(snapshot_grid(run, panel));
    }
    Ok(single_column(
        format!("{}: snapshots", run.label),
        vec![(SNAPSHOT_ROW, Panel::Mechanism(panel))],
    ))
}

/// True when a snapshot of `rows` draws a base circle.
fn geometry_has_base_circle(rows: &[Row]) -> bool {
    rows.iter().flat_map(|r| &r.panels).any(|p| match p {
        Panel::Mechanism(m) => m
            .frames
            .iter()
            .any(|f| f.cams.iter().any(|c| !c.base_circle.is_empty())),
        _ => false,
    })
}

/// Snapshots per row of the grid drawn for a moving cam.
const GRID_COLUMNS: usize = 3;

/// One small panel per snapshot, on common scales, each titled with its time and the cam's
/// angle: a turning cam drawn nine times over itself would hide the mechanism.
fn snapshot_grid(run: &RunView, panel: MechanismPanel) -> Figure {
    let angle = run
        .info
        .contacts
        .first()
        .and_then(|c| c.cam_coordinate)
        .map(|i| (i, &run.info.coordinates[i].name));
    let indices = snapshot_indices(run.samples.len(), SNAPSHOTS);
    let mut panels: Vec<Panel> = panel
        .frames
        .into_iter()
        .zip(indices)
        .map(|(frame, i)| {
            let sample = &run.samples[i];
            let title = match angle {
                Some((c, name)) => format!(
                    "t = {} s, {name} = {}°",
                    round_time(sample.t),
                    one_decimal(sample.q[c].to_degrees())
                ),
                None => format!("t = {} s", round_time(sample.t)),
            };
            Panel::Mechanism(MechanismPanel {
                title,
                x_label: panel.x_label.clone(),
                y_label: panel.y_label.clone(),
                bounds: panel.bounds,
                cam: panel.cam.clone(),
                frames: vec![frame],
                legend: false,
            })
        })
        .collect();
    let mut rows = Vec::new();
    while !panels.is_empty() {
        let rest = panels.split_off(GRID_COLUMNS.min(panels.len()));
        rows.push(Row {
            height: SNAPSHOT_ROW / 2 + 60,
            panels: std::mem::replace(&mut panels, rest),
        });
    }
    let base_circle = if geometry_has_base_circle(&rows) {
        "base circle thin, "
    } else {
        ""
    };
    Figure {
        title: format!(
            "{}: snapshots (cam material grey, {base_circle}follower in colour)",
            run.label
        ),
        width: COLUMN_WIDTH + 200,
        rows,
    }
}

fn usable_geometry<'a>(run: &RunView<'a>) -> Result<&'a Geometry, String> {
    match run.geometry {
        Some(g) if g.n() == run.info.n() => Ok(g),
        Some(_) => Err("the model file does not match the built-in model".into()),
        None => Err("no model geometry".into()),
    }
}

/// Two runs side by side: the selected coordinates (by name, those both models have), the
/// contact positions and the snapshots, on common scales.
pub fn comparison(a: &RunView, b: &RunView, coords: &[String]) -> Figure {
    let (prefix_a, prefix_b) = (format!("{}: ", a.label), format!("{}: ", b.label));
    let mut rows = Vec::new();
    for name in coords {
        let (Some(i), Some(j)) = (a.info.coordinate_index(name), b.info.coordinate_index(name))
        else {
            continue;
        };
        let range = padded(union(
            data_range(a.samples.iter().map(|s| s.q[i])),
            data_range(b.samples.iter().map(|s| s.q[j])),
        ));
        rows.push(Row {
            height: LINE_ROW,
            panels: vec![
                Panel::Lines(coordinate_panel(a, i, Some(range), FIRST, &prefix_a)),
                Panel::Lines(coordinate_panel(b, j, Some(range), SECOND, &prefix_b)),
            ],
        });
    }
    for (k, name) in a.info.contacts.iter().map(|c| &c.name).enumerate() {
        let Some(l) = b.info.contact_index(name) else {
            continue;
        };
        let range = padded(union(
            data_range(a.samples.iter().map(|s| s.contacts[k].x)),
            data_range(b.samples.iter().map(|s| s.contacts[l].x)),
        ));
        rows.push(Row {
            height: LINE_ROW,
            panels: vec![
                Panel::Lines(position_panel(a, k, Some(range), FIRST, &prefix_a)),
                Panel::Lines(position_panel(b, l, Some(range), SECOND, &prefix_b)),
            ],
        });
    }
    rows.push(Row {
        height: SNAPSHOT_ROW,
        panels: comparison_snapshots(a, b, &prefix_a, &prefix_b),
    });
    Figure {
        title: format!("{} and {} side by side", a.label, b.label),
        width: 2 * COLUMN_WIDTH,
        rows,
    }
}

fn comparison_snapshots(a: &RunView, b: &RunView, prefix_a: &str, prefix_b: &str) -> Vec<Panel> {
    let panels = [(a, prefix_a), (b, prefix_b)].map(|(run, prefix)| {
        usable_geometry(run)
            .map(|g| mechanism_panel(run, g, prefix))
            .map_err(|e| format!("{prefix}no snapshots: {e}"))
    });
    let common = panels
        .iter()
        .filter_map(|p| p.as_ref().ok())
        .map(|p| p.bounds)
        .reduce(|p, q| (union(p.0, q.0), union(p.1, q.1)));
    panels
        .into_iter()
        .map(|p| match p {
            Ok(mut panel) => {
                if let Some(bounds) = common {
                    panel.bounds = bounds;
                }
                Panel::Mechanism(panel)
            }
            Err(message) => Panel::Message(message),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn snapshots_are_evenly_spaced() {
        assert_eq!(snapshot_indices(1001, 9)[..3], [0, 125, 250]);
        assert_eq!(snapshot_indices(1001, 9).last(), Some(&1000));
        assert_eq!(snapshot_indices(3, 9), vec![0, 1, 2]);
        assert!(snapshot_indices(0, 9).is_empty());
    }

    #[test]
    fn a_curve_per_revolution() {
        // Three turns forwards in 0.1 rad steps: three curves, each within [0°, 360°).
        let forwards = per_revolution((0..189).map(|i| (0.1 * i as f64, i as f64)));
        assert_eq!(forwards.len(), 3);
        assert!(
            forwards
                .iter()
                .flatten()
                .all(|p| (0.0..360.0).contains(&p.0))
        );
        assert_eq!(forwards.iter().map(Vec::len).sum::<usize>(), 189);
        // Backwards: wraps the other way, a new curve at each turn too.
        let backwards = per_revolution((0..189).map(|i| (-0.1 * i as f64, 0.0)));
        assert_eq!(backwards.len(), 4);
        assert_eq!(one_decimal(-0.04), "0.0");
        assert_eq!(one_decimal(-0.06), "-0.1");
    }

    #[test]
    fn ranges_stay_drawable() {
        assert_eq!(padded((0.0, 1.0)), (-0.06, 1.06));
        let (lo, hi) = padded((0.0, 0.0));
        assert!(lo < 0.0 && hi > 0.0);
        assert_eq!(padded((f64::INFINITY, f64::NEG_INFINITY)), (-1.0, 1.0));
        assert_eq!(round_time(1.25), "1.25");
        assert_eq!(round_time(10.0), "10");
    }
}
