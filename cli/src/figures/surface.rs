//! `surface.png`: each spatial cam with the contact's path on it, in the cam's frame.
//!
//! - a surface z = f(x, y): f as colours over the box the path covers, the path over it;
//! - a barrel cam: its groove developed (unrolled) on the plane at its pitch radius R, the
//!   pitch curve (R θ, g(θ)) over a turn with the flanks a roller's radius to either side
//!   (along the developed curve's normal), and the path of the contact point on them;
//! - a surface of revolution r = g(z): its meridian in the (r, z) half-plane and the path of
//!   the contact point there.

use super::RunView;
use crate::kinematics::SurfaceShape;
use crate::plots::{Figure, HeatPanel, LinePanel, Panel, Series};
use plotters::style::RGBColor;
use std::f64::consts::TAU;

/// A drawn curve's points.
type Curve = Vec<(f64, f64)>;

/// Cells along each side of a surface's colour map.
const GRID: usize = 64;

/// Points of a drawn curve (a groove's turn, a meridian).
const CURVE_POINTS: usize = 720;

/// The gap (m) below which a sample is in contact.
const IN_CONTACT: f64 = 1e-6;

/// Height of a panel (px).
const ROW: u32 = 460;

const PITCH: RGBColor = RGBColor(40, 40, 40);
const FLANK: RGBColor = RGBColor(120, 120, 120);
const PATH: RGBColor = RGBColor(215, 48, 39);

/// The figure, when the model has a spatial cam.
pub fn surface(run: &RunView) -> Option<Figure> {
    let geometry = run.geometry?;
    let mut panels = Vec::new();
    for (k, shape) in geometry.surfaces.iter().enumerate() {
        let (Some(shape), Some(contact)) = (shape, run.info.contacts.get(k)) else {
            continue;
        };
        let name = &contact.name;
        // In contact only: a one-sided run's follower in flight has no contact point (its
        // gap h grows; held contact keeps it to round-off, far below a micrometre).
        let points: Vec<[f64; 3]> = run
            .samples
            .iter()
            .filter(|s| s.h.get(k).is_some_and(|h| h.abs() <= IN_CONTACT))
            .filter_map(|s| s.contacts.get(k))
            .map(|c| [c.x, c.y, c.z])
            .filter(|p| p.iter().all(|v| v.is_finite()))
            .collect();
        panels.push((ROW, panel(name, shape, &points)));
    }
    if panels.is_empty() {
        return None;
    }
    Some(Figure::column(
        format!("{}: the contact's path on its cam surface", run.label),
        1000,
        panels,
    ))
}

fn panel(name: &str, shape: &SurfaceShape, points: &[[f64; 3]]) -> Panel {
    match shape {
        SurfaceShape::Graph(f) => {
            let path: Vec<(f64, f64)> = points.iter().map(|p| (p[0], p[1])).collect();
            let ((x0, x1), (y0, y1)) = (
                span(path.iter().map(|p| p.0)),
                span(path.iter().map(|p| p.1)),
            );
            let (x, y) = (grid(x0, x1), grid(y0, y1));
            let z = surface_grid(f, &x, &y);
            Panel::Heat(HeatPanel {
                title: format!("{name}: the surface z = f(x, y) and the contact's path (white)"),
                x_label: "cam frame x [m]".into(),
                y_label: "cam frame y [m]".into(),
                z_label: "z = f(x, y) [m]".into(),
                x,
                y,
                z,
                empty: "the surface is not defined over the path".into(),
                path,
            })
        }
        SurfaceShape::Barrel { g, radius, roller } => {
            let (pitch, lower, upper) = developed_groove(g, *radius, *roller);
            // The contact point, on the flank the roller bears on, developed at R.
            let contact: Vec<(f64, f64)> = points
                .iter()
                .map(|p| (radius * p[1].atan2(p[0]), p[2]))
                .collect();
            let mut series = vec![
                Series {
                    label: Some("pitch curve z = g(θ)".into()),
                    color: PITCH,
                    points: pitch,
                },
                Series {
                    label: (*roller > 0.0).then(|| "flanks".to_string()),
                    color: FLANK,
                    points: lower,
                },
                Series {
                    label: None,
                    color: FLANK,
                    points: upper,
                },
            ];
            series.extend(
                split_at_wraps(&contact, radius * TAU)
                    .into_iter()
                    .map(|points| Series {
                        label: None,
                        color: PATH,
                        points,
                    }),
            );
            lines(
                format!(
                    "{name}: the groove developed at the pitch radius R = {radius} m, the \
                     contact point in red"
                ),
                "R θ (developed, θ from the cam frame's x axis) [m]",
                "z along the cam's axis [m]",
                series,
            )
        }
        SurfaceShape::Revolution(g) => {
            let path: Vec<(f64, f64)> = points.iter().map(|p| (p[0].hypot(p[1]), p[2])).collect();
            let (z0, z1) = span(path.iter().map(|p| p.1));
            let meridian: Vec<(f64, f64)> = (0..=CURVE_POINTS)
                .map(|i| z0 + (z1 - z0) * i as f64 / CURVE_POINTS as f64)
                .map(|z| (g.eval(z), z))
                .filter(|p| p.0.is_finite())
                .collect();
            lines(
                format!("{name}: the meridian r = g(z) and the contact's path (red)"),
                "r, distance from the cam's axis [m]",
                "z along the cam's axis [m]",
                vec![
                    Series {
                        label: Some("meridian".into()),
                        color: PITCH,
                        points: meridian,
                    },
                    Series {
                        label: Some("contact point".into()),
                        color: PATH,
                        points: path,
                    },
                ],
            )
        }
    }
}

/// A line panel whose ranges cover every series.
fn lines(title: String, x_label: &str, y_label: &str, series: Vec<Series>) -> Panel {
    let all = || series.iter().flat_map(|s| s.points.iter());
    Panel::Lines(LinePanel {
        title,
        x_label: x_label.into(),
        y_label: y_label.into(),
        x_range: span(all().map(|p| p.0)),
        y_range: span(all().map(|p| p.1)),
        series,
        zero_line: false,
        markers: Vec::new(),
    })
}

/// The range of `values` padded by a tenth of its width (at least 1 mm each way).
fn span(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !(lo.is_finite() && hi.is_finite()) {
        return (-1.0, 1.0);
    }
    let pad = (0.1 * (hi - lo)).max(1e-3);
    (lo - pad, hi + pad)
}

/// `GRID` evenly spaced cell centres over [a, b].
fn grid(a: f64, b: f64) -> Vec<f64> {
    (0..GRID)
        .map(|i| a + (b - a) * (i as f64 + 0.5) / GRID as f64)
        .collect()
}

/// f at every (x[i], y[j]), `None` where it is not a finite number.
pub(super) fn surface_grid(
    f: &camchain_codegen::profile::Scalar,
    x: &[f64],
    y: &[f64],
) -> Vec<Vec<Option<f64>>> {
    x.iter()
        .map(|&x| {
            y.iter()
                .map(|&y| Some(f.eval_at(&[x, y])).filter(|v| v.is_finite()))
                .collect()
        })
        .collect()
}

/// The pitch curve (R θ, g(θ)) over a turn, θ in (−π, π], and the flanks the roller's radius
/// ρ below and above it along the developed curve's unit normal (−g′/R, 1)/W.
pub(super) fn developed_groove(
    g: &camchain_codegen::profile::Scalar,
    radius: f64,
    roller: f64,
) -> (Curve, Curve, Curve) {
    let (mut pitch, mut lower, mut upper) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..=CURVE_POINTS {
        let theta = -std::f64::consts::PI + TAU * i as f64 / CURVE_POINTS as f64;
        let z = g.eval(theta);
        // g′ by a central difference: a drawing, not a result.
        let step = 1e-6;
        let slope = (g.eval(theta + step) - g.eval(theta - step)) / (2.0 * step) / radius;
        let w = (1.0 + slope * slope).sqrt();
        let (nu, nz) = (-slope / w, 1.0 / w);
        let u = radius * theta;
        pitch.push((u, z));
        lower.push((u - roller * nu, z - roller * nz));
        upper.push((u + roller * nu, z + roller * nz));
    }
    (pitch, lower, upper)
}

/// `points` cut where consecutive x jump by more than half of `period` (a path crossing the
/// developed turn's seam at θ = ±π).
fn split_at_wraps(points: &[(f64, f64)], period: f64) -> Vec<Vec<(f64, f64)>> {
    let mut pieces: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut last: Option<f64> = None;
    for &p in points {
        if last.is_none_or(|x| (p.0 - x).abs() > 0.5 * period) {
            pieces.push(Vec::new());
        }
        if let Some(piece) = pieces.last_mut() {
            piece.push(p);
        }
        last = Some(p.0);
    }
    pieces
}

#[cfg(test)]
mod tests {
    use super::*;
    use camchain_codegen::profile::parse_expression_in;

    /// The colour map holds the surface's own values at the cell centres (the model's f,
    /// evaluated independently here), and nothing where f is not a number.
    #[test]
    fn the_colour_map_is_the_surface() {
        let f =
            parse_expression_in("0.5*x*x - y + (1.0 - x).ln()", &["x", "y"], &[]).expect("parses");
        let (x, y) = (grid(-1.0, 2.0), grid(0.0, 1.0));
        let z = surface_grid(&f, &x, &y);
        for (i, &xi) in x.iter().enumerate() {
            for (j, &yj) in y.iter().enumerate() {
                let exact = 0.5 * xi * xi - yj + (1.0 - xi).ln();
                match z[i][j] {
                    Some(v) => assert_eq!(v, exact),
                    None => assert!(xi >= 1.0, "({xi}, {yj}) is defined"),
                }
            }
        }
    }

    /// The developed groove of a sine: the pitch curve is g, the flanks the roller's radius
    /// from it across the curve, on either side.
    #[test]
    fn the_flanks_are_a_rollers_radius_from_the_pitch_curve() {
        let g = parse_expression_in("0.01*theta.sin()", &["theta"], &[]).expect("parses");
        let (pitch, lower, upper) = developed_groove(&g, 0.05, 0.004);
        for ((p, l), u) in pitch.iter().zip(&lower).zip(&upper) {
            assert!((p.1 - 0.01 * (p.0 / 0.05).sin()).abs() < 1e-15);
            let d = |a: &(f64, f64)| (a.0 - p.0).hypot(a.1 - p.1);
            assert!((d(l) - 0.004).abs() < 1e-12 && (d(u) - 0.004).abs() < 1e-12);
            assert!(l.1 < p.1 && u.1 > p.1);
        }
    }

    #[test]
    fn a_path_is_cut_where_it_crosses_the_seam() {
        let period = 1.0;
        let pieces = split_at_wraps(
            &[(0.4, 0.0), (0.49, 0.0), (-0.49, 0.0), (-0.4, 0.0)],
            period,
        );
        assert_eq!(pieces.len(), 2);
    }
}
