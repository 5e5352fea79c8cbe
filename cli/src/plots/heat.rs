//! Heat maps: values on a grid of two swept parameters as coloured cells, with a colour bar
//! (or, when no cell has a value, the panel's message in their place).

use super::*;

/// The cell edges around increasing grid values: midway between neighbours, half a gap
/// beyond the ends (a single value gets ±5 % of itself, or ±0.5); values that are all
/// non-negative get no edge below zero (a stiffness swept over 0 and 10 has no axis from −5).
pub(super) fn cell_edges(values: &[f64]) -> Vec<f64> {
    let mut edges = unclamped_edges(values);
    if let (Some(&v), Some(first)) = (values.first(), edges.first_mut())
        && v >= 0.0
    {
        *first = first.max(0.0);
    }
    edges
}

pub(super) fn unclamped_edges(values: &[f64]) -> Vec<f64> {
    match values {
        [] => vec![0.0, 1.0],
        [v] => {
            let half = if *v == 0.0 { 0.5 } else { 0.05 * v.abs() };
            vec![v - half, v + half]
        }
        _ => {
            let n = values.len();
            let mut edges = Vec::with_capacity(n + 1);
            edges.push(values[0] - 0.5 * (values[1] - values[0]));
            edges.extend(values.windows(2).map(|w| 0.5 * (w[0] + w[1])));
            edges.push(values[n - 1] + 0.5 * (values[n - 1] - values[n - 2]));
            edges
        }
    }
}

/// The viridis colour map over [0, 1].
pub fn viridis(f: f64) -> RGBColor {
    const STOPS: [[f64; 3]; 5] = [
        [68.0, 1.0, 84.0],
        [59.0, 82.0, 139.0],
        [33.0, 145.0, 140.0],
        [94.0, 201.0, 98.0],
        [253.0, 231.0, 37.0],
    ];
    let x = 4.0
        * if f.is_finite() {
            f.clamp(0.0, 1.0)
        } else {
            0.0
        };
    let i = (x.floor() as usize).min(3);
    let u = x - i as f64;
    let mix = |k: usize| (STOPS[i][k] + u * (STOPS[i + 1][k] - STOPS[i][k])).round() as u8;
    RGBColor(mix(0), mix(1), mix(2))
}

pub(super) fn draw_heat<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    p: &HeatPanel,
) -> Result<(), PlotError> {
    let area = caption(area, &p.title)?;
    let (w, _) = area.dim_in_pixel();
    let (map, bar) = area.split_horizontally(w.saturating_sub(130));
    let edges = |v: &[f64]| {
        if p.path.is_empty() {
            cell_edges(v)
        } else {
            unclamped_edges(v)
        }
    };
    let (xe, ye) = (edges(&p.x), edges(&p.y));
    let (x0, x1) = (xe[0], xe[xe.len() - 1]);
    let (y0, y1) = (ye[0], ye[ye.len() - 1]);
    let values: Vec<f64> = p.z.iter().flatten().flatten().copied().collect();
    let (lo, hi) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let (lo, hi) = if lo.is_finite() && hi > lo {
        (lo, hi)
    } else if lo.is_finite() {
        (lo - 0.5, lo + 0.5)
    } else {
        (0.0, 1.0)
    };
    let labels = (p.x_label.as_str(), p.y_label.as_str());
    if values.is_empty() {
        // No value anywhere: no colour scale to show; the panel says why instead.
        plain_chart(&area, labels, (x0, x1), (y0, y1), false)?;
        return draw_message(&area, &p.empty);
    }
    let mut chart = plain_chart(&map, labels, (x0, x1), (y0, y1), false)?;
    let mut cells = Vec::new();
    for (i, column) in p.z.iter().enumerate() {
        for (j, z) in column.iter().enumerate() {
            let color = match z {
                Some(v) => viridis((v - lo) / (hi - lo)).filled(),
                None => GRID_BOLD.filled(),
            };
            cells.push(Rectangle::new(
                [(xe[i], ye[j]), (xe[i + 1], ye[j + 1])],
                color,
            ));
        }
    }
    chart.draw_series(cells)?;
    if !p.path.is_empty() {
        chart.draw_series(LineSeries::new(
            p.path.iter().copied(),
            WHITE.stroke_width(2),
        ))?;
    }
    let (power, z_label) = scaled_axis((lo, hi), &p.z_label);
    let scale = 10f64.powi(-power);
    let mut legend = ChartBuilder::on(&bar)
        .margin(MARGIN)
        .margin_left(4)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(0)
        .right_y_label_area_size(90)
        .build_cartesian_2d(0.0..1.0, (lo * scale)..(hi * scale))?
        .set_secondary_coord(0.0..1.0, (lo * scale)..(hi * scale));
    let z_format = tick_format((lo * scale, hi * scale));
    legend
        .configure_secondary_axes()
        .y_desc(z_label.as_str())
        .y_label_formatter(&z_format)
        .label_style((FONT, TICK_SIZE))
        .axis_desc_style((FONT, AXIS_SIZE))
        .draw()?;
    let steps = 64;
    legend.draw_series((0..steps).map(|k| {
        let (a, b) = (k as f64 / steps as f64, (k + 1) as f64 / steps as f64);
        let (za, zb) = ((lo + a * (hi - lo)) * scale, (lo + b * (hi - lo)) * scale);
        Rectangle::new([(0.0, za), (1.0, zb)], viridis(a).filled())
    }))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A non-negative parameter swept over two values (0 and 10) used to get an axis from
    /// −5: the cells now start at zero, the middle edge and the far end as before.
    #[test]
    fn two_value_axis_of_a_non_negative_parameter_starts_at_zero() {
        assert_eq!(cell_edges(&[0.0, 10.0]), vec![0.0, 5.0, 15.0]);
        assert_eq!(cell_edges(&[0.0]), vec![0.0, 0.5]);
        // Values below zero keep their symmetric cells.
        assert_eq!(cell_edges(&[-1.0, 1.0]), vec![-2.0, 0.0, 2.0]);
    }
}
