//! Profiles through tables of points (`table:`): points written in the model file or read
//! from a CSV file beside it, checked, and interpolated by a C² cubic spline
//! (`camchain_runtime::spline`) that the profile's expressions read as a tabulated leaf.
//!
//! - explicit: x, y of y = f(x), x increasing; natural ends unless clamped (or periodic);
//! - polar: θ, r of r(θ) over one turn, the last point repeating the first 2π later; always
//!   periodic; θ in radians, or in degrees with `degrees: true`;
//! - parametric: x, y of a curve in order along it, parametrised by the length of the
//!   polygon through the points (chord length); closed (periodic) unless declared open
//!   (`ends: Natural`), its last point then repeating the first, and turned counterclockwise
//!   if it was written clockwise (the cam's material on the left, as for every parametric
//!   profile).
//!
//! A closed table must close: its last row repeats the first one's value one period later,
//! checked before anything is built ([`closes`]), so that a table that lost its closing row
//! is an error at that row rather than an open curve or a jump at the seam. Every number is
//! within ±[`LARGEST`], so that the spline's arithmetic cannot overflow, and the spline
//! built is checked finite.

use super::table_files::{LARGEST, MAX_TABLE_POINTS, ends_of, read_file, too_many_points};
use super::{Checked, Context, Profile};
use crate::error::ModelError;
use crate::model::Follower;
use crate::profile::{Scalar, Tabulated};
use crate::schema::csv;
use crate::schema::raw::{self, TableForm};
use camchain_runtime::spline::{CLOSURE_TOLERANCE, Ends, Spline, SplineError};
use std::f64::consts::TAU;
use std::path::PathBuf;

/// Where one point of a table is written.
#[derive(Debug, Clone)]
enum At {
    /// `points[k]` in the model file.
    Inline(usize),
    /// A line of a table file (shown as `file`) and the columns of its two cells.
    File {
        file: PathBuf,
        line: usize,
        columns: [usize; 2],
    },
}

impl At {
    /// Where the point is, for messages that refer to another point: `line 4` or
    /// `points[0]`.
    fn described(&self) -> String {
        match self {
            At::Inline(k) => format!("points[{k}]"),
            At::File { line, .. } => format!("line {line}"),
        }
    }
}

/// The points of a table with where each is written.
struct Points {
    values: Vec<[f64; 2]>,
    at: Vec<At>,
    /// The names of the two columns (`x, y` or `theta, r`).
    names: [&'static str; 2],
    /// `file`'s path as the model writes it, for descriptions.
    from: Option<String>,
}

/// A table that makes a curve.
#[derive(Clone, Copy)]
enum Curve {
    Explicit,
    Polar,
    Parametric,
}

/// The profile of `table` for contact `name` (path `path`) followed by `follower`, and the
/// interval of its variable the table covers (the contact's default range; none for a
/// surface, [`super::grids`]).
pub(super) fn table_profile(
    cx: &Context,
    path: &str,
    table: &raw::Table,
    (name, follower): (&str, &Follower),
) -> Checked<(Profile, Option<(f64, f64)>)> {
    let field = format!("{path}.table");
    let (form, names) = match table.form {
        TableForm::Explicit => (Curve::Explicit, ["x", "y"]),
        TableForm::Polar => (Curve::Polar, ["theta", "r"]),
        TableForm::Parametric => (Curve::Parametric, ["x", "y"]),
        TableForm::Surface => {
            let profile = super::grids::grid_profile(cx, (path, &field), table, name, follower)?;
            return Ok((profile, None));
        }
    };
    if table.y_ends.is_some() {
        return Err(cx.at.error(
            &format!("{field}.y_ends"),
            "only a surface's table (`form: Surface`) has ends along y; a profile's table has \
             `ends` only",
        ));
    }
    let points = points(cx, &field, table, names)?;
    if points.values.len() > MAX_TABLE_POINTS {
        let at = &points.at[MAX_TABLE_POINTS];
        return Err(point_error(
            cx,
            &field,
            at,
            0,
            too_many_points(points.values.len()),
        ));
    }
    within_range(cx, &field, &points)?;
    let ends = table.ends.map(ends_of);
    let described = |what: &str| match &points.from {
        Some(file) => format!(
            "{what} through the {} points of {file}",
            points.values.len()
        ),
        None => format!("{what} through {} points", points.values.len()),
    };
    match form {
        Curve::Explicit => {
            let ends = ends.unwrap_or(Ends::Natural);
            if ends == Ends::Periodic {
                closes(cx, &field, &points, "a periodic table")?;
            }
            let (x, y) = columns(&points.values);
            let spline = spline(cx, &field, &points, &x, &y, ends)?;
            let f =
                Scalar::Var(0).tabulated(&Tabulated::spline(format!("{name}_table"), spline), 0);
            let range = (x[0], x[x.len() - 1]);
            let source = described("a spline");
            Ok((Profile::Explicit { source, f }, Some(range)))
        }
        Curve::Polar => {
            if let Some(other) = ends.filter(|e| *e != Ends::Periodic) {
                return Err(cx.at.error(
                    &format!("{field}.ends"),
                    format!(
                        "a polar table closes on itself: its ends are `Periodic`, not {other:?}"
                    ),
                ));
            }
            let scale = if table.degrees { TAU / 360.0 } else { 1.0 };
            let (theta, r): (Vec<f64>, Vec<f64>) =
                points.values.iter().map(|p| (p[0] * scale, p[1])).unzip();
            one_turn(cx, &field, &points, &theta, table.degrees)?;
            closes(cx, &field, &points, "a polar table")?;
            let spline = spline(cx, &field, &points, &theta, &r, Ends::Periodic)?;
            let r =
                Scalar::Var(0).tabulated(&Tabulated::spline(format!("{name}_table"), spline), 0);
            let source = described("a periodic spline");
            Ok((Profile::Polar { source, r }, Some((0.0, TAU))))
        }
        Curve::Parametric => {
            parametric(cx, &field, points, ends, name).map(|(p, covers)| (p, Some(covers)))
        }
    }
}

/// A parametric table: x(t) and y(t) splines of the chord length t; closed unless declared
/// open (`ends: Natural`).
fn parametric(
    cx: &Context,
    field: &str,
    mut points: Points,
    ends: Option<Ends>,
    name: &str,
) -> Checked<(Profile, (f64, f64))> {
    if let Some(Ends::Clamped { .. }) = ends {
        return Err(cx.at.error(
            &format!("{field}.ends"),
            "a parametric table is open (`Natural`) or closed (`Periodic`); clamped ends take \
             one slope each and a curve's ends need a direction",
        ));
    }
    let n = points.values.len();
    let closed = ends.is_none_or(|e| e == Ends::Periodic);
    if closed {
        curve_closes(cx, field, &points)?;
        if signed_area(&points.values) < 0.0 {
            // Counterclockwise, so that the cam's material is on the left.
            points.values.reverse();
            points.at.reverse();
        }
    }
    let mut t = Vec::with_capacity(n);
    let mut length = 0.0;
    for (k, p) in points.values.iter().enumerate() {
        if k > 0 {
            let q = points.values[k - 1];
            let chord = (p[0] - q[0]).hypot(p[1] - q[1]);
            if chord == 0.0 {
                return Err(point_error(
                    cx,
                    field,
                    &points.at[k],
                    0,
                    format!(
                        "this point repeats its neighbour at {} along the curve: a curve's \
                         points must differ from their neighbours",
                        points.at[k - 1].described()
                    ),
                ));
            }
            length += chord;
        }
        t.push(length);
    }
    let ends = if closed {
        Ends::Periodic
    } else {
        Ends::Natural
    };
    let (x, y) = columns(&points.values);
    let sx = spline(cx, field, &points, &t, &x, ends)?;
    let sy = spline(cx, field, &points, &t, &y, ends)?;
    let what = if closed {
        "a closed curve of chord-length splines"
    } else {
        "an open curve of chord-length splines"
    };
    let described = match &points.from {
        Some(file) => format!("{what} through the {n} points of {file}"),
        None => format!("{what} through {n} points"),
    };
    let profile = Profile::Parametric {
        x_source: described.clone(),
        y_source: described,
        x: Scalar::Var(0).tabulated(&Tabulated::spline(format!("{name}_table_x"), sx), 0),
        y: Scalar::Var(0).tabulated(&Tabulated::spline(format!("{name}_table_y"), sy), 0),
    };
    Ok((profile, (0.0, length)))
}

/// Twice the signed area of the closed polygon (positive counterclockwise).
fn signed_area(p: &[[f64; 2]]) -> f64 {
    (0..p.len())
        .map(|k| {
            let (a, b) = (p[k], p[(k + 1) % p.len()]);
            a[0] * b[1] - a[1] * b[0]
        })
        .sum()
}

fn columns(values: &[[f64; 2]]) -> (Vec<f64>, Vec<f64>) {
    values.iter().map(|p| (p[0], p[1])).unzip()
}

/// Every number of the table is finite and within ±[`LARGEST`].
fn within_range(cx: &Context, field: &str, points: &Points) -> Checked<()> {
    for (p, at) in points.values.iter().zip(&points.at) {
        for (cell, &v) in p.iter().enumerate() {
            let name = points.names[cell];
            let problem = if !v.is_finite() {
                format!("{name} must be a finite number, not {v}")
            } else if v.abs() > LARGEST {
                format!(
                    "{name} = {v:e} is beyond ±{LARGEST:e}, the largest magnitude a table's \
                     spline computes with"
                )
            } else {
                continue;
            };
            return Err(point_error(cx, field, at, cell, problem));
        }
    }
    Ok(())
}

/// A closed table's second column ends where it starts: the last row's value is the first
/// one's, within [`CLOSURE_TOLERANCE`] of the column's largest magnitude (the runtime's
/// rule). A table written with ten significant digits or more (CAD exports, `camchain cam
/// --table`, which writes every number to the last bit) closes far within it, and a table
/// that lost its closing row misses it by the profile's change over one step, unless the
/// profile dwells there: its angle or length then tells ([`one_turn`], [`curve_closes`]).
fn closes(cx: &Context, field: &str, points: &Points, what: &str) -> Checked<()> {
    let n = points.values.len();
    if n < 2 {
        return Ok(());
    }
    let name = points.names[1];
    let (first, last) = (points.values[0][1], points.values[n - 1][1]);
    let scale = points.values.iter().fold(0.0f64, |m, p| m.max(p[1].abs()));
    let difference = (last - first).abs();
    if difference <= CLOSURE_TOLERANCE * scale.max(f64::MIN_POSITIVE) {
        return Ok(());
    }
    Err(point_error(
        cx,
        field,
        &points.at[n - 1],
        1,
        format!(
            "{what} is closed: its last row repeats the first one's {name} one period later, \
             but {name} is {last} here and {first} on {} (difference {difference:.3e}, more \
             than {CLOSURE_TOLERANCE:e} of the largest |{name}|, {scale}); is the closing row \
             missing?",
            points.at[0].described()
        ),
    ))
}

/// A closed curve's last point is its first, within [`CLOSURE_TOLERANCE`] of the table's
/// largest coordinate (see [`closes`]); a curve that lost its closing row misses it by a
/// whole chord.
fn curve_closes(cx: &Context, field: &str, points: &Points) -> Checked<()> {
    let n = points.values.len();
    if n < 2 {
        return Ok(());
    }
    let (a, b) = (points.values[0], points.values[n - 1]);
    let size = points
        .values
        .iter()
        .fold(0.0f64, |m, p| m.max(p[0].abs()).max(p[1].abs()));
    let gap = (a[0] - b[0]).hypot(a[1] - b[1]);
    if gap <= CLOSURE_TOLERANCE * size.max(f64::MIN_POSITIVE) {
        return Ok(());
    }
    Err(point_error(
        cx,
        field,
        &points.at[n - 1],
        0,
        format!(
            "a parametric table is a closed curve unless declared open, and its last point \
             ({}, {}) must repeat its first ({}, {}) on {}, but they are {gap:.3e} m apart \
             (more than {CLOSURE_TOLERANCE:e} of its largest coordinate, {size} m): add the \
             first point again as the last row, or declare an open curve with `ends: Natural`",
            b[0],
            b[1],
            a[0],
            a[1],
            points.at[0].described()
        ),
    ))
}

/// The spline through (x, y), its errors located at the point (and cell) they concern; a
/// spline whose solve overflowed (points too close for their values) is refused at the
/// first knot it could not compute.
fn spline(
    cx: &Context,
    field: &str,
    points: &Points,
    x: &[f64],
    y: &[f64],
    ends: Ends,
) -> Checked<Spline> {
    let spline = Spline::new(x, y, ends).map_err(|e| {
        let (point, cell, message) = match &e {
            SplineError::NotIncreasing {
                index,
                value,
                previous,
            } => {
                let name = points.names[0];
                let message = format!(
                    "the {name} column must increase strictly, but {name} = {value} here does \
                     not exceed {previous} on {}",
                    points.at[index - 1].described()
                );
                (Some(*index), 0, message)
            }
            SplineError::NotFinite { index, .. } => (Some(*index), 0, e.to_string()),
            SplineError::EndsDoNotMeet { .. } => (Some(x.len() - 1), 1, e.to_string()),
            SplineError::TooFewPoints { .. } | SplineError::LengthMismatch { .. } => {
                (None, 0, e.to_string())
            }
        };
        match point.and_then(|k| points.at.get(k)) {
            Some(at) => point_error(cx, field, at, cell, message),
            None => cx.at.error(field, message),
        }
    })?;
    let overflow = spline.knot_curvatures().iter().position(|m| !m.is_finite());
    match overflow.and_then(|k| points.at.get(k)) {
        Some(at) => Err(point_error(
            cx,
            field,
            at,
            0,
            "the spline's curvature overflows at this point: its neighbours are too close for \
             the change of value between them"
                .to_string(),
        )),
        None => Ok(spline),
    }
}

/// A polar table covers exactly one turn: its last angle is the first plus 2π (360°).
fn one_turn(
    cx: &Context,
    field: &str,
    points: &Points,
    theta: &[f64],
    degrees: bool,
) -> Checked<()> {
    if theta.len() < 2 {
        return Ok(());
    }
    let span = theta[theta.len() - 1] - theta[0];
    if (span - TAU).abs() <= CLOSURE_TOLERANCE * TAU {
        return Ok(());
    }
    let (shown, turn) = if degrees {
        (span.to_degrees(), "360°")
    } else {
        (span, "2π rad")
    };
    let last = points.at.len() - 1;
    Err(point_error(
        cx,
        field,
        &points.at[last],
        0,
        format!(
            "a polar table covers one turn, its last point repeating the first {turn} later, \
             but its angles span {shown}{}{}",
            if degrees { "°" } else { " rad" },
            if span < TAU {
                " (is the closing row missing?)"
            } else {
                ""
            }
        ),
    ))
}

/// The table's points, from the model file or from its CSV file.
fn points(
    cx: &Context,
    field: &str,
    table: &raw::Table,
    names: [&'static str; 2],
) -> Checked<Points> {
    match (&table.points, &table.file) {
        (Some(points), None) => Ok(Points {
            values: points.iter().map(|&(a, b)| [a, b]).collect(),
            at: (0..points.len()).map(At::Inline).collect(),
            names,
            from: None,
        }),
        (None, Some(written)) => {
            let (text, shown) = read_file(cx, &format!("{field}.file"), written)?;
            let rows = csv::read(&text, names).map_err(|e| ModelError {
                file: shown.clone(),
                line: e.line,
                column: e.column,
                field: format!("{field}.file"),
                message: e.message,
            })?;
            Ok(Points {
                values: rows.iter().map(|r| r.values).collect(),
                at: rows
                    .iter()
                    .map(|r| At::File {
                        file: shown.clone(),
                        line: r.line,
                        columns: r.columns,
                    })
                    .collect(),
                names,
                from: Some(written.clone()),
            })
        }
        _ => Err(cx.at.error(
            field,
            "a table gives its points either in the file (`points: [(x, y), …]`) or in a CSV \
             file (`file: \"cam.csv\"`, relative to the model file): exactly one of them",
        )),
    }
}

/// An error about one point of a table: at `points[k]` in the model file, or at the line
/// and the column of its cell `cell` (0 or 1) in a table file.
fn point_error(cx: &Context, field: &str, at: &At, cell: usize, message: String) -> ModelError {
    match at {
        At::Inline(k) => cx.at.error(&format!("{field}.points[{k}]"), message),
        At::File {
            file,
            line,
            columns,
        } => ModelError {
            file: file.clone(),
            line: *line,
            column: columns[cell.min(1)],
            field: format!("{field}.file"),
            message,
        },
    }
}
