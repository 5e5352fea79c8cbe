//! Drawing figures with plotters, to SVG and PNG, without system libraries.
//!
//! A [`Figure`] is a title over rows of panels: line plots against time, or snapshots of
//! the mechanism over its cam. Each figure is saved twice: `<stem>.svg` (vector, text left
//! to the viewer's sans-serif font) and `<stem>.png` (rendered into memory by plotters'
//! bitmap backend and encoded with `png`). Text is laid out and rasterised by ab_glyph from
//! DejaVu Sans embedded in the binary, so no system font or font library is needed.

mod heat;
mod legend;
mod mechanism;

use heat::draw_heat;
use mechanism::draw_mechanism;
pub use mechanism::time_color;

use super::kinematics::CamPicture;
use camchain_codegen::profile::Scalar;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::{FontStyle, register_font};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The font family every text uses (DejaVu Sans, registered under this name).
const FONT: &str = "sans-serif";
/// Font sizes in pixels.
const TITLE_SIZE: u32 = 26;
const CAPTION_SIZE: u32 = 19;
const AXIS_SIZE: u32 = 17;
const TICK_SIZE: u32 = 15;
const LEGEND_SIZE: u32 = 14;
/// Space around a chart and for its tick labels, in pixels.
const MARGIN: u32 = 12;
const X_LABEL_AREA: u32 = 48;
const Y_LABEL_AREA: u32 = 86;
/// Width of the legend column beside a snapshot chart, in pixels.
const LEGEND_COLUMN: u32 = 130;
/// Colours of the grid, the cam and neutral lines.
const GRID_BOLD: RGBColor = RGBColor(215, 215, 215);
const GRID_LIGHT: RGBColor = RGBColor(240, 240, 240);
const CAM_FILL: RGBColor = RGBColor(222, 222, 222);
const CAM_EDGE: RGBColor = RGBColor(80, 80, 80);
const NEUTRAL: RGBColor = RGBColor(120, 120, 120);
/// Points of the drawn cam profile across a panel.
const PROFILE_POINTS: usize = 400;

/// A titled figure made of rows of panels.
pub struct Figure {
    /// Printed across the top.
    pub title: String,
    /// Width in pixels.
    pub width: u32,
    /// Rows from top to bottom.
    pub rows: Vec<Row>,
}

impl Figure {
    /// A figure `width` pixels wide of one panel per row, each `(height, panel)`.
    pub fn column(title: String, width: u32, panels: Vec<(u32, Panel)>) -> Figure {
        Figure {
            title,
            width,
            rows: panels
                .into_iter()
                .map(|(height, panel)| Row {
                    height,
                    panels: vec![panel],
                })
                .collect(),
        }
    }
}

/// A row of panels of equal width.
pub struct Row {
    /// Height in pixels.
    pub height: u32,
    /// Panels from left to right.
    pub panels: Vec<Panel>,
}

/// What a panel shows.
pub enum Panel {
    /// Curves against a common x axis.
    Lines(LinePanel),
    /// Snapshots of the mechanism over its cam, at equal scales on both axes.
    Mechanism(MechanismPanel),
    /// Only a message (e.g. why a snapshot cannot be drawn).
    Message(String),
    /// Values on a grid of two parameters, as colours, with a colour bar.
    Heat(HeatPanel),
    /// Points without lines (a scatter), failed points marked.
    Points(PointsPanel),
}

/// Values z(x, y) on the grid of the x and y values, drawn as coloured cells.
pub struct HeatPanel {
    /// Caption above the chart.
    pub title: String,
    /// Axis descriptions, with units.
    pub x_label: String,
    /// Axis descriptions, with units.
    pub y_label: String,
    /// The value's description, with its unit (the colour bar's label).
    pub z_label: String,
    /// The grid's x values, increasing.
    pub x: Vec<f64>,
    /// The grid's y values, increasing.
    pub y: Vec<f64>,
    /// `z[i][j]` at (x[i], y[j]); `None` where the run failed or has no value (drawn grey).
    pub z: Vec<Vec<Option<f64>>>,
    /// What the panel says, in place of a colour bar, when no cell has a value (`no lift-off
    /// in any run`).
    pub empty: String,
    /// A path drawn over the cells (a contact's path over its cam surface), in the axes'
    /// coordinates; empty for none. With a path the grid is a surface's, not swept
    /// parameters': its cells are not clipped at zero.
    pub path: Vec<(f64, f64)>,
}

/// Points on one pair of axes.
pub struct PointsPanel {
    /// Caption above the chart.
    pub title: String,
    /// Axis descriptions, with units.
    pub x_label: String,
    /// Axis descriptions, with units.
    pub y_label: String,
    /// Axis ranges.
    pub x_range: (f64, f64),
    /// Axis ranges.
    pub y_range: (f64, f64),
    /// The points.
    pub points: Vec<(f64, f64)>,
    /// x of the runs without a value (failed, or no lift-off): small crosses on the x axis.
    pub missing: Vec<f64>,
}

/// Curves on one pair of axes.
pub struct LinePanel {
    /// Caption above the chart.
    pub title: String,
    /// Axis descriptions, with units.
    pub x_label: String,
    /// Axis descriptions, with units.
    pub y_label: String,
    /// Axis ranges.
    pub x_range: (f64, f64),
    /// Axis ranges.
    pub y_range: (f64, f64),
    /// The curves.
    pub series: Vec<Series>,
    /// Draw the line y = 0 when it is in range.
    pub zero_line: bool,
    /// Dashed vertical lines at these x, with their legend text.
    pub markers: Vec<(f64, String)>,
}

/// One curve.
pub struct Series {
    /// Legend text (none: not in the legend).
    pub label: Option<String>,
    /// Line colour.
    pub color: RGBColor,
    /// Points in order.
    pub points: Vec<(f64, f64)>,
}

/// Snapshots of a mechanism in a plane, over a cam y = f(x) of that plane.
pub struct MechanismPanel {
    /// Caption above the chart.
    pub title: String,
    /// Axis descriptions, with units.
    pub x_label: String,
    /// Axis descriptions, with units.
    pub y_label: String,
    /// The region that must be visible ((x0, x1), (y0, y1)); widened to equal scales.
    pub bounds: ((f64, f64), (f64, f64)),
    /// The cam profile; its material lies below it.
    pub cam: Option<Scalar>,
    /// The snapshots, in time order.
    pub frames: Vec<Frame>,
    /// Draw the legend column (the snapshots' times) beside the chart.
    pub legend: bool,
}

/// The mechanism at one instant, in plane coordinates.
pub struct Frame {
    /// Legend text (the time).
    pub label: String,
    /// Colour of this snapshot.
    pub color: RGBColor,
    /// Straight links between joints and markers.
    pub links: Vec<[(f64, f64); 2]>,
    /// Joints.
    pub joints: Vec<(f64, f64)>,
    /// Joints to the ground.
    pub bases: Vec<(f64, f64)>,
    /// Contact points.
    pub tips: Vec<(f64, f64)>,
    /// Centres of mass of bodies drawn only up to them (no child, no marker).
    pub coms: Vec<(f64, f64)>,
    /// The cams and follower shapes where they are at this instant.
    pub cams: Vec<CamPicture>,
}

/// What a figure is drawn for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Target {
    /// SVG: curves as polylines.
    Vector,
    /// PNG: curves segment by segment.
    Raster,
}

/// An error while drawing or saving, as one line.
#[derive(Debug)]
pub struct PlotError(pub String);

impl<E: std::error::Error + Send + Sync> From<DrawingAreaErrorKind<E>> for PlotError {
    fn from(e: DrawingAreaErrorKind<E>) -> Self {
        PlotError(e.to_string())
    }
}

impl std::fmt::Display for PlotError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

/// Registers the embedded fonts once.
fn fonts() -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        register_font(FONT, FontStyle::Normal, dejavu::sans::regular()).is_ok()
            && register_font(FONT, FontStyle::Bold, dejavu::sans::bold()).is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err(PlotError("the embedded font could not be loaded".into()))
    }
}

impl Figure {
    /// Height in pixels: the title and every row.
    pub fn height(&self) -> u32 {
        TITLE_SIZE * 2 + self.rows.iter().map(|r| r.height).sum::<u32>()
    }

    /// Writes `<stem>.svg` and `<stem>.png` in `dir`; returns their paths.
    pub fn save(&self, dir: &Path, stem: &str) -> Result<Vec<PathBuf>, PlotError> {
        fonts()?;
        let size = (self.width, self.height());
        let svg_path = dir.join(format!("{stem}.svg"));
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
            self.draw(&root, Target::Vector)?;
            root.present()?;
        }
        crate::output::write_bytes(&svg_path, svg.as_bytes()).map_err(PlotError)?;
        let png_path = dir.join(format!("{stem}.png"));
        let mut rgb = vec![0u8; 3 * size.0 as usize * size.1 as usize];
        {
            let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
            self.draw(&root, Target::Raster)?;
            root.present()?;
        }
        write_png(&png_path, &rgb, size)
            .map_err(|e| PlotError(format!("cannot write {}: {e}", png_path.display())))?;
        Ok(vec![png_path, svg_path])
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        target: Target,
    ) -> Result<(), PlotError> {
        root.fill(&WHITE)?;
        let body = root.titled(&self.title, (FONT, TITLE_SIZE, FontStyle::Bold))?;
        let total: u32 = self.rows.iter().map(|r| r.height).sum::<u32>().max(1);
        let available = body.dim_in_pixel().1;
        let mut rest = body;
        for (i, row) in self.rows.iter().enumerate() {
            let area = if i + 1 == self.rows.len() {
                rest.clone()
            } else {
                let height =
                    (u64::from(available) * u64::from(row.height) / u64::from(total)) as u32;
                let (top, bottom) = rest.split_vertically(height);
                rest = bottom;
                top
            };
            let cells = area.split_evenly((1, row.panels.len().max(1)));
            for (cell, panel) in cells.iter().zip(&row.panels) {
                match panel {
                    Panel::Lines(p) => draw_lines(cell, p, target)?,
                    Panel::Mechanism(p) => draw_mechanism(cell, p)?,
                    Panel::Message(text) => draw_message(cell, text)?,
                    Panel::Heat(p) => draw_heat(cell, p)?,
                    Panel::Points(p) => draw_points(cell, p)?,
                }
            }
        }
        Ok(())
    }
}

fn write_png(path: &Path, rgb: &[u8], (width, height): (u32, u32)) -> Result<(), String> {
    let mut bytes = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut bytes, width, height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
        writer.write_image_data(rgb).map_err(|e| e.to_string())?;
        writer.finish().map_err(|e| e.to_string())?;
    }
    crate::output::write_bytes(path, &bytes)
}

/// Tick labels with as many decimals as the tick spacing needs (about 6 ticks per axis),
/// scientific notation for very small or very large values.
fn tick_format((lo, hi): (f64, f64)) -> impl Fn(&f64) -> String {
    let magnitude = lo.abs().max(hi.abs());
    let step = ((hi - lo) / 6.0).abs().max(f64::MIN_POSITIVE);
    let scientific = !(1e-3..1e5).contains(&magnitude);
    let decimals = (-step.log10().floor()).clamp(0.0, 8.0) as usize;
    move |v: &f64| {
        let v = if v.abs() < step * 1e-6 { 0.0 } else { *v };
        if v == 0.0 {
            "0".into()
        } else if scientific {
            format!("{v:.1e}")
        } else {
            format!("{v:.decimals$}")
        }
    }
}

/// The panel's caption above its chart; returns the area left for the chart.
fn caption<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    title: &str,
) -> Result<DrawingArea<DB, Shift>, PlotError> {
    Ok(area.titled(title, (FONT, CAPTION_SIZE))?)
}

fn draw_lines<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    p: &LinePanel,
    target: Target,
) -> Result<(), PlotError> {
    let area = caption(area, &p.title)?;
    let (x0, x1) = p.x_range;
    let (mut chart, scale) = axes(&area, (&p.x_label, &p.y_label), p.x_range, p.y_range)?;
    let (y0, y1) = (p.y_range.0 * scale, p.y_range.1 * scale);
    if p.zero_line && y0 < 0.0 && y1 > 0.0 {
        chart.draw_series(LineSeries::new([(x0, 0.0), (x1, 0.0)], NEUTRAL))?;
    }
    let mut legend = false;
    for (x, label) in &p.markers {
        let style = NEUTRAL.stroke_width(2);
        chart
            .draw_series(DashedLineSeries::new([(*x, y0), (*x, y1)], 8, 6, style))?
            .label(label.as_str())
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 24, y)], style));
        legend = true;
    }
    let columns = chart.plotting_area().dim_in_pixel().0 as usize;
    for s in &p.series {
        let style = s.color.stroke_width(2);
        let points: Vec<(f64, f64)> = decimate(&s.points, p.x_range, columns / 2)
            .into_iter()
            .map(|(x, y)| (x, y * scale))
            .collect();
        // A raster is drawn segment by segment: the bitmap backend joins thick polylines
        // with mitres, which shoot far past sharp turns (noise-like residuals).
        let pieces: Vec<Vec<(f64, f64)>> = match target {
            Target::Vector => vec![points],
            Target::Raster => points.windows(2).map(<[_]>::to_vec).collect(),
        };
        let drawn = chart.draw_series(pieces.into_iter().map(|p| PathElement::new(p, style)))?;
        if let Some(label) = &s.label {
            drawn
                .label(label.as_str())
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 24, y)], style));
            legend = true;
        }
    }
    if legend {
        let corner = legend::corner(p, chart.plotting_area().dim_in_pixel());
        chart
            .configure_series_labels()
            .position(corner)
            .background_style(WHITE.mix(0.85))
            .border_style(NEUTRAL)
            .label_font((FONT, LEGEND_SIZE))
            .draw()?;
    }
    Ok(())
}

/// A chart on f64 axes.
type Chart<'a, DB> = ChartContext<
    'a,
    DB,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// A chart of line or point plots: labelled axes with a grid, y plotted in a power of ten
/// when its values are too small or too large for plain tick labels; returns the chart and
/// the factor the y values are to be multiplied by.
fn axes<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    (x_label, y_label): (&str, &str),
    (x0, x1): (f64, f64),
    y_range: (f64, f64),
) -> Result<(Chart<'a, DB>, f64), PlotError> {
    let (power, y_label) = scaled_axis(y_range, y_label);
    let scale = 10f64.powi(-power);
    let (y0, y1) = (y_range.0 * scale, y_range.1 * scale);
    let mut chart = ChartBuilder::on(area)
        .margin(MARGIN)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(Y_LABEL_AREA)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    let (x_format, y_format) = (tick_format((x0, x1)), tick_format((y0, y1)));
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(y_label.as_str())
        .x_label_formatter(&x_format)
        .y_label_formatter(&y_format)
        .x_labels(10)
        .y_labels(7)
        .label_style((FONT, TICK_SIZE))
        .axis_desc_style((FONT, AXIS_SIZE))
        .bold_line_style(GRID_BOLD)
        .light_line_style(GRID_LIGHT)
        .draw()?;
    Ok((chart, scale))
}

/// A chart on exactly these ranges (no scaling of the axis), with the grid or without it.
fn plain_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    (x_label, y_label): (&str, &str),
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
    grid: bool,
) -> Result<Chart<'a, DB>, PlotError> {
    let mut chart = ChartBuilder::on(area)
        .margin(MARGIN)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(Y_LABEL_AREA)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    let (x_format, y_format) = (tick_format((x0, x1)), tick_format((y0, y1)));
    let mut mesh = chart.configure_mesh();
    mesh.x_desc(x_label)
        .y_desc(y_label)
        .x_label_formatter(&x_format)
        .y_label_formatter(&y_format)
        .label_style((FONT, TICK_SIZE))
        .axis_desc_style((FONT, AXIS_SIZE));
    if grid {
        mesh.bold_line_style(GRID_BOLD).light_line_style(GRID_LIGHT);
    } else {
        mesh.disable_mesh();
    }
    mesh.draw()?;
    Ok(chart)
}

fn draw_points<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    p: &PointsPanel,
) -> Result<(), PlotError> {
    let area = caption(area, &p.title)?;
    let (mut chart, scale) = axes(&area, (&p.x_label, &p.y_label), p.x_range, p.y_range)?;
    let y0 = p.y_range.0 * scale;
    let color = RGBColor(31, 119, 180);
    chart.draw_series(
        p.points
            .iter()
            .map(|&(x, y)| Circle::new((x, y * scale), 3, color.filled())),
    )?;
    chart.draw_series(
        p.missing
            .iter()
            .map(|&x| Cross::new((x, y0), 4, RGBColor(200, 40, 40).stroke_width(2))),
    )?;
    Ok(())
}

/// For values too small or too large for plain tick labels: the power of ten they are
/// plotted in, and the axis label with it (`A_h [m]` → `A_h [10⁻¹⁶ m]`); otherwise
/// `(0, label)`.
fn scaled_axis((lo, hi): (f64, f64), label: &str) -> (i32, String) {
    let magnitude = lo.abs().max(hi.abs());
    if magnitude == 0.0 || !magnitude.is_finite() || (1e-3..1e5).contains(&magnitude) {
        return (0, label.to_string());
    }
    let power = magnitude.log10().floor() as i32;
    let superscript: String = power
        .to_string()
        .chars()
        .map(|c| match c {
            '-' => '⁻',
            d => ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'][d as usize - '0' as usize],
        })
        .collect();
    let text = match (label.rfind('['), label.ends_with(']')) {
        (Some(open), true) => format!("{}[10{superscript} {}", &label[..open], &label[open + 1..]),
        _ => format!("{label} (10{superscript})"),
    };
    (power, text)
}

/// At most `buckets` × 2 points: the lowest and the highest of each of `buckets` equal
/// slices of the x range, in their original order, so that the envelope is kept while
/// sub-pixel segments (which the bitmap backend draws ragged) are dropped.
fn decimate(points: &[(f64, f64)], (x0, x1): (f64, f64), buckets: usize) -> Vec<(f64, f64)> {
    if buckets == 0 || points.len() <= 2 * buckets || x1 <= x0 {
        return points.to_vec();
    }
    let bucket = |x: f64| (((x - x0) / (x1 - x0) * buckets as f64) as usize).min(buckets - 1);
    let mut kept: Vec<(f64, f64)> = Vec::with_capacity(2 * buckets + 2);
    let mut i = 0;
    while i < points.len() {
        let b = bucket(points[i].0);
        let mut j = i;
        let (mut low, mut high) = (i, i);
        while j < points.len() && bucket(points[j].0) == b {
            if points[j].1 < points[low].1 {
                low = j;
            }
            if points[j].1 > points[high].1 {
                high = j;
            }
            j += 1;
        }
        let (first, second) = (low.min(high), low.max(high));
        kept.push(points[first]);
        if second != first {
            kept.push(points[second]);
        }
        i = j;
    }
    if let (Some(last), Some(end)) = (kept.last(), points.last())
        && last != end
    {
        kept.push(*end);
    }
    kept
}

fn draw_message<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
) -> Result<(), PlotError> {
    let (w, h) = area.dim_in_pixel();
    let style = TextStyle::from((FONT, AXIS_SIZE).into_font())
        .color(&NEUTRAL)
        .pos(plotters::style::text_anchor::Pos::new(
            plotters::style::text_anchor::HPos::Center,
            plotters::style::text_anchor::VPos::Center,
        ));
    area.draw_text(text, &style, ((w / 2) as i32, (h / 2) as i32))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_have_the_decimals_they_need() {
        let f = tick_format((-0.015, 0.01));
        assert_eq!(f(&0.005), "0.005");
        assert_eq!(f(&1e-20), "0");
        let g = tick_format((0.0, 10.0));
        assert_eq!(g(&2.0), "2");
        let h = tick_format((-2e-16, 2e-16));
        assert_eq!(h(&1e-16), "1.0e-16");
    }

    #[test]
    fn tiny_values_get_a_power_of_ten() {
        assert_eq!(
            scaled_axis((-2e-16, 3e-16), "A_h [m]"),
            (-16, "A_h [10⁻¹⁶ m]".into())
        );
        assert_eq!(scaled_axis((0.0, 2.0), "q [rad]"), (0, "q [rad]".into()));
        assert_eq!(scaled_axis((0.0, 2e6), "F"), (6, "F (10⁶)".into()));
    }

    #[test]
    fn decimation_keeps_the_envelope() {
        let points: Vec<(f64, f64)> = (0..1000)
            .map(|i| (i as f64 / 999.0, if i % 2 == 0 { 1.0 } else { -1.0 }))
            .collect();
        let kept = decimate(&points, (0.0, 1.0), 50);
        assert!(kept.len() <= 101);
        assert!(kept.iter().any(|p| p.1 == 1.0) && kept.iter().any(|p| p.1 == -1.0));
        assert_eq!(kept.first(), points.first());
        assert_eq!(kept.last(), points.last());
        assert!(kept.windows(2).all(|w| w[0].0 < w[1].0));
    }
}
