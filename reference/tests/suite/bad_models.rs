//! The bad-model corpus: every file of `tests/bad_models/` is a valid model with one defect,
//! named in its first comment line; its second says which model it derives from:
//! `models/paper_concave.ron`, `driven_concave.ron`, `spatial_arm.ron`, or one of the models
//! of cams on moving bodies, `eccentric_roller.ron`, `eccentric_flat.ron`, `rocker_roller.ron`,
//! `camshaft_flywheel.ron` and `paper_rotating.ron`, or `four_bar.ron` for loops (a defect that needs two contacts adds a
//! second roller under the cam of `eccentric_roller` or `camshaft_flywheel`, otherwise valid).
//! The loader the build uses
//! (`camchain_codegen::generate_file`) must reject each with an error that names the file,
//! the line and column of the defect, the dotted field path and the problem; the numeric
//! reference (`NumericModel::load`, what `camchain simulate file.ron` runs) must reject it
//! too, without panicking.
//!
//! The expected positions below were read off the files (the text each error must point
//! at is given in the comment of its row), not taken from the loader's output.

use camchain_reference::NumericModel;
use camchain_runtime::Simulate;
use std::collections::BTreeSet;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};

/// Where the numeric reference notices the defect.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Reference {
    /// `NumericModel::load` fails with the loader's error (same line, column and field).
    Load,
    /// The file is valid as a description and loads; assembling the initial state onto the
    /// cam fails (the build checks this, the reference when a run starts).
    Assemble,
    /// Only the build rejects the file: what is wrong matters to the generated code alone
    /// (a model name that is no Rust identifier names no module on the numeric path), so the
    /// reference loads and assembles it.
    Accept,
}

/// What the error for one corpus file must say.
struct Case {
    /// File name in `tests/bad_models/`.
    file: &'static str,
    /// 1-based line and column of the defect.
    line: usize,
    column: usize,
    /// Dotted field path.
    field: &'static str,
    /// A phrase the message must contain.
    phrase: &'static str,
    reference: Reference,
    /// The file the error points into when it is not the model file: a table of points the
    /// model names (relative to `tests/bad_models/`).
    located: Option<&'static str>,
}

const fn case(
    file: &'static str,
    line: usize,
    column: usize,
    field: &'static str,
    phrase: &'static str,
) -> Case {
    Case {
        file,
        line,
        column,
        field,
        phrase,
        reference: Reference::Load,
        located: None,
    }
}

/// One row per corpus file, alphabetical within each group. Comments say what the position
/// points at.
const CASES: &[Case] = &[
    // `"ground"`, the first body's name.
    case(
        "body_named_ground.ron",
        9,
        19,
        "bodies[0].name",
        "reserved for the fixed base",
    ),
    // The y_axis tuple `(0.6, 0.6, 0.8)`.
    case(
        "cam_axes_not_orthogonal.ron",
        86,
        82,
        "contacts[0].frame.y_axis",
        "must be orthogonal",
    ),
    // `"disc"` after `cam_body:`.
    case(
        "cam_body_unknown.ron",
        122,
        23,
        "contacts[0].cam_body",
        "unknown body `disc`",
    ),
    // `"type"` after the contact's `name:`.
    case(
        "contact_name_keyword.ron",
        120,
        19,
        "contacts[0].name",
        "contact name `type` is not a valid Rust identifier",
    ),
    // `"roller"` after the contact's `marker:` (the contact is named after its marker).
    case(
        "contact_name_taken.ron",
        45,
        21,
        "contacts[0].marker",
        "clashes with coordinate `roller_parameter`",
    ),
    // `"roller"`, the second contact's name.
    case(
        "contact_names_differ_in_case.ron",
        65,
        19,
        "contacts[1].name",
        "differs from `Roller` (contacts[0]) only in letter case",
    ),
    // `"B"` after `marker:`.
    case(
        "contact_on_unknown_marker.ron",
        68,
        18,
        "contacts[0].marker",
        "unknown marker `B`",
    ),
    // The follower's `coordinate: "cam_angle_dot"`.
    case(
        "coordinate_named_like_a_velocity.ron",
        41,
        29,
        "bodies[1].joint.coordinate",
        "taken by the velocity of coordinate `cam_angle`",
    ),
    // The rocker's `coordinate: "t"`.
    case(
        "coordinate_named_t.ron",
        35,
        29,
        "bodies[1].joint.coordinate",
        "`t` already means something in expressions",
    ),
    // The second `"body3"` name (the fourth body's).
    case(
        "duplicate_body_name.ron",
        50,
        19,
        "bodies[3].name",
        "duplicate body name `body3`",
    ),
    // The second `"cam_follower"`.
    case(
        "duplicate_contact_name.ron",
        65,
        19,
        "contacts[1].name",
        "duplicate contact name `cam_follower` (contacts[0])",
    ),
    // body4's `coordinate: "q3"`.
    case(
        "duplicate_coordinate.ron",
        59,
        29,
        "bodies[3].joint.coordinate",
        "duplicate coordinate `q3`",
    ),
    // The normal `(0.0, -1.0, 0.1)`.
    case(
        "flat_face_normal_out_of_plane.ron",
        44,
        36,
        "contacts[0].follower.normal",
        "must lie in the cam plane",
    ),
    // `Flat(` after `follower:`.
    case(
        "flat_face_on_hollow_profile.ron",
        44,
        23,
        "contacts[0].follower",
        "a flat face needs a strictly convex profile, but at theta = 3.141593 the profile is hollow",
    ),
    // `Flat(` after `follower:`.
    case(
        "flat_face_tilted_camshaft.ron",
        44,
        23,
        "contacts[0].follower",
        "but joint `cam_angle` between them turns about",
    ),
    // `[]` after `bodies:`.
    case("empty_body_list.ron", 7, 13, "bodies", "at least one body"),
    // The second `"q2"` of the hold list.
    case(
        "hold_coordinate_twice.ron",
        72,
        28,
        "initial.hold[2]",
        "`q2` is listed twice",
    ),
    // `inf` after `ixz:` on upper_arm's inertia line.
    case(
        "inertia_inf_product.ron",
        27,
        93,
        "bodies[1].inertia.ixz",
        "must be finite, got inf",
    ),
    // `Full(` of upper_arm's inertia.
    case(
        "inertia_not_positive_definite.ron",
        27,
        22,
        "bodies[1].inertia",
        "must be positive definite",
    ),
    // `Full(` of the turret's inertia.
    case(
        "inertia_triangle_inequality.ron",
        13,
        22,
        "bodies[0].inertia",
        "violate the triangle inequality",
    ),
    // `-inf`, the forearm anchor's z.
    case(
        "inf_anchor.ron",
        45,
        36,
        "bodies[2].joint.anchor[2]",
        "must be finite, got -inf",
    ),
    // `-inf`, gravity's y.
    case(
        "inf_gravity.ron",
        6,
        20,
        "gravity[1]",
        "must be finite, got -inf",
    ),
    // The second `"q1"` key of `initial.q`.
    case(
        "initial_coordinate_twice.ron",
        71,
        62,
        "initial.q[\"q1\"]",
        "`q1` is given twice",
    ),
    // The key `"q5"`.
    case(
        "initial_unknown_coordinate.ron",
        71,
        62,
        "initial.q[\"q5\"]",
        "unknown coordinate `q5`",
    ),
    // `"paper concave"`: a module cannot be named so; the numeric path runs it.
    Case {
        reference: Reference::Accept,
        ..case(
            "invalid_model_name.ron",
            4,
            11,
            "name",
            "not a valid Rust identifier",
        )
    },
    // `"-0.01*cam_angle_dot"` after `load:`.
    case(
        "load_on_prescribed_joint.ron",
        24,
        114,
        "bodies[0].joint.load",
        "a prescribed joint cannot also have a load",
    ),
    // `cam_speed` inside the load's string.
    case(
        "load_unknown_variable.ron",
        29,
        38,
        "bodies[0].joint.load",
        "unknown name `cam_speed`: a load is an expression of the time `t`, the coordinates (cam_angle, lift)",
    ),
    // The `)` right after `cam_angle_dot/`, where the divisor is missing.
    case(
        "load_unparsable.ron",
        29,
        52,
        "bodies[0].joint.load",
        "not a valid expression",
    ),
    // `"body5"` after `body:`.
    case(
        "marker_on_unknown_body.ron",
        65,
        27,
        "markers[0].body",
        "unknown body `body5`",
    ),
    // The `(` after `joint:` of body3, the joint that lacks its axis.
    case(
        "missing_axis.ron",
        42,
        20,
        "bodies[2].joint.axis",
        "missing field named `axis`",
    ),
    // The `(` opening body2, the body that lacks its mass.
    case(
        "missing_mass.ron",
        21,
        9,
        "bodies[1].mass",
        "missing field named `mass`",
    ),
    // `NaN` in the tool's axis.
    case(
        "nan_axis.ron",
        72,
        29,
        "bodies[4].joint.axis[1]",
        "must be finite, got NaN",
    ),
    // `NaN` in upper_arm's centre of mass.
    case(
        "nan_com.ron",
        26,
        24,
        "bodies[1].com[1]",
        "must be finite, got NaN",
    ),
    // `1e308` after `mass:`.
    case(
        "huge_mass.ron",
        24,
        19,
        "bodies[1].mass",
        "mass = 1e308 is outside 1e-100 … 1e100",
    ),
    // `NaN` after `mass:`.
    case(
        "nan_mass.ron",
        24,
        19,
        "bodies[1].mass",
        "mass must be positive and finite, got NaN",
    ),
    // `-0.5` after `damping:`.
    case(
        "negative_damping.ron",
        19,
        35,
        "bodies[0].joint.spring.damping",
        "damping must be non-negative",
    ),
    // `Izz(-0.01)`.
    case(
        "negative_inertia.ron",
        26,
        22,
        "bodies[1].inertia",
        "must be positive definite",
    ),
    // `-2.0` after `mass:`.
    case(
        "negative_mass.ron",
        25,
        19,
        "bodies[1].mass",
        "mass must be positive and finite",
    ),
    // `-40.0` after `stiffness:`.
    case(
        "negative_stiffness.ron",
        46,
        37,
        "bodies[2].joint.spring.stiffness",
        "stiffness must be non-negative",
    ),
    // `-10.0` after `t_end:`.
    case(
        "negative_t_end.ron",
        74,
        25,
        "simulation.t_end",
        "t_end must be positive",
    ),
    // The second `"k2"`.
    case(
        "parameter_duplicate.ron",
        32,
        16,
        "parameters[19].name",
        "duplicate parameter name `k2`",
    ),
    // `"l1/(l2 - 0.1)"`: 0.3/0.
    case(
        "parameter_expression_infinite.ron",
        45,
        19,
        "bodies[0].com[0]",
        "must be finite, got inf",
    ),
    // The end of `"l1/"`, where the divisor is missing.
    case(
        "parameter_expression_syntax.ron",
        45,
        23,
        "bodies[0].com[0]",
        "not a valid expression",
    ),
    // `"k2"`, the first component of body3's axis.
    case(
        "parameter_in_axis.ron",
        76,
        24,
        "bodies[2].joint.axis[0]",
        "this field must be constant, but k2 is read at run time",
    ),
    // `-1.0` after `max:`.
    case(
        "parameter_min_above_max.ron",
        37,
        65,
        "parameters[24].max",
        "the maximum -1 is below the minimum 1",
    ),
    // `"q3"`, the last parameter's name.
    case(
        "parameter_named_like_coordinate.ron",
        37,
        16,
        "parameters[24].name",
        "is taken by coordinate `q3`",
    ),
    // `"m2 - 1.0"` = -0.5.
    case(
        "parameter_negative_mass.ron",
        57,
        19,
        "bodies[1].mass",
        "mass must be positive and finite, got -0.5",
    ),
    // `"x"`, the last parameter's name.
    case(
        "parameter_reserved_name.ron",
        37,
        16,
        "parameters[24].name",
        "`x` already means something in expressions",
    ),
    // `m2` inside the string after `mass:`.
    case(
        "parameter_undeclared.ron",
        24,
        20,
        "bodies[1].mass",
        "unknown name `m2`: the model declares no parameters",
    ),
    // `-40.0`, k3's value.
    case(
        "parameter_value_below_min.ron",
        32,
        29,
        "parameters[19].value",
        "its value is below the minimum 0 declared for `k3`",
    ),
    // body1's `parent: "body4"`.
    case(
        "parent_cycle.ron",
        10,
        21,
        "bodies[0].parent",
        "cycle: body1 -> body4 -> body3 -> body2 -> body1",
    ),
    // The opening quote of `"r0 + h*theta/(2.0*PI)"`.
    case(
        "polar_not_closed.ron",
        49,
        20,
        "contacts[0].polar",
        "a polar profile must close on itself",
    ),
    // The opening quote of `"r0 - 3.0*h*(1.0 - theta.cos())"`.
    case(
        "polar_radius_not_positive.ron",
        49,
        20,
        "contacts[0].polar",
        "the polar radius must be positive over the cam, but r(theta = 1.8",
    ),
    // `loop` inside the drive's string.
    case(
        "prescribed_loop.ron",
        19,
        38,
        "bodies[0].joint.prescribed",
        "control flow is not allowed",
    ),
    // The `x` of `2.0*PI*x`.
    case(
        "prescribed_wrong_variable.ron",
        19,
        51,
        "bodies[0].joint.prescribed",
        "the only variable allowed here is `t`",
    ),
    // The `|` opening the closure.
    case(
        "profile_closure.ron",
        68,
        55,
        "contacts[0].profile",
        "closures are not allowed",
    ),
    // The divisor `(1.0 - 1.0)`.
    case(
        "profile_division_by_zero.ron",
        68,
        62,
        "contacts[0].profile",
        "division by zero",
    ),
    // `panic!()`.
    case(
        "profile_macro.ron",
        68,
        54,
        "contacts[0].profile",
        "macros are not allowed",
    ),
    // `(-1.0).sqrt()`.
    case(
        "profile_nan_constant.ron",
        68,
        54,
        "contacts[0].profile",
        "evaluates to NaN",
    ),
    // The 33rd of the 40 nested `(`.
    case(
        "profile_nested_too_deeply.ron",
        68,
        90,
        "contacts[0].profile",
        "nested too deeply",
    ),
    // `std::process::exit`.
    case(
        "profile_process_exit.ron",
        68,
        54,
        "contacts[0].profile",
        "`std::process::exit` is not a known math function",
    ),
    // The `(` before `x.powi(3)`.
    case(
        "profile_unclosed_paren.ron",
        68,
        58,
        "contacts[0].profile",
        "unclosed `(`",
    ),
    // `foo`.
    case(
        "profile_unknown_function.ron",
        68,
        54,
        "contacts[0].profile",
        "`foo` is not a known math function",
    ),
    // The `x` of `0.5 x`.
    case(
        "profile_unparsable.ron",
        68,
        48,
        "contacts[0].profile",
        "not a valid expression",
    ),
    // `y`.
    case(
        "profile_wrong_variable.ron",
        68,
        48,
        "contacts[0].profile",
        "the only variable allowed here is `x`",
    ),
    // `1.5` after `restitution:`.
    case(
        "restitution_above_one.ron",
        59,
        103,
        "simulation.restitution",
        "restitution must be in [0e0, 1e0], got 1.5e0",
    ),
    // `-0.5` after `restitution:`.
    case(
        "restitution_negative.ron",
        59,
        103,
        "simulation.restitution",
        "restitution must be in [0e0, 1e0], got -5e-1",
    ),
    // `0.5` after `restitution:`.
    case(
        "restitution_two_contacts.ron",
        79,
        103,
        "simulation.restitution",
        "needs exactly one contact; this model has 2",
    ),
    // `0.5` after `restitution:`.
    case(
        "restitution_with_rk4.ron",
        59,
        100,
        "simulation.restitution",
        "needs an adaptive integrator",
    ),
    // `"rho"` in `Roller(radius: "rho")`.
    case(
        "roller_undercut.ron",
        46,
        38,
        "contacts[0].follower.radius",
        "is larger than the profile's hollow at theta = 3.926991, whose radius of curvature is 4.566038e-3 m",
    ),
    // `"A"` after `marker:`, the contact that lacks its range.
    case(
        "roller_without_range.ron",
        120,
        21,
        "contacts[0].marker",
        "a roller on an explicit profile needs `range: (from, to)`",
    ),
    // The `]` closing body2's anchor.
    case(
        "syntax_mismatched_bracket.ron",
        30,
        39,
        "bodies[1].joint.anchor",
        "Expected closing `)`, found `]`",
    ),
    // Just after `mass: 0.5`, where the comma is missing.
    case(
        "syntax_missing_comma.ron",
        24,
        22,
        "bodies[1].mass",
        "Expected comma",
    ),
    // `kg`.
    case(
        "syntax_stray_token.ron",
        24,
        23,
        "bodies[1].mass",
        "found `kg`",
    ),
    // The second closing `)`.
    case(
        "syntax_trailing_text.ron",
        76,
        1,
        "<top level>",
        "trailing characters",
    ),
    // Just after `com: (0.05, 0.0, 0.0,`, where the `)` is missing.
    case(
        "syntax_unclosed_paren.ron",
        25,
        34,
        "bodies[1].com",
        "the group opened at 25:18 is not closed",
    ),
    // The opening quote of `"q4]`.
    case(
        "syntax_unterminated_string.ron",
        72,
        28,
        "initial.hold[2]",
        "no closing",
    ),
    // `"A"` of the second contact.
    case(
        "two_contacts_one_marker.ron",
        69,
        18,
        "contacts[1].marker",
        "already has a contact",
    ),
    // `[` of `["q2"]`.
    case(
        "type_list_for_string.ron",
        31,
        29,
        "bodies[1].joint.coordinate",
        "Expected string",
    ),
    // `0.05` after `com:`.
    case(
        "type_number_for_list.ron",
        25,
        18,
        "bodies[1].com",
        "Expected opening `(`",
    ),
    // The `)` where gravity's third component is missing.
    case(
        "type_short_vector.ron",
        6,
        25,
        "gravity",
        "array of length 3 but found 2",
    ),
    // `true` after `mass:`.
    case(
        "type_string_for_number.ron",
        24,
        19,
        "bodies[1].mass",
        "Expected a number or a string with an expression of the parameters",
    ),
    // `colour`.
    case(
        "unknown_field.ron",
        25,
        13,
        "bodies[1].colour",
        "Unexpected field named `colour`",
    ),
    // `Ixx(0.01)`.
    case(
        "unknown_inertia_form.ron",
        26,
        22,
        "bodies[1].inertia",
        "variant named `Ixx`",
    ),
    // `Euler`.
    case(
        "unknown_integrator.ron",
        74,
        57,
        "simulation.integrator",
        "unknown integrator (one of rk4, dopri5, dop853, in any letter case), found `Euler`",
    ),
    // `Slider`.
    case(
        "unknown_joint_kind.ron",
        42,
        23,
        "bodies[2].joint.kind",
        "variant named `Slider`",
    ),
    // `"body7"`.
    case(
        "unknown_parent.ron",
        37,
        21,
        "bodies[2].parent",
        "unknown parent `body7`",
    ),
    // `gravty`.
    case(
        "unknown_top_level_field.ron",
        6,
        5,
        "gravty",
        "Unexpected field named `gravty`",
    ),
    // The `(` after `initial:`: the profile is infinite there (it divides by x - x), which
    // the message says instead of calling |h| zero.
    Case {
        file: "profile_undefined_at_guess.ron",
        line: 70,
        column: 14,
        field: "initial",
        phrase: "the constraints are -inf at the initial guess",
        reference: Reference::Assemble,
        located: None,
    },
    // The hold list: every coordinate held, none left to close the loop.
    Case {
        file: "loop_every_coordinate_held.ron",
        line: 53,
        column: 15,
        field: "initial.hold",
        phrase: "every coordinate is held or driven",
        reference: Reference::Assemble,
        located: None,
    },
    // The `(` after `initial:`.
    Case {
        file: "unreachable_initial_state.ron",
        line: 70,
        column: 14,
        field: "initial",
        phrase: "neither held nor driven (q3) do not move the contact point",
        reference: Reference::Assemble,
        located: None,
    },
    // body3's axis `(0.0, 0.0, 0.0)`.
    case(
        "zero_axis.ron",
        43,
        23,
        "bodies[2].joint.axis",
        "must be a non-zero vector",
    ),
    // The cam's x_axis `(0.0, 0.0, 0.0)`.
    case(
        "zero_cam_axis.ron",
        86,
        57,
        "contacts[0].frame.x_axis",
        "must be a non-zero vector",
    ),
    // `0.0` after `dt_out:`.
    case(
        "zero_dt_out.ron",
        75,
        38,
        "simulation.dt_out",
        "dt_out must be positive",
    ),
    // `0.0` after `mass:`.
    case(
        "zero_mass.ron",
        24,
        19,
        "bodies[1].mass",
        "mass must be positive and finite, got 0",
    ),
    // Profiles from tables of points and from motion laws (issue 14); each position is that
    // of the value the row's field names (or of the table file's cell), found in the file.
    case(
        "table_too_few_points.ron",
        46,
        20,
        "contacts[0].table",
        "needs at least 2 points",
    ),
    case(
        "table_abscissa_repeated.ron",
        49,
        89,
        "contacts[0].table.points[3]",
        "must increase strictly",
    ),
    case(
        "table_polar_not_closed.ron",
        49,
        107,
        "contacts[0].table.points[4]",
        "r is 0.051 here and 0.05 on points[0]",
    ),
    case(
        "table_polar_not_a_turn.ron",
        49,
        107,
        "contacts[0].table.points[4]",
        "covers one turn",
    ),
    case(
        "table_file_and_points.ron",
        46,
        20,
        "contacts[0].table",
        "exactly one of them",
    ),
    case(
        "table_file_missing.ron",
        46,
        45,
        "contacts[0].table.file",
        "cannot read the table file",
    ),
    Case {
        file: "table_csv_not_a_number.ron",
        line: 5,
        column: 7,
        field: "contacts[0].table.file",
        phrase: "`0.0395x` is not a number (y)",
        reference: Reference::Load,
        located: Some("tables/not_a_number.csv"),
    },
    // `0.0,-0.04` on line 6, the last row: not the first point, `0.04,0.0` on line 3.
    Case {
        file: "table_csv_not_closed.ron",
        line: 6,
        column: 1,
        field: "contacts[0].table.file",
        phrase: "must repeat its first (0.04, 0) on line 3",
        reference: Reference::Load,
        located: Some("tables/not_closed.csv"),
    },
    Case {
        file: "table_csv_wrong_header.ron",
        line: 1,
        column: 1,
        field: "contacts[0].table.file",
        phrase: "this table's columns are `theta, r`",
        reference: Reference::Load,
        located: Some("tables/wrong_header.csv"),
    },
    Case {
        file: "table_csv_short_row.ron",
        line: 4,
        column: 1,
        field: "contacts[0].table.file",
        phrase: "has 1 cell",
        reference: Reference::Load,
        located: Some("tables/short_row.csv"),
    },
    case(
        "table_parametric_clamped.ron",
        46,
        122,
        "contacts[0].table.ends",
        "clamped ends take one slope each",
    ),
    case(
        "table_and_polar.ron",
        50,
        20,
        "contacts[0].table",
        "give only one of",
    ),
    case(
        "law_not_a_turn.ron",
        50,
        27,
        "contacts[0].law.segments",
        "add up to 350.000000°, not 360°",
    ),
    case(
        "law_does_not_return.ron",
        54,
        50,
        "contacts[0].law.segments[3].lift",
        "must come back to lift 0",
    ),
    case(
        "law_rise_goes_down.ron",
        53,
        52,
        "contacts[0].law.segments[1].lift",
        "a rise ends above the lift it starts from",
    ),
    case(
        "law_segment_angle_zero.ron",
        53,
        36,
        "contacts[0].law.segments[2].degrees",
        "a segment's angle must be positive",
    ),
    case(
        "law_unknown_law.ron",
        52,
        31,
        "contacts[0].law.segments[1].law",
        "variant named `Parabolic`",
    ),
    case(
        "law_roller_undercuts.ron",
        45,
        38,
        "contacts[0].follower.radius",
        "undercuts the cam designed for it",
    ),
    case(
        "law_flat_cusp.ron",
        48,
        30,
        "contacts[0].law.base_radius",
        "would have a cusp",
    ),
    case(
        "law_offset_outside_prime_circle.ron",
        49,
        45,
        "contacts[0].law.motion.offset",
        "outside the prime circle",
    ),
    case(
        "law_arm_cannot_reach.ron",
        50,
        65,
        "contacts[0].law.motion.arm",
        "cannot reach the prime circle",
    ),
    case(
        "law_pressure_limit_out_of_range.ron",
        57,
        37,
        "contacts[0].law.max_pressure_angle",
        "between 0 and 90",
    ),
    case(
        "law_lift_read_at_run_time.ron",
        52,
        48,
        "contacts[0].law.segments[1].lift",
        "must be constant",
    ),
    case(
        "law_no_segments.ron",
        50,
        27,
        "contacts[0].law.segments",
        "at least one segment",
    ),
    // Loops (from models/four_bar.ron).
    // The slot's axis `(0.0, 0.0, 1.0)`.
    case(
        "loop_axis_out_of_plane.ron",
        48,
        114,
        "loops[1].axis",
        "must be in the x-y plane",
    ),
    // The loop `pin` itself: its coupler is too short to reach the rocker.
    Case {
        file: "loop_cannot_close.ron",
        line: 47,
        column: 9,
        field: "loops[0]",
        phrase: "cannot be assembled",
        reference: Reference::Assemble,
        located: None,
    },
    // `"coupler"` as the loop's second body.
    case(
        "loop_joins_a_body_to_itself.ron",
        47,
        95,
        "loops[0].b.body",
        "joins `coupler` to itself",
    ),
    // The second loop's name `"pin"`.
    case(
        "loop_name_taken.ron",
        48,
        16,
        "loops[1].name",
        "already used by loops[0]",
    ),
    // The second loop, `(name: "stop", …)`.
    case(
        "loop_too_many_equations.ron",
        48,
        9,
        "loops[1]",
        "more constraint equations than free coordinates",
    ),
    // `"rocket"`.
    case(
        "loop_unknown_body.ron",
        47,
        95,
        "loops[0].b.body",
        "unknown body `rocket`",
    ),
    // Cam surfaces and barrel cams. `-0.001` after the groove's `backlash:`.
    case(
        "backlash_negative.ron",
        51,
        27,
        "contacts[0].barrel.backlash",
        "a length of 0 m or more, got -0.001",
    ),
    // `0.001` after `backlash:`, in a model without `restitution`.
    case(
        "backlash_without_restitution.ron",
        51,
        27,
        "contacts[0].barrel.backlash",
        "give the flanks' coefficient of restitution",
    ),
    // `"0.01*theta + base"`, the barrel's groove.
    case(
        "barrel_groove_open.ron",
        51,
        25,
        "contacts[0].barrel.groove",
        "must close round the cylinder",
    ),
    // `Roller(radius: "rho")`: 10 mm against the groove's 5 mm crests.
    case(
        "barrel_groove_undercut.ron",
        48,
        38,
        "contacts[0].follower.radius",
        "undercuts the groove's lower flank: at θ = 11.500°",
    ),
    // The surface's text: a logarithm undefined over part of the region.
    case(
        "surface_undefined_in_region.ron",
        43,
        22,
        "contacts[0].surface",
        "the surface is not defined over its region: f = NaN",
    ),
    // Surfaces through grids of points. The table's `(` in the model file: points written
    // inline.
    case(
        "grid_inline_points.ron",
        43,
        20,
        "contacts[0].table",
        "a surface's table is read from a CSV file of x, y, z rows",
    ),
    // The z cell of the point (0.2, 0.1), which should repeat (-0.2, 0.1)'s on line 5.
    Case {
        file: "grid_periodic_edges_differ.ron",
        line: 25,
        column: 11,
        field: "contacts[0].table.file",
        phrase: "the grid is periodic in x, so z[4][3] must repeat z[0][3]",
        reference: Reference::Load,
        located: Some("tables/grid_periodic_edges_differ.csv"),
    },
    // The first row of x = 0.1 (line 17), whose point (0.1, -0.1) no row gives.
    Case {
        file: "grid_point_missing.ron",
        line: 17,
        column: 1,
        field: "contacts[0].table.file",
        phrase: "no row gives z at (x, y) = (0.1, -0.1)",
        reference: Reference::Load,
        located: Some("tables/grid_point_missing.csv"),
    },
    // The second row of (0, 0.1), line 16 (the first is line 15).
    Case {
        file: "grid_point_repeated.ron",
        line: 16,
        column: 1,
        field: "contacts[0].table.file",
        phrase: "gives the point (x, y) = (0, 0.1) again, after line 15",
        reference: Reference::Load,
        located: Some("tables/grid_point_repeated.csv"),
    },
    // `Flat(normal: …)` on a cam surface.
    case(
        "surface_with_flat.ron",
        44,
        23,
        "contacts[0].follower",
        "a surface takes a point (`follower: Knife`) or a ball",
    ),
    // Face cams. `Flat(normal: …)` in a groove.
    case(
        "face_flat_follower.ron",
        31,
        23,
        "contacts[0].follower",
        "a flat face cannot run in a face cam's groove",
    ),
    // The `law` given beside the `groove`.
    case(
        "face_groove_and_law.ron",
        34,
        22,
        "contacts[0].face.law",
        "either as `groove: \"g(theta)\"` or as a `law`, not both",
    ),
    // `Roller(radius: 0.03)`: the lobes' 24 mm radius of curvature.
    case(
        "face_groove_undercut.ron",
        32,
        38,
        "contacts[0].follower.radius",
        "undercuts the groove's inner flank: at θ = 0.0000 rad the centre line is convex",
    ),
];

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad_models")
}

/// Everything wrong with one case, or nothing.
fn check(case: &Case) -> Vec<String> {
    let mut problems = Vec::new();
    let path = corpus().join(case.file);
    let display = PathBuf::from("tests/bad_models").join(case.file);
    let generated = catch_unwind(|| camchain_codegen::generate_file(&path, &display));
    match generated {
        Err(_) => problems.push("generate_file panicked".to_string()),
        Ok(Ok(_)) => problems.push("generate_file accepted the file".to_string()),
        Ok(Err(e)) => {
            let prefix = format!(
                "tests/bad_models/{}:{}:{}: {}: ",
                case.located.unwrap_or(case.file),
                case.line,
                case.column,
                case.field
            );
            let shown = e.to_string().replace('\\', "/");
            if !shown.starts_with(&prefix) {
                problems.push(format!("error `{shown}` does not start with `{prefix}`"));
            }
            if !e.message.contains(case.phrase) {
                problems.push(format!("message `{}` lacks `{}`", e.message, case.phrase));
            }
        }
    }
    let reference = catch_unwind(AssertUnwindSafe(|| {
        NumericModel::load(&path).map(|model| model.assemble(0.0).map(|_| ()))
    }));
    match (case.reference, reference) {
        (_, Err(_)) => problems.push("the numeric reference panicked".to_string()),
        (Reference::Load, Ok(Err(e))) => {
            // Same error as the build's loader, with the path as given.
            let want = (case.line, case.column, case.field);
            let file = case.located.map_or(path.clone(), |f| corpus().join(f));
            if (e.line, e.column, e.field.as_str()) != want || e.file != file {
                problems.push(format!("NumericModel::load gave `{e}`, want {want:?}"));
            }
        }
        (Reference::Load, Ok(Ok(_))) => {
            problems.push("NumericModel::load accepted the file".to_string());
        }
        (Reference::Assemble, Ok(Ok(Err(_)))) => {}
        (Reference::Assemble, Ok(Ok(Ok(())))) => {
            problems.push("the reference assembled the initial state".to_string());
        }
        (Reference::Accept, Ok(Ok(Ok(())))) => {}
        (Reference::Accept, Ok(Ok(Err(e)))) => {
            problems.push(format!("the reference failed to assemble: {e}"));
        }
        (Reference::Accept | Reference::Assemble, Ok(Err(e))) => {
            problems.push(format!("NumericModel::load failed (`{e}`)"));
        }
    }
    problems
}

#[test]
fn every_bad_model_is_rejected_with_its_location_and_problem() {
    let failures: Vec<String> = CASES
        .iter()
        .flat_map(|case| {
            check(case)
                .into_iter()
                .map(move |p| format!("{}: {p}", case.file))
        })
        .collect();
    assert!(
        failures.is_empty(),
        "{} problems:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn the_table_covers_the_corpus_exactly() {
    // The model files; the tables some of them name are in `tables/`.
    let on_disk: BTreeSet<String> = std::fs::read_dir(corpus())
        .expect("tests/bad_models exists")
        .map(|entry| entry.expect("a directory entry"))
        .filter(|entry| entry.path().is_file())
        .map(|entry| entry.file_name())
        .map(|name| name.to_string_lossy().into_owned())
        .collect();
    let in_table: BTreeSet<String> = CASES.iter().map(|c| c.file.to_string()).collect();
    assert_eq!(in_table.len(), CASES.len(), "a file is listed twice");
    let untested: Vec<&String> = on_disk.difference(&in_table).collect();
    let missing: Vec<&String> = in_table.difference(&on_disk).collect();
    assert!(
        untested.is_empty(),
        "files without an expectation: {untested:?}"
    );
    assert!(
        missing.is_empty(),
        "expectations without a file: {missing:?}"
    );
    assert!(
        on_disk.len() >= 30,
        "the corpus has {} files",
        on_disk.len()
    );
    for name in &on_disk {
        let text = std::fs::read_to_string(corpus().join(name)).expect("readable");
        assert!(
            text.starts_with("// Bad model: "),
            "{name} does not start with a `// Bad model: <defect>` comment"
        );
    }
}
