//! Tabulated functions (a spline through a table of points, a motion law) as constants and
//! an evaluation function calling the runtime.

use super::literals::{ALLOW_LITERALS, float_list, lit};
use crate::expr::Graph;
use crate::profile::TabulatedFunction;

/// Every tabulated function of the graph as constants and a function `eval_<name>(s)` returning
/// its value and first three derivatives at s: a spline's table (abscissas, values and the
/// second derivatives at the knots, computed at build time) for
/// `camchain_runtime::spline::evaluate`, or a motion law's segments for
/// `camchain_runtime::motion_law::evaluate`.
pub(super) fn table_helpers(g: &Graph) -> String {
    let mut out = String::new();
    for table in g.tables() {
        let text = match &table.function {
            TabulatedFunction::Spline(spline) => spline_helper(&table.name, spline),
            TabulatedFunction::Law(program) => law_helper(&table.name, program),
        };
        out.push_str(&text);
    }
    for grid in g.grids() {
        out.push_str(&grid_helper(&grid.name, &grid.spline));
    }
    out
}

/// The constants and the evaluation function of a spline surface named `name`: its knots,
/// values and knot derivatives (computed at build time) for
/// `camchain_runtime::surface_spline::partials`.
pub(super) fn grid_helper(
    name: &str,
    surface: &camchain_runtime::surface_spline::SurfaceSpline,
) -> String {
    let upper = name.to_uppercase();
    let (nx, ny) = surface.shape();
    let n = nx * ny;
    let periodic = surface.is_periodic();
    let array = |suffix: &str, what: &str, len: usize, values: &[f64]| {
        format!(
            "/// {name}: {what}.\n{ALLOW_LITERALS}\nconst {upper}_{suffix}: [f64; {len}] = {};\n",
            float_list(values)
        )
    };
    let axis = |p: bool| {
        if p {
            "periodic"
        } else {
            "open, its end cells' cubics continuing beyond the grid"
        }
    };
    format!(
        "{}{}{}{}{}{}\
         /// {name}: a C² bicubic spline surface through a {nx} × {ny} grid (x {}; y {}).\n\
         const {upper}: rt::surface_spline::SurfaceTable<'static> = \
         rt::surface_spline::SurfaceTable {{ x: &{upper}_X, y: &{upper}_Y, z: &{upper}_Z, \
         mx: &{upper}_MX, my: &{upper}_MY, mxy: &{upper}_MXY, periodic: [{}, {}] }};\n\
         /// {name}: ∂ᵖ_x ∂ᵠ_y at (x, y) as `[p][q]`, p, q ≤ 3.\n\
         #[inline]\n\
         fn eval_{name}(x: f64, y: f64) -> [[f64; 4]; 4] {{\n\
         rt::surface_spline::partials(&{upper}, x, y)\n}}\n",
        array("X", "the x knots", nx, surface.x_knots()),
        array("Y", "the y knots", ny, surface.y_knots()),
        array(
            "Z",
            "the values z(x_i, y_j), row i after row",
            n,
            surface.values()
        ),
        array("MX", "∂²z/∂x² at the knots", n, surface.knot_curvatures_x()),
        array("MY", "∂²z/∂y² at the knots", n, surface.knot_curvatures_y()),
        array(
            "MXY",
            "∂⁴z/∂x²∂y² at the knots",
            n,
            surface.knot_cross_curvatures()
        ),
        axis(periodic[0]),
        axis(periodic[1]),
        periodic[0],
        periodic[1],
    )
}

/// The constants and the evaluation function of a spline named `name`.
pub(super) fn spline_helper(name: &str, spline: &camchain_runtime::spline::Spline) -> String {
    let upper = name.to_uppercase();
    let n = spline.abscissas().len();
    format!(
        "/// {name}: the table's abscissas, values and second derivatives at the knots.\n\
         {ALLOW_LITERALS}\n\
         const {upper}_X: [f64; {n}] = {};\n\
         {ALLOW_LITERALS}\n\
         const {upper}_Y: [f64; {n}] = {};\n\
         {ALLOW_LITERALS}\n\
         const {upper}_M: [f64; {n}] = {};\n\
         /// {name}: the spline and its first three derivatives at s ({}).\n\
         #[inline]\n\
         fn eval_{name}(s: f64) -> [f64; 4] {{\n\
         rt::spline::evaluate(&{upper}_X, &{upper}_Y, &{upper}_M, {}, s)\n}}\n",
        float_list(spline.abscissas()),
        float_list(spline.values()),
        float_list(spline.knot_curvatures()),
        if spline.is_periodic() {
            "periodic: repeats every period"
        } else {
            "open: its end cubics continue beyond the table"
        },
        spline.is_periodic(),
    )
}

/// The segments and the evaluation function of a motion law named `name`.
pub(super) fn law_helper(
    name: &str,
    program: &camchain_runtime::motion_law::MotionProgram,
) -> String {
    let upper = name.to_uppercase();
    let segments: Vec<String> = program
        .segments()
        .iter()
        .map(|s| {
            format!(
                "rt::motion_law::Segment {{ law: rt::motion_law::Law::{:?}, angle: {}, lift: {} }}",
                s.law,
                lit(s.angle),
                lit(s.lift)
            )
        })
        .collect();
    format!(
        "/// {name}: the follower's motion law, segment by segment (its law, the cam angle it \
         takes in rad, the lift at its end).\n\
         {ALLOW_LITERALS}\n\
         const {upper}: [rt::motion_law::Segment; {}] = [{}];\n\
         /// {name}: the follower's displacement and its first three derivatives with respect \
         to the cam's angle at theta (repeats every turn).\n\
         #[inline]\n\
         fn eval_{name}(theta: f64) -> [f64; 4] {{\n\
         rt::motion_law::evaluate(&{upper}, theta)\n}}\n",
        segments.len(),
        segments.join(", "),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use camchain_runtime::motion_law::{Law, MotionProgram, Segment};
    use camchain_runtime::spline::{Ends, Spline};
    use std::f64::consts::PI;

    #[test]
    fn a_spline_is_its_knots_values_and_second_derivatives() {
        // Natural ends through (0, 0), (1, 1), (2, 0): M0 = M2 = 0 and
        // M0 + 4 M1 + M2 = 6 (y0 − 2 y1 + y2) / h² = −12, so M1 = −3.
        let spline = Spline::new(&[0.0, 1.0, 2.0], &[0.0, 1.0, 0.0], Ends::Natural);
        let text = spline_helper("cam", &spline.expect("a valid table"));
        assert!(text.contains("const CAM_X: [f64; 3] = [0.0, 1.0, 2.0];"));
        assert!(text.contains("const CAM_Y: [f64; 3] = [0.0, 1.0, 0.0];"));
        assert!(
            text.contains("const CAM_M: [f64; 3] = [0.0, -3.0, 0.0];"),
            "{text}"
        );
        assert!(text.contains("fn eval_cam(s: f64) -> [f64; 4] {\nrt::spline::evaluate(&CAM_X, &CAM_Y, &CAM_M, false, s)\n}"));
        assert!(text.contains("open: its end cubics continue"));
    }

    #[test]
    fn a_motion_law_is_its_segments() {
        let cycloidal = |lift| Segment {
            law: Law::Cycloidal,
            angle: PI,
            lift,
        };
        let program =
            MotionProgram::new(&[cycloidal(0.01), cycloidal(0.0)]).expect("a rise and a return");
        let text = law_helper("lift", &program);
        assert!(
            text.contains(
                "const LIFT: [rt::motion_law::Segment; 2] = [rt::motion_law::Segment { law: \
             rt::motion_law::Law::Cycloidal, angle: 3.141592653589793, lift: 0.01 }, \
             rt::motion_law::Segment { law: rt::motion_law::Law::Cycloidal, angle: \
             3.141592653589793, lift: 0.0 }];"
            ),
            "{text}"
        );
        assert!(text.contains("rt::motion_law::evaluate(&LIFT, theta)"));
    }

    #[test]
    fn a_graph_without_tables_has_no_helper() {
        assert_eq!(table_helpers(&Graph::new()), "");
    }
}
