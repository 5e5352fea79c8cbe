//! Cam surfaces through a grid of points (`table: (form: Surface, file: "…")`): rows x, y, z
//! read from a CSV file beside the model, in any order, that must cover every pair of their
//! distinct x and y values exactly once; interpolated by the C² bicubic spline of
//! `camchain_runtime::surface_spline`, which the surface's expression reads as a tabulated
//! leaf of two variables ([`Scalar::Grid`]).
//!
//! Every problem is located at the line and the column of the CSV that causes it: a cell
//! that is not a number, a number beyond ±[`LARGEST`], a point given twice, a point missing
//! from the grid (at the first row of its x), a periodic edge that does not repeat the other,
//! values that change too fast for their spacing. The spline is built in O(n) for n points
//! (the runtime's solves along the grid lines) when the file is read.

use super::table_files::{LARGEST, MAX_TABLE_POINTS, ends_of, read_file, too_many_points};
use super::{Checked, Context, Profile};
use crate::error::ModelError;
use crate::model::Follower;
use crate::profile::{Gridded, Scalar};
use crate::schema::csv::{self, Row};
use crate::schema::raw;
use camchain_runtime::spline::Ends;
use camchain_runtime::surface_spline::{SurfaceSpline, SurfaceSplineError};
use std::collections::HashMap;

/// The surface z = S(x, y) of `table` (at `field` of contact `path`) for contact `name`.
pub(super) fn grid_profile(
    cx: &Context,
    (path, field): (&str, &str),
    table: &raw::Table,
    name: &str,
    follower: &Follower,
) -> Checked<Profile> {
    let what = "a surface: a surface takes a point (`follower: Knife`) or a ball (`follower: \
                Roller(radius: …)`, its centre the marker)";
    surface_follower(cx, path, (follower, what, true))?;
    if table.degrees {
        return Err(cx.at.error(
            &format!("{field}.degrees"),
            "a surface's table has lengths x, y, z, not angles: `degrees` is for polar tables",
        ));
    }
    let written = match (&table.points, &table.file) {
        (None, Some(file)) => file,
        _ => {
            return Err(cx.at.error(
                field,
                "a surface's table is read from a CSV file of x, y, z rows (`file: \
                 \"surface.csv\"`, relative to the model file), one row per grid point",
            ));
        }
    };
    let (text, shown) = read_file(cx, &format!("{field}.file"), written)?;
    let at = |line: usize, column: usize, message: String| ModelError {
        file: shown.clone(),
        line,
        column,
        field: format!("{field}.file"),
        message,
    };
    let rows = csv::read(&text, ["x", "y", "z"]).map_err(|e| at(e.line, e.column, e.message))?;
    if let Some(row) = rows.get(MAX_TABLE_POINTS) {
        return Err(at(row.line, row.columns[0], too_many_points(rows.len())));
    }
    for row in &rows {
        for (k, &v) in row.values.iter().enumerate() {
            if v.abs() > LARGEST {
                return Err(at(
                    row.line,
                    row.columns[k],
                    format!(
                        "{} = {v:e} is beyond ±{LARGEST:e}, the largest magnitude a table's \
                         spline computes with",
                        ["x", "y", "z"][k]
                    ),
                ));
            }
        }
    }
    let grid = Grid::of(&rows).map_err(|(line, column, message)| at(line, column, message))?;
    let ends_x = table.ends.map_or(Ends::Natural, ends_of);
    let ends_y = table.y_ends.map_or(ends_x, ends_of);
    let spline = SurfaceSpline::new(&grid.x, &grid.y, &grid.z, [ends_x, ends_y])
        .map_err(|e| spline_error(cx, field, &grid, &at, e))?;
    let (nx, ny) = spline.shape();
    let source = format!("a bicubic spline through the {nx} × {ny} grid of {written}");
    let surface = Gridded::new(format!("{name}_surface"), spline);
    Ok(Profile::Surface {
        source,
        f: Scalar::gridded(&surface, (0, 0), Scalar::Var(0), Scalar::Var(1)),
    })
}

/// A surface takes a point, or a ball where `balls`; any other follower is refused with "a
/// flat face cannot follow {what}".
pub(super) fn surface_follower(
    cx: &Context,
    path: &str,
    (follower, what, balls): (&Follower, &str, bool),
) -> Checked<()> {
    match follower {
        Follower::Knife => Ok(()),
        Follower::Roller { .. } if balls => Ok(()),
        Follower::Roller { .. } | Follower::Flat { .. } | Follower::Mushroom { .. } => {
            Err(cx.at.error(
                &format!("{path}.follower"),
                format!("a {} cannot follow {what}", follower.kind().label()),
            ))
        }
    }
}

/// The grid the rows make: the distinct x and y values in increasing order and the values
/// row by row (`z[i * ny + j]` at (x_i, y_j)), with the line of each point.
struct Grid {
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
    /// The line and the z column of each point, as `z`.
    at: Vec<(usize, usize)>,
}

/// A problem at a line and a column of the file.
type Located = (usize, usize, String);

impl Grid {
    /// The grid of `rows`, or where it is not one: a point given twice, or a pair of an x
    /// and a y of the rows that no row gives (reported at the first row of that x).
    fn of(rows: &[Row<3>]) -> Result<Grid, Located> {
        let distinct = |k: usize| {
            let mut v: Vec<f64> = rows.iter().map(|r| r.values[k]).collect();
            v.sort_by(f64::total_cmp);
            // −0 and +0 are one knot.
            v.dedup_by(|a, b| a == b);
            v
        };
        let (x, y) = (distinct(0), distinct(1));
        let (nx, ny) = (x.len(), y.len());
        let index = |knots: &[f64], v: f64| knots.partition_point(|&k| k < v);
        let mut z = vec![f64::NAN; nx * ny];
        let mut at = vec![(0, 0); nx * ny];
        let mut first_of_x: HashMap<usize, &Row<3>> = HashMap::new();
        for row in rows {
            let (i, j) = (index(&x, row.values[0]), index(&y, row.values[1]));
            first_of_x.entry(i).or_insert(row);
            let k = i * ny + j;
            if at[k].0 != 0 {
                return Err((
                    row.line,
                    row.columns[0],
                    format!(
                        "this row gives the point (x, y) = ({}, {}) again, after line {}: a \
                         grid has one z per point",
                        row.values[0], row.values[1], at[k].0
                    ),
                ));
            }
            z[k] = row.values[2];
            at[k] = (row.line, row.columns[2]);
        }
        if let Some(k) = at.iter().position(|a| a.0 == 0) {
            let (i, j) = (k / ny, k % ny);
            let (line, column) = first_of_x
                .get(&i)
                .map_or((1, 1), |r| (r.line, r.columns[0]));
            return Err((
                line,
                column,
                format!(
                    "no row gives z at (x, y) = ({}, {}): the rows have {nx} distinct x and {ny} \
                     distinct y values, so the grid needs all {} of their pairs and has {} (x = \
                     {} starts on this line; a grid's x and y values must repeat exactly, to the \
                     last digit, from one line of points to the next)",
                    x[i],
                    y[j],
                    nx as u128 * ny as u128,
                    rows.len(),
                    x[i]
                ),
            ));
        }
        Ok(Grid { x, y, z, at })
    }
}

/// The runtime's refusal of a grid, located at the point it concerns where there is one.
fn spline_error(
    cx: &Context,
    field: &str,
    grid: &Grid,
    at: &dyn Fn(usize, usize, String) -> ModelError,
    e: SurfaceSplineError,
) -> ModelError {
    let ny = grid.y.len();
    let point = |i: usize, j: usize| grid.at.get(i * ny + j).copied();
    let located = match &e {
        SurfaceSplineError::EdgesDoNotMeet { last_cell, .. } => point(last_cell.0, last_cell.1),
        SurfaceSplineError::Overflow { i, j, .. } | SurfaceSplineError::NotFinite { i, j, .. } => {
            point(*i, *j)
        }
        SurfaceSplineError::Shape { .. }
        | SurfaceSplineError::Knots { .. }
        | SurfaceSplineError::TooWide { .. }
        | SurfaceSplineError::Slopes { .. }
        | SurfaceSplineError::Line { .. } => None,
    };
    let message = format!("the grid cannot make a surface: {e}");
    match located {
        Some((line, column)) => at(line, column, message),
        None => cx.at.error(&format!("{field}.file"), message),
    }
}
