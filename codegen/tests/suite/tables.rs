//! Tables of points read from CSV files: a closed table must close (its last row repeating
//! the first one's value one period later) or be declared open, and every problem in a table
//! file is reported at the line and the column of the cell it concerns, counted in the file
//! as an editor counts them (comment, header and blank lines included).
//!
//! The models are `models/table_cam.ron` (a closed parametric table, the cam of
//! `cycloidal_roller`) with its table given as text (`Files::Embedded`), checked as the
//! command line checks a file (`check_source_in`: validation and assembly). Expected lines
//! and columns are counted off the texts written here.

use camchain_codegen::schema::Files;
use camchain_codegen::{ModelError, check_source_in};
use std::path::Path;

/// The model file's text with its table `table: (…)` replaced by `table`.
fn table_cam(table: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../models/table_cam.ron");
    let source = std::fs::read_to_string(path).expect("models/table_cam.ron");
    let written = "table: (form: Parametric, file: \"tables/cycloidal_roller_profile.csv\"),";
    assert!(source.contains(written), "table_cam's table changed");
    source.replace(written, table)
}

/// `table_cam` with its table read from `csv` (as `t.csv`) by `table`.
fn check(table: &str, csv: &str) -> Result<camchain_codegen::Model, ModelError> {
    let files = [("t.csv", csv)];
    check_source_in(
        &table_cam(table),
        Path::new("models/table_cam.ron"),
        Files::Embedded(&files),
    )
}

/// The error of a table that must be refused.
fn refused(table: &str, csv: &str) -> ModelError {
    match check(table, csv) {
        Ok(_) => panic!("the table was accepted:\n{csv}"),
        Err(e) => e,
    }
}

fn assert_at(e: &ModelError, line: usize, column: usize, phrases: &[&str]) {
    assert_eq!(
        (e.file.as_path(), e.line, e.column, e.field.as_str()),
        (
            Path::new("models/t.csv"),
            line,
            column,
            "contacts[0].table.file"
        ),
        "{e}"
    );
    for phrase in phrases {
        assert!(e.message.contains(phrase), "`{phrase}` not in: {e}");
    }
}

/// The table of `table_cam`: 2 comment lines, the header, then 721 points (720 and the
/// first again), lines 4 to 724.
fn profile_csv() -> String {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../models/tables/cycloidal_roller_profile.csv");
    std::fs::read_to_string(path).expect("the table_cam's table")
}

const PARAMETRIC: &str = "table: (form: Parametric, file: \"t.csv\"),";

/// The hostile tester's case: table_cam's table with its closing row removed used to become
/// an open curve, on which the roller assembled at a lift of 0.0275 m, inside the 0.04 m base
/// circle. A parametric table is closed unless declared open: the table is refused at its
/// last row (line 723), naming both points; declared open (`ends: Natural`) it is accepted.
#[test]
fn a_closed_table_without_its_closing_row_is_refused_at_its_last_row() {
    let text = profile_csv();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 724, "2 comments, a header and 721 points");
    assert_eq!(lines[3], lines[723], "the last row repeats the first");
    let without = lines[..723].join("\n") + "\n";
    let e = refused(PARAMETRIC, &without);
    // The first point is written `0.0,0.04000000000000001` on line 4.
    assert_at(
        &e,
        723,
        1,
        &[
            "must repeat its first (0, 0.04000000000000001) on line 4",
            "declare an open curve with `ends: Natural`",
        ],
    );
    let open = "table: (form: Parametric, file: \"t.csv\", ends: Natural),";
    let model = check(open, &without).unwrap_or_else(|e| panic!("declared open: {e}"));
    assert!(
        format!("{:?}", model.contacts[0].profile).contains("an open curve"),
        "declared open, the curve is open"
    );
    // With its closing row the table is the closed curve, as before.
    check(PARAMETRIC, &text).unwrap_or_else(|e| panic!("the closed table: {e}"));
    // Declared closed (`ends: Periodic`) without the row: the same error.
    let closed = "table: (form: Parametric, file: \"t.csv\", ends: Periodic),";
    assert_at(&refused(closed, &without), 723, 1, &["line 4"]);
}

/// A polar table missing its closing row: its angles do not span a turn, refused at the
/// last row's θ cell; with the row but another radius, refused at the last row's r cell,
/// naming both radii and the line of the first.
#[test]
fn a_polar_table_that_does_not_close_is_refused_at_its_last_row() {
    let polar = "table: (form: Polar, degrees: true, file: \"t.csv\"),";
    // A circle of radius 0.05 about the camshaft's axis, every 45°.
    let mut rows: Vec<String> = (0..8).map(|k| format!("{}, 0.05", 45 * k)).collect();
    let csv = |rows: &[String]| format!("theta,r\n# degrees\n{}\n", rows.join("\n"));
    let e = refused(polar, &csv(&rows));
    // Header, comment, 8 rows: the last, `315, 0.05`, on line 10.
    assert_at(&e, 10, 1, &["span 315°", "is the closing row missing?"]);
    rows.push("360, 0.0501".to_string());
    let e = refused(polar, &csv(&rows));
    // `360, 0.0501` on line 11, its r cell at column 6.
    assert_at(&e, 11, 6, &["r is 0.0501 here and 0.05 on line 3"]);
    rows.pop();
    rows.push("360, 0.05".to_string());
    check(polar, &csv(&rows)).unwrap_or_else(|e| panic!("the closed table: {e}"));
}

/// An explicit table declared periodic must close as well: its error names the point of the
/// model file.
#[test]
fn a_periodic_explicit_table_that_does_not_close_is_refused_at_its_last_point() {
    let source = table_cam(
        "table: (form: Explicit, ends: Periodic, points: [(0.0, 0.05), (0.1, 0.06), (0.2, \
         0.055), (0.3, 0.051)]),",
    );
    let e = check_source_in(
        &source,
        Path::new("models/table_cam.ron"),
        Files::Embedded(&[]),
    )
    .expect_err("the table does not close");
    assert_eq!(e.field, "contacts[0].table.points[3]", "{e}");
    assert!(
        e.message.contains("y is 0.051 here and 0.05 on points[0]"),
        "{e}"
    );
}

/// One corrupted row of a closed 9-row table (a circle every 45°, the first again last),
/// at a given line, and where its error must point.
struct Corrupt {
    /// The row's text.
    row: &'static str,
    /// The error's column and a phrase of its message.
    column: usize,
    phrase: &'static str,
}

/// Every kind of bad cell, on every kind of line (the first point, after comments, blank
/// lines and a header, the last, with Windows line ends): the error names the line and the
/// column the cell starts at. A number beyond ±1e100 (the spline's arithmetic limit) was
/// accepted and overflowed in the chord lengths, reported at the wrong line and column as
/// "point 720".
#[test]
fn table_csv_errors_name_the_line_and_column_of_the_cell() {
    let cases = [
        Corrupt {
            row: "0.001, 1e308",
            column: 8,
            phrase: "y = 1e308 is beyond ±1e100",
        },
        Corrupt {
            row: "  -1e150 ; 0.04",
            column: 3,
            phrase: "x = -1e150 is beyond ±1e100",
        },
        Corrupt {
            row: "0.02,1e400",
            column: 6,
            phrase: "y must be a finite number, not `1e400`",
        },
        Corrupt {
            row: "NaN,0.04",
            column: 1,
            phrase: "x must be a finite number, not `NaN`",
        },
        Corrupt {
            row: "0.02;abc",
            column: 6,
            phrase: "`abc` is not a number (y)",
        },
        Corrupt {
            row: "0.02,",
            column: 6,
            phrase: "the y cell is empty",
        },
        Corrupt {
            row: "0.02",
            column: 1,
            phrase: "this one has 1 cell",
        },
    ];
    let points: Vec<String> = (0..=8)
        .map(|k| {
            let angle = std::f64::consts::FRAC_PI_4 * f64::from(k % 8);
            format!("{:?},{:?}", 0.04 * angle.cos(), 0.04 * angle.sin())
        })
        .collect();
    // Line by line: comment, header, blank, point 0 (line 4), comment, points 1–3
    // (lines 6–8), blank, points 4–8 (lines 10–14).
    let layout = |points: &[String]| {
        let mut lines = vec!["# a circle".to_string(), "x, y".to_string(), String::new()];
        lines.push(points[0].clone());
        lines.push("# every 45°".to_string());
        lines.extend(points[1..4].iter().cloned());
        lines.push(String::new());
        lines.extend(points[4..].iter().cloned());
        lines
    };
    let clean = layout(&points).join("\n");
    check(PARAMETRIC, &clean).unwrap_or_else(|e| panic!("the clean table: {e}"));
    for (point, line) in [(0, 4), (1, 6), (3, 8), (4, 10), (8, 14)] {
        for case in &cases {
            let mut corrupted = points.clone();
            corrupted[point] = case.row.to_string();
            for end in ["\n", "\r\n"] {
                let csv = layout(&corrupted).join(end);
                let e = refused(PARAMETRIC, &csv);
                assert_at(&e, line, case.column, &[case.phrase]);
            }
        }
    }
}

/// The hostile tester's file: table_cam's own table with the second point's y (line 5)
/// written 1e308, once reported at 4:1 as "point 720".
#[test]
fn a_huge_number_in_table_cams_table_is_reported_at_its_cell() {
    let text = profile_csv();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    // Line 5 is `0.0003490614199349575,0.03999847692256686`: its y cell starts at column 23.
    assert!(
        lines[4].starts_with("0.0003490614199349575,"),
        "{}",
        lines[4]
    );
    lines[4] = "0.0003490614199349575,1e308".to_string();
    let e = refused(PARAMETRIC, &lines.join("\n"));
    assert_at(&e, 5, 23, &["y = 1e308 is beyond ±1e100"]);
}

/// Numbers within bounds can still overflow the spline when two abscissas are a subnormal
/// step apart (the slope between them is infinite): refused at the first point whose
/// curvature could not be computed, not carried into the run as infinities.
#[test]
fn a_spline_that_overflows_is_refused_at_its_point() {
    let source = table_cam(
        "table: (form: Explicit, points: [(0.0, 0.05), (5e-324, 0.06), (0.1, 0.05), (0.2, \
         0.05)]),",
    );
    let e = check_source_in(
        &source,
        Path::new("models/table_cam.ron"),
        Files::Embedded(&[]),
    )
    .expect_err("the spline overflows");
    assert!(
        e.field.starts_with("contacts[0].table.points["),
        "located at a point: {e}"
    );
    assert!(e.message.contains("curvature overflows"), "{e}");
}
