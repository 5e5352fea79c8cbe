//! Where a line panel's legend goes: the corner of the plotting area where it covers the
//! fewest drawn points, so that it does not hide the curves it names.

use super::{LEGEND_SIZE, LinePanel};
use plotters::prelude::SeriesLabelPosition;

/// The corners tried, `(right, upper)`, in order of preference when they cover equally few
/// points.
const CORNERS: [(bool, bool); 4] = [(true, true), (false, true), (true, false), (false, false)];

/// The legend position of a corner.
fn position((right, upper): (bool, bool)) -> SeriesLabelPosition {
    match (right, upper) {
        (true, true) => SeriesLabelPosition::UpperRight,
        (false, true) => SeriesLabelPosition::UpperLeft,
        (true, false) => SeriesLabelPosition::LowerRight,
        (false, false) => SeriesLabelPosition::LowerLeft,
    }
}

/// Points sampled along each vertical marker line (a marker is drawn over the full height).
const MARKER_POINTS: usize = 32;

/// The corner for the legend of `panel` on a plotting area of `(width, height)` pixels:
/// the legend's box is estimated from its entries (one line of [`LEGEND_SIZE`] text each,
/// as wide as the longest label plus its sample line) and the corner whose box holds the
/// fewest of the panel's points is chosen.
pub fn corner(panel: &LinePanel, (width, height): (u32, u32)) -> SeriesLabelPosition {
    let labels: Vec<&str> = panel
        .markers
        .iter()
        .map(|(_, label)| label.as_str())
        .chain(panel.series.iter().filter_map(|s| s.label.as_deref()))
        .collect();
    let longest = labels.iter().map(|l| l.chars().count()).max().unwrap_or(0);
    // Glyphs average about 0.6 em; 40 px for the sample line, the gaps and the border.
    let box_width = 0.6 * f64::from(LEGEND_SIZE) * longest as f64 + 40.0;
    let box_height = (f64::from(LEGEND_SIZE) + 8.0) * labels.len() as f64 + 12.0;
    let fx = (box_width / f64::from(width.max(1))).min(1.0);
    let fy = (box_height / f64::from(height.max(1))).min(1.0);
    let (x0, x1) = panel.x_range;
    let (y0, y1) = panel.y_range;
    let (sx, sy) = (x1 - x0, y1 - y0);
    if !(sx > 0.0 && sy > 0.0) {
        return position(CORNERS[0]);
    }
    // Every point as fractions (u, v) of the plotting area, from its lower left corner.
    let series = panel.series.iter().flat_map(|s| {
        s.points
            .iter()
            .map(|&(x, y)| ((x - x0) / sx, (y - y0) / sy))
    });
    let markers = panel.markers.iter().flat_map(|&(x, _)| {
        (0..=MARKER_POINTS).map(move |k| ((x - x0) / sx, k as f64 / MARKER_POINTS as f64))
    });
    let points: Vec<(f64, f64)> = series.chain(markers).collect();
    let covered = |(right, upper): (bool, bool)| {
        points
            .iter()
            .filter(|&&(u, v)| {
                let in_u = if right { u >= 1.0 - fx } else { u <= fx };
                let in_v = if upper { v >= 1.0 - fy } else { v <= fy };
                in_u && in_v && (0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v)
            })
            .count()
    };
    let mut best = CORNERS[0];
    let mut fewest = usize::MAX;
    for corner in CORNERS {
        let n = covered(corner);
        if n < fewest {
            (best, fewest) = (corner, n);
        }
    }
    position(best)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plots::Series;
    use plotters::style::RGBColor;

    fn panel(points: Vec<(f64, f64)>) -> LinePanel {
        LinePanel {
            title: String::new(),
            x_label: String::new(),
            y_label: String::new(),
            x_range: (0.0, 1.0),
            y_range: (0.0, 1.0),
            series: vec![Series {
                label: Some("normal force".into()),
                color: RGBColor(0, 0, 0),
                points,
            }],
            zero_line: false,
            markers: Vec::new(),
        }
    }

    /// A force that rises to the right fills the upper right corner, where the legend used
    /// to be: it goes to the upper left instead, which the curve leaves empty.
    #[test]
    fn legend_avoids_a_curve_in_the_upper_right() {
        let rising = (0..=100)
            .map(|k| (k as f64 / 100.0, k as f64 / 100.0))
            .collect();
        let corner = corner(&panel(rising), (800, 300));
        assert!(
            matches!(
                corner,
                SeriesLabelPosition::UpperLeft | SeriesLabelPosition::LowerRight
            ),
            "{corner:?}"
        );
    }

    /// A curve along the top of the panel (a force near its maximum all along) sends the
    /// legend to a lower corner.
    #[test]
    fn legend_avoids_a_curve_along_the_top() {
        let high = (0..=100).map(|k| (k as f64 / 100.0, 0.95)).collect();
        let corner = corner(&panel(high), (800, 300));
        assert!(
            matches!(
                corner,
                SeriesLabelPosition::LowerRight | SeriesLabelPosition::LowerLeft
            ),
            "{corner:?}"
        );
    }

    /// Where no corner is covered, the legend stays in the upper right.
    #[test]
    fn legend_stays_upper_right_when_it_is_free() {
        let low = (0..=100).map(|k| (k as f64 / 100.0, 0.5)).collect();
        assert!(matches!(
            corner(&panel(low), (800, 300)),
            SeriesLabelPosition::UpperRight
        ));
    }
}
