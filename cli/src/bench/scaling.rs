//! The figure of the scaling study: operations, build time and evaluation time against the
//! number of bodies, from the CSV that `codegen/examples/scaling.rs` writes.

use crate::CliError;
use crate::plots::{Figure, LinePanel, Panel, Row, Series};
use plotters::style::RGBColor;
use std::path::Path;

/// Columns of `scaling.csv` plotted, with their legend and colour.
const OPS: [(&str, &str, RGBColor); 4] = [
    ("mass_matrix", "M", RGBColor(31, 119, 180)),
    ("inertial_forces", "F", RGBColor(255, 127, 14)),
    ("applied_forces", "Q", RGBColor(44, 160, 44)),
    ("constraint_terms", "J, c", RGBColor(214, 39, 40)),
];
const TIMES: [(&str, &str, RGBColor); 3] = [
    ("build_s", "build [s]", RGBColor(0, 0, 0)),
    ("equations_ns", "equations [µs]", RGBColor(31, 119, 180)),
    (
        "constraint_terms_ns",
        "constraint_terms [µs]",
        RGBColor(214, 39, 40),
    ),
];

/// Reads `csv` and writes `scaling.png`/`.svg` into `figures`.
pub fn run(csv: &Path, figures: &Path) -> Result<(), CliError> {
    let failed = |e: String| CliError::Failed(format!("{}: {e}", csv.display()));
    let text = std::fs::read_to_string(csv).map_err(|e| failed(e.to_string()))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let rows: Vec<Vec<f64>> = lines
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            l.split(',')
                .map(|v| v.trim().parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    let column = |name: &str, scale: f64| -> Result<Vec<(f64, f64)>, CliError> {
        let k = header
            .iter()
            .position(|h| *h == name)
            .ok_or_else(|| failed(format!("no column `{name}`")))?;
        Ok(rows
            .iter()
            .filter(|r| r.len() > k && r[0] > 0.0 && r[k] > 0.0)
            .map(|r| (r[0].log2(), (r[k] * scale).log10()))
            .collect())
    };
    let mut ops = Vec::new();
    for (name, label, color) in OPS {
        ops.push(Series {
            label: Some(label.to_string()),
            color,
            points: column(name, 1.0)?,
        });
    }
    let mut times = Vec::new();
    for (name, label, color) in TIMES {
        let scale = if name.ends_with("_ns") { 1e-3 } else { 1.0 };
        times.push(Series {
            label: Some(label.to_string()),
            color,
            points: column(name, scale)?,
        });
    }
    let guides = |points: &[(f64, f64)]| -> Vec<Series> {
        let Some(&(x0, y0)) = points.first() else {
            return Vec::new();
        };
        let last = points.last().map_or(x0, |p| p.0);
        let line = |slope: f64, label: &str, color| Series {
            label: Some(label.to_string()),
            color,
            points: vec![(x0, y0), (last, y0 + slope * (last - x0) * 2f64.log10())],
        };
        vec![
            line(1.0, "∝ N", RGBColor(170, 170, 170)),
            line(2.0, "∝ N²", RGBColor(110, 110, 110)),
        ]
    };
    let f_points = ops[1].points.clone();
    ops.extend(guides(&f_points));
    let panel = |title: &str, y_label: &str, series: Vec<Series>| {
        let ys: Vec<f64> = series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.1))
            .collect();
        let lo = ys.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = ys.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        Panel::Lines(LinePanel {
            title: title.to_string(),
            x_label: "log2 N (bodies)".to_string(),
            y_label: y_label.to_string(),
            x_range: (0.8, 6.2),
            y_range: (lo.floor() - 0.2, hi.ceil() + 0.2),
            series,
            zero_line: false,
            markers: Vec::new(),
        })
    };
    let figure = Figure {
        title: "Scaling of the generated code with the number of bodies".to_string(),
        width: 1400,
        rows: vec![Row {
            height: 460,
            panels: vec![
                panel("operations per term", "log10 operations", ops),
                panel("build and evaluation time", "log10 time", times),
            ],
        }],
    };
    std::fs::create_dir_all(figures).map_err(|e| failed(e.to_string()))?;
    figure
        .save(figures, "scaling")
        .map(|_| ())
        .map_err(|e| failed(e.to_string()))
}
