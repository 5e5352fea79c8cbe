//! The figures of a run, after the paper's figures 3–6.
//!
//! - `histories`: time histories of the coordinates (by default all of them, from the tip
//!   to the base; the paper's figures 3 and 5 show q4 and q3) and of each contact point's
//!   position along its cam;
//! - `snapshots`: the mechanism drawn over the cam profile at evenly spaced times (the
//!   paper's figures 4 and 6);
//! - `contact`: each contact's normal force (with the first lift-off time, if any) and
//!   constraint residual against time;
//! - `comparison`: two runs side by side (the concave and the convex cam), on common
//!   scales so that the difference between them shows at a glance.

use super::kinematics::Geometry;
use super::plots::{Figure, Frame, LinePanel, MechanismPanel, Panel, Row, Series, time_color};
use super::summary::{lift_off, unit};
use camchain_runtime::{CoordinateKind, ModelInfo, Sample};
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
    /// The samples.
    pub samples: &'a [Sample],
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
fn padded((lo, hi): (f64, f64)) -> (f64, f64) {
    if !(lo.is_finite() && hi.is_finite()) {
        return (-1.0, 1.0);
    }
    let span = hi - lo;
    let pad = if span > 1e-9 * lo.abs().max(hi.abs()) && span > 0.0 {
        0.06 * span
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
    let what = match c.kind {
        CoordinateKind::Revolute => "rotation",
        CoordinateKind::Prismatic => "displacement in the guide",
    };
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
    Figure {
        title,
        width: COLUMN_WIDTH,
        rows: panels
            .into_iter()
            .map(|(height, panel)| Row {
                height,
                panels: vec![panel],
            })
            .collect(),
    }
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
        let markers = lift_off(run.samples, k)
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
                title: format!("{name}: constraint residual h = f2(q) − f3(f1(q))"),
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

fn frame(geometry: &Geometry, sample: &Sample, color: RGBColor) -> Frame {
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
    Frame {
        label: format!("t = {} s", round_time(sample.t)),
        color,
        links,
        joints: origins,
        bases,
        tips: sample
            .contacts
            .iter()
            .map(|c| project(&c.position))
            .collect(),
        coms,
    }
}

/// A time for a legend: at most 3 decimals, no trailing zeros.
fn round_time(t: f64) -> String {
    let text = format!("{t:.3}");
    text.trim_end_matches('0').trim_end_matches('.').to_string()
}

fn frames(run: &RunView, geometry: &Geometry) -> Vec<Frame> {
    let indices = snapshot_indices(run.samples.len(), SNAPSHOTS);
    let last = indices.len().saturating_sub(1).max(1) as f64;
    indices
        .iter()
        .enumerate()
        .map(|(j, &i)| frame(geometry, &run.samples[i], time_color(j as f64 / last)))
        .collect()
}

fn frame_bounds(frames: &[Frame]) -> ((f64, f64), (f64, f64)) {
    let points = || {
        frames.iter().flat_map(|f| {
            f.joints
                .iter()
                .chain(&f.tips)
                .chain(f.links.iter().flatten())
        })
    };
    let xs = data_range(points().map(|p| p.0));
    let ys = data_range(points().map(|p| p.1));
    let (x, y) = (padded(xs), padded(ys));
    (x, y)
}

fn mechanism_panel(run: &RunView, geometry: &Geometry, prefix: &str) -> MechanismPanel {
    let frames = frames(run, geometry);
    let ground = geometry.plane.is_ground();
    let (x_label, y_label) = if ground {
        ("x [m]", "y [m]")
    } else {
        ("x in the cam plane [m]", "y in the cam plane [m]")
    };
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
    }
}

/// The mechanism over its cam at evenly spaced times; a note instead when the geometry is
/// not available.
pub fn snapshots(run: &RunView) -> Result<Figure, String> {
    let geometry = usable_geometry(run)?;
    let panel = Panel::Mechanism(mechanism_panel(run, geometry, ""));
    Ok(single_column(
        format!("{}: snapshots", run.label),
        vec![(SNAPSHOT_ROW, panel)],
    ))
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
    fn ranges_stay_drawable() {
        assert_eq!(padded((0.0, 1.0)), (-0.06, 1.06));
        let (lo, hi) = padded((0.0, 0.0));
        assert!(lo < 0.0 && hi > 0.0);
        assert_eq!(padded((f64::INFINITY, f64::NEG_INFINITY)), (-1.0, 1.0));
        assert_eq!(round_time(1.25), "1.25");
        assert_eq!(round_time(10.0), "10");
    }
}
