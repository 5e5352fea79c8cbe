//! The report's figures: log-scale line panels of quantities against time.

use crate::plots::{LinePanel, Panel, Series};
use plotters::style::RGBColor;

/// Colours of the curves of one figure, in order.
pub(super) const PALETTE: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
];

/// Floor of the log-scale plots: values below it (exact zeros) are drawn at it.
pub(super) const LOG_FLOOR: f64 = 1e-18;

/// (t, log10 max(|value|, floor)) points.
pub(super) fn log_points(points: impl Iterator<Item = (f64, f64)>) -> Vec<(f64, f64)> {
    points
        .filter(|(_, v)| v.is_finite())
        .map(|(t, v)| (t, v.abs().max(LOG_FLOOR).log10()))
        .collect()
}

pub(super) fn range(series: &[Series], floor: f64) -> ((f64, f64), (f64, f64)) {
    let points = series.iter().flat_map(|s| s.points.iter());
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for &(x, y) in points {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if !(x0.is_finite() && x1 > x0) {
        (x0, x1) = (0.0, 1.0);
    }
    if !(y0.is_finite() && y1.is_finite()) {
        (y0, y1) = (floor, floor + 1.0);
    }
    let pad = 0.05 * (y1 - y0).max(1.0);
    ((x0, x1), (y0 - pad, y1 + pad))
}

pub(super) fn line_panel(title: &str, y_label: &str, series: Vec<Series>) -> Panel {
    let (x_range, y_range) = range(&series, LOG_FLOOR.log10());
    Panel::Lines(LinePanel {
        title: title.to_string(),
        x_label: "t [s]".into(),
        y_label: y_label.to_string(),
        x_range,
        y_range,
        series,
        zero_line: false,
        markers: Vec::new(),
    })
}

pub(super) fn series(label: &str, index: usize, points: Vec<(f64, f64)>) -> Series {
    Series {
        label: Some(label.to_string()),
        color: PALETTE[index % PALETTE.len()],
        points,
    }
}
