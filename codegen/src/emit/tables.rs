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
    out
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
