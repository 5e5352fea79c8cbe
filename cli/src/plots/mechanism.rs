//! Snapshots of the mechanism: its bodies, cams and followers drawn to scale at several
//! times, coloured early → late, with their legend.

use super::*;

/// Widens `bounds` (with a small border) so that one metre has the same length in pixels
/// on both axes of a `width` × `height` plotting area.
pub(super) fn equal_scales(
    ((x0, x1), (y0, y1)): ((f64, f64), (f64, f64)),
    (width, height): (u32, u32),
) -> ((f64, f64), (f64, f64)) {
    let border = 0.05 * (x1 - x0).max(y1 - y0).max(1e-3);
    let (x0, x1, y0, y1) = (x0 - border, x1 + border, y0 - border, y1 + border);
    let (w, h) = (f64::from(width.max(1)), f64::from(height.max(1)));
    let scale = ((x1 - x0) / w).max((y1 - y0) / h);
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let (half_w, half_h) = (0.5 * scale * w, 0.5 * scale * h);
    ((cx - half_w, cx + half_w), (cy - half_h, cy + half_h))
}

pub(super) fn draw_mechanism<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    p: &MechanismPanel,
) -> Result<(), PlotError> {
    let area = caption(area, &p.title)?;
    let (w, h) = area.dim_in_pixel();
    let legend_width = if p.legend { LEGEND_COLUMN } else { 0 };
    let (area, legend_area) = area.split_horizontally(w.saturating_sub(legend_width));
    let plot = (
        w.saturating_sub(legend_width + Y_LABEL_AREA + 2 * MARGIN),
        h.saturating_sub(X_LABEL_AREA + 2 * MARGIN),
    );
    let ((x0, x1), (y0, y1)) = equal_scales(p.bounds, plot);
    let labels = (p.x_label.as_str(), p.y_label.as_str());
    let mut chart = plain_chart(&area, labels, (x0, x1), (y0, y1), true)?;
    if let Some(profile) = &p.cam {
        let curve: Vec<(f64, f64)> = (0..=PROFILE_POINTS)
            .map(|i| x0 + (x1 - x0) * i as f64 / PROFILE_POINTS as f64)
            .map(|x| (x, profile.eval(x)))
            .filter(|(_, y)| y.is_finite())
            .map(|(x, y)| (x, y.clamp(y0, y1)))
            .collect();
        let mut outline = curve.clone();
        outline.extend([(x1, y0), (x0, y0)]);
        chart.draw_series(std::iter::once(Polygon::new(outline, CAM_FILL.filled())))?;
        chart.draw_series(LineSeries::new(curve, CAM_EDGE.stroke_width(2)))?;
    }
    for frame in &p.frames {
        for cam in &frame.cams {
            draw_cam(&mut chart, cam, frame.color)?;
        }
    }
    for frame in &p.frames {
        draw_frame(&mut chart, frame)?;
    }
    if p.legend {
        draw_time_legend(&legend_area, p)?;
    }
    Ok(())
}

/// A cam where its body carries it (material filled, profile edge, base circle thin, centre
/// as a small cross) and its follower's roller or flat face in the snapshot's colour.
pub(super) fn draw_cam<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    cam: &CamPicture,
    color: RGBColor,
) -> Result<(), PlotError> {
    if !cam.material.is_empty() {
        chart.draw_series(std::iter::once(Polygon::new(
            cam.material.clone(),
            CAM_FILL.filled(),
        )))?;
    }
    if cam.closed {
        chart.draw_series(std::iter::once(Polygon::new(
            cam.outline.clone(),
            CAM_FILL.filled(),
        )))?;
    }
    if !cam.outline.is_empty() {
        let mut edge = cam.outline.clone();
        if cam.closed {
            edge.push(cam.outline[0]);
        }
        chart.draw_series(LineSeries::new(edge, CAM_EDGE.stroke_width(2)))?;
    }
    if !cam.outer_flank.is_empty() {
        let mut edge = cam.outer_flank.clone();
        edge.push(cam.outer_flank[0]);
        chart.draw_series(LineSeries::new(edge, CAM_EDGE.stroke_width(2)))?;
    }
    if !cam.base_circle.is_empty() {
        chart.draw_series(LineSeries::new(
            cam.base_circle.clone(),
            NEUTRAL.stroke_width(1),
        ))?;
    }
    if cam.centre.0.is_finite() && cam.centre.1.is_finite() {
        chart.draw_series(std::iter::once(Cross::new(
            cam.centre,
            4,
            CAM_EDGE.stroke_width(1),
        )))?;
    }
    if !cam.roller.is_empty() {
        chart.draw_series(LineSeries::new(cam.roller.clone(), color.stroke_width(2)))?;
    }
    if !cam.face.is_empty() {
        chart.draw_series(LineSeries::new(cam.face.clone(), color.stroke_width(3)))?;
    }
    Ok(())
}

/// The legend of a snapshot panel, beside the chart: the cam, then one line per snapshot.
pub(super) fn draw_time_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    p: &MechanismPanel,
) -> Result<(), PlotError> {
    let font = (FONT, LEGEND_SIZE).into_font();
    let row = |i: usize| (MARGIN + 10 + 24 * i as u32) as i32;
    let mut entries = 0;
    let moving_cam = p
        .frames
        .iter()
        .any(|f| f.cams.iter().any(|c| !c.outline.is_empty()));
    if p.cam.is_some() || moving_cam {
        let y = row(0);
        area.draw(&Rectangle::new(
            [(4, y - 7), (28, y + 7)],
            CAM_FILL.filled(),
        ))?;
        area.draw(&PathElement::new(
            [(4, y - 7), (28, y - 7)],
            CAM_EDGE.stroke_width(2),
        ))?;
        area.draw(&Text::new("cam", (36, y - 8), font.clone()))?;
        entries = 1;
    }
    for (i, frame) in p.frames.iter().enumerate() {
        let y = row(entries + i);
        area.draw(&PathElement::new(
            [(4, y), (28, y)],
            frame.color.stroke_width(3),
        ))?;
        area.draw(&Text::new(frame.label.as_str(), (36, y - 8), font.clone()))?;
    }
    if p.frames.iter().any(|f| !f.coms.is_empty()) {
        let y = row(entries + p.frames.len());
        area.draw(&Cross::new((16, y), 6, BLACK.stroke_width(2)))?;
        area.draw(&Text::new("centre of mass", (36, y - 8), font))?;
    }
    Ok(())
}

pub(super) fn draw_frame<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    frame: &Frame,
) -> Result<(), PlotError> {
    let link = frame.color.stroke_width(3);
    chart.draw_series(frame.links.iter().map(|l| PathElement::new(*l, link)))?;
    let ring = frame.color.stroke_width(2);
    chart.draw_series(
        frame
            .joints
            .iter()
            .map(|j| Circle::new(*j, 4, WHITE.filled())),
    )?;
    chart.draw_series(frame.joints.iter().map(|j| Circle::new(*j, 4, ring)))?;
    chart.draw_series(
        frame
            .bases
            .iter()
            .map(|b| TriangleMarker::new(*b, 9, BLACK.filled())),
    )?;
    chart.draw_series(
        frame
            .tips
            .iter()
            .map(|t| Circle::new(*t, 5, frame.color.filled())),
    )?;
    let cross = frame.color.stroke_width(2);
    chart.draw_series(frame.coms.iter().map(|c| Cross::new(*c, 6, cross)))?;
    Ok(())
}

/// A colour for fraction `f` ∈ [0, 1] of a run (viridis from dark purple to green, its
/// pale yellow end left out so that every snapshot shows on white).
pub fn time_color(f: f64) -> RGBColor {
    const STOPS: [(f64, [f64; 3]); 5] = [
        (0.0, [68.0, 1.0, 84.0]),
        (0.25, [59.0, 82.0, 139.0]),
        (0.5, [33.0, 145.0, 140.0]),
        (0.75, [94.0, 201.0, 98.0]),
        (1.0, [253.0, 231.0, 37.0]),
    ];
    let x = 0.8 * f.clamp(0.0, 1.0);
    let i = STOPS.iter().rposition(|(s, _)| *s <= x).unwrap_or(0).min(3);
    let ((s0, c0), (s1, c1)) = (STOPS[i], STOPS[i + 1]);
    let u = (x - s0) / (s1 - s0);
    let mix = |k: usize| (c0[k] + u * (c1[k] - c0[k])).round() as u8;
    RGBColor(mix(0), mix(1), mix(2))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equal_scales_keep_the_bounds_visible() {
        let ((x0, x1), (y0, y1)) = equal_scales(((0.0, 1.0), (0.0, 0.2)), (800, 400));
        assert!(x0 < 0.0 && x1 > 1.0 && y0 < 0.0 && y1 > 0.2);
        assert!(((x1 - x0) / 800.0 - (y1 - y0) / 400.0).abs() < 1e-12);
    }

    #[test]
    fn time_colours_run_from_purple_to_green() {
        assert_eq!(time_color(0.0), RGBColor(68, 1, 84));
        assert_eq!(time_color(2.0), time_color(1.0));
    }
}
